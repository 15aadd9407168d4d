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

// The exponent form (|v| < 1e-4, as contour errors in mm and axis errors in
// degrees often are) and values next to powers of ten, where the decimal
// exponent is hardest to get right.
TEST(Format17, MatchesStdToCharsForSmallValuesAndNextToPowersOfTen) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> exp(-14, -3);
  for (int i = 0; i < 300000; ++i) {
    const double v = mant(rng) * std::pow(10.0, exp(rng));
    ASSERT_EQ(Fast(v), Reference(v)) << v;
  }
  for (int e = -20; e <= 18; ++e) {
    const double p = std::pow(10.0, e);
    for (double v : {p, std::nextafter(p, 0.0), std::nextafter(p, 1e300), 0.99999999999999999 * p, 5.0 * p}) {
      ASSERT_EQ(Fast(v), Reference(v)) << v;
      ASSERT_EQ(Fast(-v), Reference(-v)) << -v;
    }
  }
  for (long i = 1; i < 200000; ++i) {  // many exactly representable and many halfway-looking values
    ASSERT_EQ(Fast(i * 1e-7), Reference(i * 1e-7));
    ASSERT_EQ(Fast(i * 0.25 * 1e-9), Reference(i * 0.25 * 1e-9));
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
