#pragma once

// The version of the robomach library and tools: the CMake project version,
// and the git commit when built from a clone (with "-dirty" when the work
// tree had uncommitted changes at build time). Every tool prints it with
// --version and writes it as `robomach_version` in its JSON outputs, so a
// result can be traced to the code that made it.

#include <string>

namespace robomach {

/// "0.1.0".
const char* VersionNumber();
/// The git commit ("a1b2c3d4e5f6", "a1b2c3d4e5f6-dirty") or "" when not
/// built from a clone.
const char* VersionCommit();
/// "0.1.0 (git a1b2c3d4e5f6)" or "0.1.0".
std::string Version();

}  // namespace robomach
