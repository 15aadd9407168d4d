#include "robomach/stability/milling.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "test_support.h"

namespace robomach::stability {
namespace {

MillingProcess Process(int teeth, double immersion, MillingDirection dir) {
  MillingProcess p;
  p.teeth = teeth;
  p.radial_immersion = immersion;
  p.direction = dir;
  p.coefficients = {6e8, 2e8, 1e8};
  return p;
}

// Slotting (φst = 0, φex = π) has the textbook average
// H0 = (N/4) [[Kr, Kt], [−Kt, Kr]] [Altintas 2000; here in the sign convention F = −a H0 Δx]. The closed
// form (3) evaluates sin/cos at 0 and π, so only rounding remains:
// ~1e-15 relative; 1e-12 leaves margin.
TEST(Milling, SlotAverageMatchesTextbookClosedForm) {
  const MillingProcess p = Process(4, 1.0, MillingDirection::kDown);
  const auto H0 = AverageDirectionalMatrix(p);
  const double Kt = 6e8, Kr = 2e8, N = 4;
  EXPECT_NEAR(H0(0, 0), N / 4 * Kr, 1e-12 * Kt);
  EXPECT_NEAR(H0(0, 1), N / 4 * Kt, 1e-12 * Kt);
  EXPECT_NEAR(H0(1, 0), -N / 4 * Kt, 1e-12 * Kt);
  EXPECT_NEAR(H0(1, 1), N / 4 * Kr, 1e-12 * Kt);
  // Axial row: (N/2π) Ka ∫ sin φ dφ = N Ka/π over [0, π], ∫ cos φ = 0.
  EXPECT_NEAR(H0(2, 0), N * 1e8 / kPi, 1e-12 * Kt);
  EXPECT_NEAR(H0(2, 1), 0.0, 1e-12 * Kt);
}

// Second method: the mean of the instantaneous matrix (2) over one tooth
// period by the midpoint rule with n samples. The integrand is smooth except
// for jumps at entry and exit (at most 2 per tooth and N teeth): each jump
// costs at most |jump|·Δψ, |jump| ≤ max|h| ≤ Kt + Kr (+Ka); the smooth part
// errs by O(Δψ²). Hence |error| ≤ 2N(Kt + Kr + Ka)/n.
TEST(Milling, AverageMatchesSampledMeanOfInstantaneousMatrix) {
  for (auto dir : {MillingDirection::kUp, MillingDirection::kDown}) {
    for (double ae : {0.05, 0.3, 0.5, 0.8, 1.0}) {
      const MillingProcess p = Process(3, ae, dir);
      const int n = 200000;
      const double omega = 100.0, T = 2.0 * kPi / (p.teeth * omega);
      Eigen::Matrix<double, 3, 2> sum = Eigen::Matrix<double, 3, 2>::Zero();
      for (int i = 0; i < n; ++i) sum += DirectionalMatrixAt(p, omega, (i + 0.5) * T / n);
      sum /= n;
      const double tol = 2.0 * p.teeth * (6e8 + 2e8 + 1e8) / n;
      EXPECT_LE((sum - AverageDirectionalMatrix(p)).cwiseAbs().maxCoeff(), tol)
          << "a/D = " << ae << (dir == MillingDirection::kUp ? " up" : " down");
      // Means over sub-intervals (used by the semi-discretization) add up.
      const auto a = MeanDirectionalMatrix(p, 0.0, 0.3 * omega * T);
      const auto b = MeanDirectionalMatrix(p, 0.3 * omega * T, omega * T);
      EXPECT_LE((0.3 * a + 0.7 * b - AverageDirectionalMatrix(p)).cwiseAbs().maxCoeff(), 1e-6);
    }
  }
}

// Engagement angles of Insperger & Stepan 2004 (down: acos(2a/D − 1) .. π;
// up: 0 .. acos(1 − 2a/D)).
TEST(Milling, EngagementAngles) {
  const MillingProcess down = Process(2, 0.05, MillingDirection::kDown);
  EXPECT_DOUBLE_EQ(down.entry_angle(), std::acos(-0.9));
  EXPECT_DOUBLE_EQ(down.exit_angle(), kPi);
  const MillingProcess up = Process(2, 0.05, MillingDirection::kUp);
  EXPECT_DOUBLE_EQ(up.entry_angle(), 0.0);
  EXPECT_DOUBLE_EQ(up.exit_angle(), std::acos(0.9));
}

TEST(Milling, KsBetaForm) {
  const auto c = CuttingCoefficients::FromKsBeta(2e9, DegToRad(70.0));
  EXPECT_NEAR(c.Kt, 2e9 * std::sin(DegToRad(70.0)), 1e-3);
  EXPECT_NEAR(c.Kr, 2e9 * std::cos(DegToRad(70.0)), 1e-3);
}

TEST(Milling, ValidateNamesTheField) {
  using ::testing::HasSubstr;
  MillingProcess p = Process(0, 0.5, MillingDirection::kDown);
  EXPECT_THAT(testing::CaptureError([&] { p.Validate(); }), HasSubstr("teeth"));
  p = Process(2, 1.2, MillingDirection::kDown);
  EXPECT_THAT(testing::CaptureError([&] { p.Validate(); }), HasSubstr("radial_immersion"));
  p = Process(2, 0.0, MillingDirection::kDown);
  EXPECT_THAT(testing::CaptureError([&] { p.Validate(); }), HasSubstr("(0, 1]"));
}

}  // namespace
}  // namespace robomach::stability
