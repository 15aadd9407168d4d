#pragma once
// Readers and writers of the five-axis machine files (formats.md §8): machine
// file (§8.3), encoder counts (§8.1), Siemens 840D sl compensation tables
// (§8.4), temperature log (§8.4), programmed path, acquired path (§8.5) and
// ISO 230-2 runs (§8.6). Units are converted here, once: mm -> m, deg -> rad.

#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "robomach/machine/acquisition.h"
#include "robomach/machine/compensation.h"
#include "robomach/machine/iso230.h"
#include "robomach/machine/nutating_head_rotary_table.h"
#include "robomach/machine/synthesis.h"

namespace robomach::io {

struct MachineFile {
  std::string path;
  machine::Machine machine;
  /// Controller axis name (AX1) -> index in machine.axes.
  std::map<std::string, int> controller_axes;
  machine::NutatingHeadGeometry geometry;  // kinematics.type nutating_head_rotary_table
};

/// @throws InputError with file:line:col for unknown keys, missing axes the
///   kinematics needs, non-positive resolutions, an unknown kinematics type.
MachineFile ReadMachineFile(const std::string& path);
/// Writes a machine file (formats.md §8.3) with these axes' origins; used by
/// axis-synth to hand over the reference position it started from.
void WriteMachineFile(const std::string& path, const MachineFile& file);

/// Parsed $AA_ENC_COMP / $AN_CEC tables.
struct CompensationTables {
  std::vector<machine::EncoderCompensation> encoder;
  std::vector<machine::CrossAxisCompensation> cross_axis;
};
/// Reads the controller's table assignments (formats.md §8.4).
/// @throws InputError "file:line: ..." for a malformed assignment, MAX not
///   equal to MIN + (n - 1) STEP, a modulo table, a measuring system other
///   than 0, $AN_CEC_DIRECTION != 0, $AN_CEC_MULT_BY_TABLE != 0, an axis not
///   in controller_axes, a gap in the points or a duplicated assignment.
CompensationTables ReadCompensationFile(const std::string& path, const MachineFile& machine);

/// Temperature log `t_s,axis,K0_mm,tan_beta,P0_mm` (formats.md §8.4).
std::vector<machine::TemperatureCompensation> ReadTemperatureLog(const std::string& path,
                                                                 const MachineFile& machine);

/// Counts file (formats.md §8.1) with a column `<axis>_count` for every axis
/// of the machine file, stored in the machine file's axis order.
/// @throws InputError for a first row that is not all zeros, non-increasing
///   t_s, a count that is not a whole number, a missing axis column.
machine::CountsRecord ReadCountsFile(const std::string& path, const MachineFile& machine);

/// Writes counts rows as they come (axis-decode streams a capture).
class CountsWriter {
 public:
  CountsWriter(std::ostream& out, const std::vector<machine::AxisScale>& axes,
               const std::vector<std::pair<std::string, std::string>>& metadata = {});
  void Row(double t_s, const std::int64_t* counts);

 private:
  std::ostream& out_;
  int num_axes_;
  std::string buffer_;
};

/// Programmed path CSV `x_mm,y_mm,z_mm,i,j,k` (a polyline).
machine::ProgrammedPath ReadProgramFile(const std::string& path);

/// Acquired path rows (formats.md §8.5), 17 significant digits.
class AcquiredPathWriter {
 public:
  AcquiredPathWriter(std::ostream& out, const std::vector<machine::AxisScale>& axes,
                     bool contour_columns);
  void Row(double t_s, const machine::AcquiredSample& s, const machine::ContourError* contour);
  /// The text of one row (with its newline) appended to `buffer`; safe to
  /// call from several threads.
  void AppendRow(std::string* buffer, double t_s, const machine::AcquiredSample& s,
                 const machine::ContourError* contour) const;

 private:
  std::ostream& out_;
  std::vector<machine::AxisScale> axes_;
  std::string buffer_;
};

/// axis-acquire's main loop: every row of `record` through `acquisition`
/// (and `tracker`, if not null) to the acquired path (formats.md §8.5,
/// header included) on `out`. Rows are computed in order (the tracker follows
/// the path) while earlier chunks are formatted and written on `threads`
/// threads (io::WritePipelined). With a tracker, the contour error of every
/// row is returned (for the statistics and the plot).
std::vector<machine::ContourError> WriteAcquiredPath(std::ostream& out, const machine::CountsRecord& record,
                                                     const std::vector<machine::AxisScale>& axes,
                                                     machine::Acquisition* acquisition,
                                                     machine::ContourTracker* tracker, int threads = 2);

/// ISO 230-2 runs (formats.md §8.6): approaches per axis name, in file order
/// of first appearance; deviations in the file's unit (wrapped for rotary).
struct IsoRuns {
  bool rotary{false};
  std::vector<std::string> axis_order;
  std::map<std::string, std::vector<machine::Iso230Approach>> approaches;
};
IsoRuns ReadIsoRuns(const std::string& path);

}  // namespace robomach::io
