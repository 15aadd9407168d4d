#include "robomach/common/number_format.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace robomach {

std::string FormatDouble(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

std::string FormatNumber(double v, int significant_digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", significant_digits, v);
  return buf;
}

std::string FormatCell(double v) { return std::isfinite(v) ? FormatDouble(v) : std::string(); }

}  // namespace robomach
