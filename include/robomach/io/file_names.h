#pragma once

// File names made from user data (posture IDs) in an output folder
// (docs/conventions.md, "File names made from IDs").

#include <map>
#include <string>
#include <vector>

namespace robomach::io {

/// A file-name stem for each ID, safe to put in an output folder: the
/// characters outside [A-Za-z0-9._-] become '_', a '.' that starts the ID or
/// follows another '.' becomes '_' (no "..", no hidden file), an empty ID becomes
/// "_", and a stem is cut to 100 characters. IDs already safe keep their
/// name; a stem that another ID already has (compared without case, for
/// case-insensitive file systems) gets "_2", "_3", ... appended. The same IDs
/// in any order give the same stems: IDs are taken in sorted order, the
/// unchanged ones first.
/// E.g. "../escaped" -> "___escaped", "sub/dir" -> "sub_dir", "P 1" -> "P_1".
std::map<std::string, std::string> SafeFileStems(const std::vector<std::string>& ids);

}  // namespace robomach::io
