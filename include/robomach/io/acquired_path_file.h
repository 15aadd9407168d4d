#pragma once
// Acquired path (formats.md §8.5): rows, and axis-acquire's pipelined main loop.
// The writer converts back for the file: m -> mm, rad -> deg.

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/machine/acquisition.h"
#include "robomach/machine/synthesis.h"

namespace robomach::io {

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

/// The contour part of axis-acquire's summary (docs/formats.md §4.1): the
/// statistics (max, mean, rms, std) of the contour error [um] and of the
/// tool axis error [deg], the programmed path's length and the part of it
/// the run covered [mm].
nlohmann::json ContourSummaryJson(const std::vector<machine::ContourError>& contour,
                                  const machine::ProgrammedPath& path);

}  // namespace robomach::io
