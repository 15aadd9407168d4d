// The one number formatter and Skew of common (issue #21): FormatDouble reads
// back to the same bits (checked against strtod, over many magnitudes),
// FormatNumber agrees with iostream's precision, FormatCell leaves
// non-finite values empty; Skew(a) b equals the cross product.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <sstream>

#include <Eigen/Geometry>

#include "robomach/common/eigen_types.h"
#include "robomach/common/number_format.h"

namespace robomach {
namespace {

TEST(NumberFormat, FormatDoubleRoundTripsExactly) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> expo(-300, 300);
  for (int i = 0; i < 20000; ++i) {
    const double v = std::ldexp(mant(rng), expo(rng));
    const std::string s = FormatDouble(v);
    EXPECT_EQ(std::strtod(s.c_str(), nullptr), v) << s;
  }
  const double tiny = std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(std::strtod(FormatDouble(tiny).c_str(), nullptr), tiny);
  EXPECT_EQ(FormatDouble(0.1), "0.1");  // shortest, not 0.10000000000000001
}

TEST(NumberFormat, FormatNumberMatchesStreamPrecision) {
  for (double v : {1.23456789e-7, 250.0, -0.000123456, 6.02214076e23, 0.0, 1.0 / 3.0}) {
    for (int digits : {3, 4, 6, 10}) {
      std::ostringstream s;
      s.precision(digits);
      s << v;
      EXPECT_EQ(FormatNumber(v, digits), s.str()) << v << " digits " << digits;
    }
  }
  EXPECT_EQ(FormatNumber(1.23456789e-7), "1.235e-07");
}

TEST(NumberFormat, FormatCellIsEmptyForNonFinite) {
  EXPECT_EQ(FormatCell(std::numeric_limits<double>::quiet_NaN()), "");
  EXPECT_EQ(FormatCell(std::numeric_limits<double>::infinity()), "");
  EXPECT_EQ(FormatCell(-std::numeric_limits<double>::infinity()), "");
  EXPECT_EQ(FormatCell(2.5e-9), FormatDouble(2.5e-9));
}

TEST(Skew, IsTheCrossProductMatrix) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d a(n(rng), n(rng), n(rng)), b(n(rng), n(rng), n(rng));
    EXPECT_LT((Skew(a) * b - a.cross(b)).norm(), 1e-15 * (1.0 + a.norm() * b.norm()));
  }
  const Eigen::Vector3d a(1.0, -2.0, 3.0);
  EXPECT_EQ((Skew(a) + Skew(a).transpose()).norm(), 0.0);  // antisymmetric
}

}  // namespace
}  // namespace robomach

// Ordinals as an English text writes them (the audit said "every 2th line").
TEST(NumberFormat, OrdinalSuffixes) {
  const std::pair<long, const char*> cases[] = {
      {1, "1st"},     {2, "2nd"},     {3, "3rd"},     {4, "4th"},     {10, "10th"},   {11, "11th"},
      {12, "12th"},   {13, "13th"},   {21, "21st"},   {22, "22nd"},   {23, "23rd"},   {101, "101st"},
      {111, "111th"}, {112, "112th"}, {1002, "1002nd"}, {0, "0th"}};
  for (const auto& [n, text] : cases) EXPECT_EQ(robomach::Ordinal(n), text) << n;
}
