#pragma once
// Fast exact formatting of a double with 17 significant digits, the text
// printf("%.17g") and std::to_chars(general, 17) produce (formats.md §8.5
// writes every number so). The acquired path of a 60 s, 8 kHz record has
// 6.7 million numbers; the general-purpose routines take most of
// axis-acquire's time budget for them.

#include <string>

namespace robomach::io {

/// Appends `v` as "%.17g" would write it (correctly rounded, trailing zeros
/// removed, exponent form for exponents < -4 or >= 17).
void AppendDouble17(double v, std::string* out);

/// Room WriteDouble17 needs at most ("-1.2345678901234567e-308" is 24).
inline constexpr int kMaxChars17 = 32;

/// The same text written at `out` (which must have kMaxChars17 bytes of
/// room); returns the end of the text. No allocation, for bulk output.
char* WriteDouble17(double v, char* out);

}  // namespace robomach::io
