// Golden-section search against closed-form maxima.
#include <gtest/gtest.h>

#include <cmath>

#include "robomach/common/golden_section.h"

namespace robomach {
namespace {

// −(x − 0.3)² on [0, 1]: maximum 0 at 0.3. After 80 reductions by 0.618 the
// bracket is below the 1e-12 stopping length, so x is within 1e-12.
TEST(GoldenSection, FindsTheVertexOfAParabola) {
  int calls = 0;
  const auto f = [&](double x) {
    ++calls;
    return -(x - 0.3) * (x - 0.3);
  };
  const auto [x, fx] = GoldenSectionMaximum(f, 0.0, 1.0, 80, 1e-12);
  EXPECT_NEAR(x, 0.3, 1e-12);
  EXPECT_NEAR(fx, 0.0, 1e-24);
  // ln(1e-12)/ln(0.618) ≈ 57 reductions, one evaluation each, plus 3.
  EXPECT_LE(calls, 61);
}

// sin x + 0.5 sin 3x + 0.05 x on [0, 2π] has local maxima at x ≈ 0.713
// (f = 1.111) and x ≈ 2.451 (f = 1.198, the global one) and a lower one at
// 4.73 (a dense scan with step 1e-4, done by hand); the grid keeps the
// refinement out of the wrong one.
TEST(GoldenSection, GridThenRefinementFindsTheGlobalMaximum) {
  const auto f = [](double x) { return std::sin(x) + 0.5 * std::sin(3.0 * x) + 0.05 * x; };
  const auto [x, fx] = MaximiseOnGrid(f, 0.0, 2.0 * M_PI, 40, 80, 1e-13);
  // Independent reference: the stationarity condition cos x + 1.5 cos 3x +
  // 0.05 = 0 (f is flat to round-off within √eps ≈ 1e-8 of the maximum, so
  // x is good to ~1e-8 and f' = f'' Δx to ~1e-7 with |f''| ≈ 5), and no
  // point of a dense scan (step 1e-5) above the result.
  EXPECT_NEAR(x, 2.4509, 1e-4);
  EXPECT_NEAR(std::cos(x) + 1.5 * std::cos(3.0 * x) + 0.05, 0.0, 1e-6);
  double best = -1e300;
  for (double t = 0.0; t <= 2.0 * M_PI; t += 1e-5) best = std::max(best, f(t));
  EXPECT_GE(fx, best - 1e-12);
}

}  // namespace
}  // namespace robomach
