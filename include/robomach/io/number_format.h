#pragma once

// The number formatter lives in common (robomach/common/number_format.h), so
// that every module can use it; io's name for it stays.

#include "robomach/common/number_format.h"

namespace robomach::io {

using robomach::FormatDouble;

}  // namespace robomach::io
