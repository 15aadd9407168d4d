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

std::string Ordinal(long n) {
  const long a = n < 0 ? -n : n;
  const char* suffix = "th";
  if (a % 100 < 11 || a % 100 > 13) {
    switch (a % 10) {
      case 1: suffix = "st"; break;
      case 2: suffix = "nd"; break;
      case 3: suffix = "rd"; break;
      default: break;
    }
  }
  return std::to_string(n) + suffix;
}

}  // namespace robomach
