#pragma once

#include <string>

namespace robomach::io {

/// Shortest text that reads back to exactly the same double.
std::string FormatDouble(double v);

}  // namespace robomach::io
