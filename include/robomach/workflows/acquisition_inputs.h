#pragma once
// axis-acquire's inputs read and checked together (docs/formats.md §8): the
// machine file, the encoder counts, and optionally the controller's
// compensation tables, its temperature log and the programmed path.

#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "robomach/io/acquired_path_file.h"
#include "robomach/io/compensation_file.h"
#include "robomach/io/machine_file.h"
#include "robomach/machine/acquisition.h"
#include "robomach/machine/compensation.h"
#include "robomach/machine/synthesis.h"

namespace robomach::workflows {

struct AcquisitionInputs {
  io::MachineFile machine;
  io::CompensationTables tables;                                 // empty without a compensation file
  std::vector<machine::TemperatureCompensation> temperatures;  // empty without a temperature log
  std::unique_ptr<machine::Compensation> compensation;       // all of them; empty() when none
  std::optional<machine::ProgrammedPath> program;
  machine::CountsRecord counts;
  /// The temperature log's and the counts file's unit findings.
  std::vector<std::string> temperature_implausible, counts_implausible;
  /// The compensation the acquisition applies (null when there is none).
  const machine::Compensation* applied() const {
    return compensation && !compensation->empty() ? compensation.get() : nullptr;
  }
  /// The unit findings of the machine file, the compensation tables, the
  /// temperature log and the counts (docs/plausibility.md), in that order:
  /// the tool flags its result (exit 3) on any.
  std::vector<std::string> implausible() const {
    std::vector<std::string> all = machine.implausible;
    all.insert(all.end(), tables.implausible.begin(), tables.implausible.end());
    all.insert(all.end(), temperature_implausible.begin(), temperature_implausible.end());
    all.insert(all.end(), counts_implausible.begin(), counts_implausible.end());
    return all;
  }
};

/// Reads every input before any work (an empty path: not given).
/// `compensation_option` names the compensation file in a message about
/// what it is (the tool's "--compensation"; "" for a library caller).
/// @throws InputError naming the file, line and column of the first problem.
AcquisitionInputs ReadAcquisitionInputs(const std::string& machine_path, const std::string& counts_path,
                                        const std::string& compensation_path = "",
                                        const std::string& temperature_path = "",
                                        const std::string& program_path = "",
                                        const std::string& compensation_option = "");

/// axis-acquire's main loop: every row of `record` through `acquisition`
/// (and `tracker`, if not null) to the acquired path (formats.md §8.5,
/// header included; io::AcquiredPathWriter) on `out`, in one pass. Rows are
/// computed in order (the tracker follows the path) while earlier chunks
/// are formatted and written on `threads` threads (io::WritePipelined):
/// only a few chunks of samples are held at a time. With a tracker, the
/// contour error of every row is returned (for the statistics and the plot).
std::vector<machine::ContourError> WriteAcquiredPath(std::ostream& out, const machine::CountsRecord& record,
                                                     const std::vector<machine::AxisScale>& axes,
                                                     machine::Acquisition* acquisition,
                                                     machine::ContourTracker* tracker, int threads = 2);

/// axis-acquire's contour figures (io::ContourSummaryJson): the statistics
/// (machine::Stats) of the contour error [um] and of the tool axis error
/// [deg], the programmed path's length and the part of it the run covered
/// [mm].
io::ContourFigures ContourFiguresOf(const std::vector<machine::ContourError>& contour,
                                    const machine::ProgrammedPath& path);

}  // namespace robomach::workflows
