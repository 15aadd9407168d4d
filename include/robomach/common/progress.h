#pragma once

#include <functional>
#include <string>

namespace robomach {

/// Progress report from a long computation: `done` of `total` steps finished.
/// The library never prints; apps pass a callback that writes to stderr.
using ProgressCallback = std::function<void(long done, long total)>;

}  // namespace robomach
