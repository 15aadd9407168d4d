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
  /// "implausible (unit mistake?): file:line: ..." for a table whose largest
  /// value or whose positions are outside the plausible ranges below
  /// (docs/plausibility.md); one per table. The axis tools flag (exit 3).
  std::vector<std::string> implausible;
};

// Compensation values are mm (deg for rotary axes), like the control's.
// Real pitch and sag tables hold a few um to tens of um (the example pitch
// table of the SINUMERIK 840D sl Function Manual Extended Functions, K3
// Compensations, 03/2013, §4.4.2.3: +3, +10, +12 um). A larger value than
// 1 mm is um typed for mm (x1000). This limit is a judgement from practice,
// not a control's limit: MD32720 $MA_CEC_MAX_SUM, once cited here as "1 mm
// by default", could not be verified (docs/plausibility.md).
inline constexpr double kMaxPlausibleCompensationMm = 1.0;
inline constexpr double kMaxPlausibleCompensationDeg = 0.1;  // 360 arc-seconds
/// Refused (exit 65): no table corrects an axis by 10 cm or 10 deg.
inline constexpr double kMaxCompensationMm = 100.0;
inline constexpr double kMaxCompensationDeg = 10.0;
/// Reads the controller's table assignments (formats.md §8.4).
/// @throws InputError "file:line: ..." for a malformed assignment, MAX not
///   equal to MIN + (n - 1) STEP, a modulo table, a measuring system other
///   than 0, $AN_CEC_DIRECTION != 0, $AN_CEC_MULT_BY_TABLE != 0, an axis not
///   in controller_axes, a gap in the points or a duplicated assignment, a
///   value over kMaxCompensationMm (kMaxCompensationDeg for rotary axes).
///   Table positions (_MIN, _MAX) are checked against the machine file's
///   plausible lengths (kMaxPlausibleMachineLengthMm).
///   A file of another kind (a PNG, a YAML, a CSV such as the temperature
///   log: io::SniffFileKind) and a file without a single $AA_ENC_COMP or
///   $AN_CEC assignment (nothing to compensate with) are refused, named as
///   what they are: "this is a CSV table (the temperature log ...);
///   --compensation expects the Siemens compensation tables ...", with
///   `option` (the tool's option, "" for none) in the message.
CompensationTables ReadCompensationFile(const std::string& path, const MachineFile& machine,
                                        const std::string& option = "");

}  // namespace robomach::io
