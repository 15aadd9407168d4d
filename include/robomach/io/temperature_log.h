#pragma once
// Temperature log of the compensation (formats.md §8.4).
// Units are converted here, once: mm -> m, deg -> rad.

#include <string>
#include <vector>

#include "robomach/io/machine_file.h"
#include "robomach/machine/compensation.h"

namespace robomach::io {

/// Temperature log `t_s,axis,K0_mm,tan_beta,P0_mm` (formats.md §8.4).
std::vector<machine::TemperatureCompensation> ReadTemperatureLog(const std::string& path,
                                                                 const MachineFile& machine);

}  // namespace robomach::io
