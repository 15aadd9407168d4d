#pragma once

// The library's one number formatter (issue #21): every file, table cell and
// message formats its doubles through these three.

#include <string>

namespace robomach {

/// Shortest text that reads back to exactly the same double (std::to_chars):
/// what files (CSV, YAML, JSON) hold.
std::string FormatDouble(double v);

/// A number for a message or a label: `significant_digits` significant
/// digits in printf's %g style ("0.0001235", "1.5e-07", "250").
std::string FormatNumber(double v, int significant_digits = 4);

/// A table cell: FormatDouble(v), or "" (an empty cell) when v is NaN or
/// infinite.
std::string FormatCell(double v);

/// An English ordinal: 1st 2nd 3rd 4th ... 11th 12th 13th ... 21st 22nd
/// 101st 111th ("every 2nd line").
std::string Ordinal(long n);

}  // namespace robomach
