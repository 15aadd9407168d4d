// AppendDouble17 against the standard library's "%.17g" (std::to_chars,
// general, precision 17), which formats.md §8.5 asks for: identical text.
#include "robomach/io/format17.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <random>
#include <cstring>

namespace robomach::io {
namespace {

std::string Reference(double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  return std::string(buf, r.ptr);
}

std::string Fast(double v) {
  std::string s;
  AppendDouble17(v, &s);
  return s;
}

TEST(Format17, MatchesStdToCharsOnRandomValuesOfEveryScale) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> exp(-8, 18);
  for (int i = 0; i < 300000; ++i) {
    const double v = mant(rng) * std::pow(10.0, exp(rng));
    ASSERT_EQ(Fast(v), Reference(v)) << v;
  }
  // Random bit patterns in the fast range, including exact ties' neighbours.
  std::uniform_int_distribution<std::uint64_t> bits;
  for (int i = 0; i < 300000; ++i) {
    std::uint64_t b = bits(rng);
    double v;
    std::memcpy(&v, &b, 8);
    if (!std::isfinite(v) || std::abs(v) < 1e-6 || std::abs(v) > 1e17) continue;
    ASSERT_EQ(Fast(v), Reference(v)) << v;
  }
}

TEST(Format17, EdgeCases) {
  for (double v : {0.0, -0.0, 1.0, -1.0, 0.1, 0.5, 1e-4, 9.9999999999999991e-5, 1e15, 999999999999999.88, 1e16, 1e17,
                   123456789012345678.0, 0.30000000000000004, 2.5, 0.00012345, 99999999999999999.0, 1e-300, 1e300,
                   std::nextafter(1.0, 2.0), std::nextafter(1.0, 0.0), 400.00000000000006, -849.99999999999989}) {
    EXPECT_EQ(Fast(v), Reference(v)) << v;
  }
}

}  // namespace
}  // namespace robomach::io
