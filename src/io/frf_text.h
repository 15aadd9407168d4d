#pragma once
// Private helpers of the FRF file formats (formats.md §3, §4): the CSV and
// the UFF58 mapping have a source file each (issue #21); these they share
// (Trim and Lower are io's, text.h).

#include <string>
#include <vector>

#include "robomach/dynamics/measured_frf.h"

namespace robomach::io::frf_text {

/// Ten significant digits, for messages.
std::string Fmt(double v);
/// A warning when an FRF declared as receptance grows like f (mobility) or
/// f² (accelerance) over its lowest lines.
void CheckLowFrequencyTrend(const dynamics::FrfKey& key, const dynamics::Frf& frf, const std::string& where,
                            std::vector<std::string>* warnings);
/// A double through printf's `fmt`.
std::string Printf(const char* fmt, double v);
/// `s` cut or padded with blanks to 80 (a UFF line) or `n` characters.
std::string Pad80(const std::string& s);
std::string PadTo(const std::string& s, size_t n);

}  // namespace robomach::io::frf_text
