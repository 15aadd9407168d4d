#include "robomach/io/number_format.h"

#include <charconv>

namespace robomach::io {

std::string FormatDouble(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

}  // namespace robomach::io
