#pragma once
// Programmed path CSV (formats.md §8.5).
// Units are converted here, once: mm -> m, deg -> rad.

#include <string>

#include "robomach/machine/acquisition.h"

namespace robomach::io {

/// Programmed path CSV `x_mm,y_mm,z_mm,i,j,k` (a polyline).
machine::ProgrammedPath ReadProgramFile(const std::string& path);

}  // namespace robomach::io
