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

}  // namespace robomach::io
