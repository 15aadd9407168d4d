#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <string_view>

namespace robomach::io {

/// Writes a file completely or not at all (formats.md §4): the content goes
/// to a temporary file in the same directory, which is renamed over `path`
/// only after everything was written and flushed. On any failure the
/// temporary file is removed and OutputError is thrown; an exception thrown
/// by `write` removes it too and propagates.
void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write);
void WriteFileAtomically(const std::string& path, std::string_view content);

/// Creates a directory (and its parents) if it does not exist.
/// @throws OutputError if that fails.
void EnsureDirectory(const std::string& path);

}  // namespace robomach::io
