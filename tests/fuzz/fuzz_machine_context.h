#pragma once

// The Siemens table, temperature log and counts readers take the machine
// file the tools read first: the project's DMU 80 P file (config/machine).
#include "robomach/io/machine_files.h"

namespace robomach::fuzz {

inline const io::MachineFile& DemoMachine() {
  static const io::MachineFile machine = io::ReadMachineFile(ROBOMACH_SOURCE_DIR "/config/machine/dmu80p.yaml");
  return machine;
}

}  // namespace robomach::fuzz
