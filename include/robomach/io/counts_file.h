#pragma once
// Encoder counts file (formats.md §8.1): reader and a streaming writer.
// Counts are integers and stay so; time in s.

#include <cstdint>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "robomach/io/machine_file.h"
#include "robomach/machine/acquisition.h"
#include "robomach/machine/synthesis.h"

namespace robomach::io {

/// The median time step of a counts file: rows are written at 10 Hz or
/// faster (controller position traces 100 Hz - 100 kHz, the 840D sl servo
/// trace at most 8 kHz; axis-decode up to its capture rate; axis-synth's
/// --sample-rate-hz range, docs/plausibility.md). The seed's 8 kHz in ms
/// is a step of 0.125 "s".
inline constexpr double kMaxPlausibleCountsStepS = 0.1;

/// Counts file (formats.md §8.1) with a column `<axis>_count` for every axis
/// of the machine file, stored in the machine file's axis order.
/// @throws InputError for a first row that is not all zeros, a negative or
///   non-increasing t_s, a count that is not a whole number, a missing axis
///   column.
/// Rows further apart than kMaxPlausibleCountsStepS (the median step) give
/// "implausible (unit mistake?): file:line: column t_s: ..." in
/// *implausible (not collected when null): a time in ms typed in the s
/// column; the axis tools print it and flag their result (exit 3).
machine::CountsRecord ReadCountsFile(const std::string& path, const MachineFile& machine,
                                     std::vector<std::string>* implausible = nullptr);

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

}  // namespace robomach::io
