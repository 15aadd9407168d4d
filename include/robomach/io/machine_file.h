#pragma once
// Machine file (formats.md §8.3): axes, resolutions, origins, the controller axis names and the kinematics.
// Units are converted here, once: mm -> m, deg -> rad.

#include <map>
#include <string>
#include <vector>

#include "robomach/machine/acquisition.h"
#include "robomach/machine/nutating_head_rotary_table.h"

namespace robomach::io {

struct MachineFile {
  std::string path;
  machine::Machine machine;
  /// Controller axis name (AX1) -> index in machine.axes.
  std::map<std::string, int> controller_axes;
  machine::NutatingHeadGeometry geometry;  // kinematics.type nutating_head_rotary_table
  /// "implausible (unit mistake?): file:line:col: ..." for each value outside
  /// its plausible range below (docs/plausibility.md): the axis tools print
  /// them and flag their result (exit 3).
  std::vector<std::string> implausible;
};

// Plausible ranges of a machine file's values (docs/plausibility.md): wide,
// so that no real machine tool is flagged, and each names the likely unit
// mistake. Sources: Heidenhain's scale and angle encoder catalogues (LIC 4100:
// 1 nm steps; LC 415: 5 - 50 nm; glass scales of older machines 1 - 10 um;
// RCN 8000 angle encoders 29 bit = 0.0000007 deg; RON/ERN 0.0001 - 0.001 deg);
// machine tools' data sheets (DMU 80P: travels 800 x 1050 x 850 mm; the
// largest gantry mills travel 20 - 30 m; nutating heads at 30 - 50 deg, pivot
// lengths 100 - 600 mm); geometric errors of rotary axes a few um to tens of
// um (ISO 230-7; Ibaraki and Knapp, IJAT 6 (2012)).
inline constexpr double kMinPlausibleLinearResolutionMm = 1e-6;   // 1 nm
inline constexpr double kMaxPlausibleLinearResolutionMm = 0.05;   // 50 um
inline constexpr double kMinPlausibleRotaryResolutionDeg = 1e-7;
inline constexpr double kMaxPlausibleRotaryResolutionDeg = 0.05;  // 180 arc-seconds
/// Lengths of the machine's geometry and positions in machine coordinates:
/// |value| (origin_mm, c_centre_mm, zero_offset_mm, pivot and tool length).
inline constexpr double kMaxPlausibleMachineLengthMm = 50000.0;
/// A non-zero pivot or tool length under this is m typed in the mm field.
inline constexpr double kMinPlausibleHeadLengthMm = 1.0;
/// A nutating head's angle under this is radians typed in the _deg field
/// (45 deg is 0.785 rad); heads are built at 30 - 50 deg.
inline constexpr double kMinPlausibleNutationDeg = 5.0;
/// |a geometric error| (eccentricities, pivot length error): over 1 mm a
/// machine would not be accepted; um typed in the mm field.
inline constexpr double kMaxPlausibleGeometricErrorMm = 1.0;
/// Refused (exit 65): a resolution beyond this cannot count a machine axis.
inline constexpr double kMaxLinearResolutionMm = 1000.0;
inline constexpr double kMaxRotaryResolutionDeg = 360.0;
/// Refused (exit 65): |a length| over 1 km is no machine tool.
inline constexpr double kMaxMachineLengthMm = 1e6;

/// @throws InputError with file:line:col for unknown keys, missing axes the
///   kinematics needs, non-positive resolutions, an unknown kinematics type,
///   a resolution over kMaxLinearResolutionMm / kMaxRotaryResolutionDeg, a
///   length over kMaxMachineLengthMm, a negative pivot or tool length.
///   Values outside the plausible ranges above go into `implausible`.
MachineFile ReadMachineFile(const std::string& path);
/// Writes a machine file (formats.md §8.3) with these axes' origins; used by
/// axis-synth to hand over the reference position it started from.
void WriteMachineFile(const std::string& path, const MachineFile& file);

}  // namespace robomach::io
