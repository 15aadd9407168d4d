#include "robomach/stability/modal_fit.h"

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/common/units.h"

namespace robomach::stability {
namespace {

// Peak picking recovers the modes an FRF was synthesised from (second
// method: the synthesis (1) of tool_tip_model.h). Errors, derived:
// - frequency: the peak line is within half a log step r/2 of the true
//   resonance, r = ln(f_hi/f_lo)/(lines−1) = ln(10)/19999 ≈ 1.2e-4;
// - damping: the half-power formula is exact to O(ζ²) for a single mode
//   [Ewins 2000] and the other mode adds a fraction
//   q ≈ |H_other(ω_k)|/|H_k(ω_k)| ≈ 2ζ_k ω_k²/|ω_j² − ω_k²| of the peak,
//   here ≈ 0.02·1/1.8 ≈ 1.1e-2, which shifts the half-power points by ~q;
// - shape |p|: scales with √(ζ · peak), so errors of ~q/2 + ζ².
// Tolerances: 2e-4 on f, 2q + ζ² on ζ and |p| relative.
TEST(ModalFit, PeakPickingRecoversWellSeparatedModes) {
  TipModalModel m;
  m.omega_rad_s = Eigen::Vector2d(HzToRadPerSec(300.0), HzToRadPerSec(500.0));
  m.zeta = Eigen::Vector2d(0.01, 0.015);
  m.p = Matrix3Xd::Zero(3, 2);
  m.p.col(0) << 4.0, 1.0, 0.0;   // [1/√kg]
  m.p.col(1) << -1.0, 3.0, 0.0;
  const Eigen::VectorXd f = LogFrequencyGrid(100.0, 1000.0, 20000);
  const auto Phi = InPlaneModalReceptance(m, f);
  const TipModalModel fit = FitModesPeakPicking(f, Phi, 4);
  ASSERT_EQ(fit.num_modes(), 2);
  for (int k = 0; k < 2; ++k) {
    const int j = 1 - k;
    const double wk = m.omega_rad_s(k), wj = m.omega_rad_s(j);
    const double q = 2.0 * m.zeta(k) * wk * wk / std::abs(wj * wj - wk * wk) *
                     (m.p.col(j).head<2>().squaredNorm() / m.p.col(k).head<2>().squaredNorm());
    EXPECT_NEAR(fit.omega_rad_s(k), wk, 2e-4 * wk) << k;
    EXPECT_NEAR(fit.zeta(k), m.zeta(k), (2.0 * q + std::pow(m.zeta(k), 2)) * m.zeta(k)) << k;
    const double n_true = m.p.col(k).norm(), n_fit = fit.p.col(k).norm();
    EXPECT_NEAR(n_fit, n_true, (2.0 * q + std::pow(m.zeta(k), 2)) * n_true) << k;
    // Direction up to sign.
    EXPECT_GT(std::abs(fit.p.col(k).normalized().dot(m.p.col(k).normalized())), 1.0 - 2.0 * q) << k;
  }
}

TEST(ModalFit, DominantModesKeepsTheMostCompliant) {
  TipModalModel m;
  m.omega_rad_s = Eigen::Vector3d(10.0, 20.0, 30.0);
  m.zeta = Eigen::Vector3d(0.01, 0.01, 0.01);
  m.p = Matrix3Xd::Zero(3, 3);
  m.p(0, 0) = 1.0;   // compliance 1/100
  m.p(1, 1) = 3.0;   // 9/400 — the largest
  m.p(2, 2) = 100.0; // axial only: no in-plane compliance
  const TipModalModel d = DominantModes(m, 2);
  ASSERT_EQ(d.num_modes(), 2);
  EXPECT_EQ(d.omega_rad_s(0), 10.0);
  EXPECT_EQ(d.omega_rad_s(1), 20.0);
}

}  // namespace
}  // namespace robomach::stability
