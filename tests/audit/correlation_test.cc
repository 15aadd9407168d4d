// Pearson correlation against a hand computation, and the 5 % threshold of
// |r| against published tables of Student's t and of the correlation
// coefficient.
#include <cmath>

#include <gtest/gtest.h>

#include "robomach/audit/correlation.h"

namespace robomach::audit {
namespace {

Eigen::VectorXd V(std::initializer_list<double> v) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double x : v) out(i++) = x;
  return out;
}

// By hand: x̄ = 3, ȳ = 4; deviations (−2, −1, 0, 1, 2) and (−2, 0, 1, 0, 1);
// Sxy = 4 + 0 + 0 + 0 + 2 = 6, Sxx = 10, Syy = 6; r = 6 / √60.
TEST(PearsonCorrelation, MatchesHandComputation) {
  const Eigen::VectorXd x = V({1, 2, 3, 4, 5}), y = V({2, 4, 5, 4, 5});
  // A few roundings of numbers of order 10: 1e-15 relative; 1e-14 is margin.
  EXPECT_NEAR(PearsonCorrelation(x, y), 6.0 / std::sqrt(60.0), 1e-14);
  EXPECT_NEAR(PearsonCorrelation(x, -y), -6.0 / std::sqrt(60.0), 1e-14);
  // Invariant under affine maps with positive scale (the unit of a
  // descriptor does not matter: rad or deg, m or mm), even with a large offset.
  EXPECT_NEAR(PearsonCorrelation(57.3 * x.array() + 1e4, 1e-3 * y.array() + 2.0), 6.0 / std::sqrt(60.0), 1e-12);
  EXPECT_NEAR(PearsonCorrelation(x, 3.0 * x.array() - 1.0), 1.0, 1e-15);
}

TEST(PearsonCorrelation, IsUndefinedWithoutSpreadOrPoints) {
  EXPECT_TRUE(std::isnan(PearsonCorrelation(V({1, 1, 1}), V({1, 2, 3}))));
  EXPECT_TRUE(std::isnan(PearsonCorrelation(V({1, 2, 3}), V({4, 4, 4}))));
  EXPECT_TRUE(std::isnan(PearsonCorrelation(V({1}), V({2}))));
  EXPECT_THROW(PearsonCorrelation(V({1, 2}), V({1, 2, 3})), std::invalid_argument);
}

// Two-sided 5 % points of Student's t, t_0.975(ν), as printed to three
// decimals in every statistics table (e.g. Abramowitz & Stegun 1964,
// Table 26.10): ν = 1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571,
// 10: 2.228, 20: 2.086, 30: 2.042. From r_c, t_c = r_c √ν / √(1 − r_c²).
// Tolerance: half a unit in the last printed digit.
TEST(CriticalCorrelation, MatchesPublishedStudentTQuantiles) {
  const std::pair<int, double> table[] = {{1, 12.706}, {2, 4.303}, {3, 3.182}, {4, 2.776},
                                          {5, 2.571},  {10, 2.228}, {20, 2.086}, {30, 2.042}};
  for (const auto& [nu, t] : table) {
    const double r = CriticalCorrelation(nu + 2);
    EXPECT_NEAR(r * std::sqrt(nu) / std::sqrt(1.0 - r * r), t, 5e-4) << "nu = " << nu;
  }
}

// Critical values of r at 5 %, two-sided, as tabulated for n points
// (Fisher & Yates' tables, three decimals): n = 3: 0.997, 5: 0.878,
// 7: 0.754, 10: 0.632, 12: 0.576, 22: 0.423.
TEST(CriticalCorrelation, MatchesPublishedCorrelationTable) {
  const std::pair<int, double> table[] = {{3, 0.997}, {5, 0.878}, {7, 0.754}, {10, 0.632}, {12, 0.576}, {22, 0.423}};
  for (const auto& [n, rc] : table) EXPECT_NEAR(CriticalCorrelation(n), rc, 5e-4) << "n = " << n;
  // A stricter level needs a larger |r|; fewer than 3 points: undefined.
  EXPECT_GT(CriticalCorrelation(10, 0.01), CriticalCorrelation(10, 0.05));
  EXPECT_TRUE(std::isnan(CriticalCorrelation(2)));
  EXPECT_THROW(CriticalCorrelation(10, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::audit
