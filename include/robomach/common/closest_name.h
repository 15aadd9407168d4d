#pragma once

// "Did you mean": the known name closest to a mistyped one, for unknown
// command-line options and unknown keys of the YAML files (issue #35).

#include <string>
#include <vector>

namespace robomach {

/// Edit distance between two strings: insertions, deletions, substitutions,
/// and a swap of two neighbouring characters, each counted as one edit
/// (optimal string alignment distance).
size_t EditDistance(const std::string& a, const std::string& b);

/// The name of `known` closest to `given`, or "" when none is close. Case
/// and '_' against '-' are ignored; close means an edit distance of at most
/// max(2, length / 4), or the same name up to its last '_'/'-' (a unit
/// suffix left off or another one: "fmax" or "fmax_khz" for "fmax_hz").
std::string ClosestName(const std::string& given, const std::vector<std::string>& known);

}  // namespace robomach
