#pragma once
// JSON output of the tools (docs/formats.md §4.1).

#include <string>

#include <nlohmann/json.hpp>

namespace robomach::report {

/// Dumps JSON with non-finite numbers written as null. A JSON object gets a
/// `robomach_version` field (robomach::Version(): the version and git
/// commit that made it) unless it has one, so every JSON output of the
/// tools can be traced to its code. Bytes of strings that are not UTF-8
/// (text quoted from a Latin-1 file) are written as \xHH.
std::string DumpJson(const nlohmann::json& j);

}  // namespace robomach::report
