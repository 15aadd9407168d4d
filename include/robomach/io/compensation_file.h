#pragma once
// Siemens 840D sl compensation tables (formats.md §8.4): $AA_ENC_COMP and $AN_CEC assignments.
// Units are converted here, once: mm -> m, deg -> rad.

#include <string>
#include <vector>

#include "robomach/io/machine_file.h"
#include "robomach/machine/compensation.h"

namespace robomach::io {

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

}  // namespace robomach::io
