#pragma once
// Private helpers of the five-axis machine files (formats.md §8): each
// format has its own source file (issue #21), these are what they share.

#include <string>
#include <string_view>

#include "robomach/machine/acquisition.h"

namespace robomach::io::machine_text {

/// The whole file in one read (a counts file of a 60 s, 8 kHz record is
/// 21 MB; a stringstream would copy it twice).
/// @throws InputError when the file cannot be opened.
std::string ReadWholeFile(const std::string& path);
/// A file value (mm or deg) of axis `a` in SI (m or rad), and back.
double ToSi(const machine::AxisScale& a, double file_value);
double FromSi(const machine::AxisScale& a, double si);
/// "_mm" for a linear axis, "_deg" for a rotary one.
std::string UnitSuffix(const machine::AxisScale& a);

}  // namespace robomach::io::machine_text
