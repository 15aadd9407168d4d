#pragma once
// Machine file (formats.md §8.3): axes, resolutions, origins, the controller axis names and the kinematics.
// Units are converted here, once: mm -> m, deg -> rad.

#include <map>
#include <string>

#include "robomach/machine/acquisition.h"
#include "robomach/machine/nutating_head_rotary_table.h"

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

}  // namespace robomach::io
