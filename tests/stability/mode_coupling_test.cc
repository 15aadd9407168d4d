#include "robomach/stability/mode_coupling.h"

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/common/units.h"

namespace robomach::stability {
namespace {

// Classic 2-DOF mode coupling [Tlusty 2000]: equal masses m,
// stiffnesses k1 ≠ k2 along x and y, no damping, and the slot cutting
// stiffness K_c = (N/4)[[Kr, Kt], [−Kt, Kr]] (milling.h (3)). The stiffness
// K + a K_c = [[k1 + a c r, a c], [−a c, k2 + a c r]] with c = N Kt/4 has
// complex eigenvalues (flutter) iff (k1 − k2)² < 4 a² c², so
//   a_crit = |k1 − k2| / (2 c) = |k1 − k2| / (N K_t / 2).
MillingProcess Slot() {
  MillingProcess p;
  p.teeth = 2;
  p.radial_immersion = 1.0;
  p.coefficients = {6e8, 2e8, 0.0};
  return p;
}

TEST(ModeCoupling, TwoDofUndampedFlutterMatchesClosedForm) {
  const double m = 20.0, k1 = 2.0e6, k2 = 3.1e6, k3 = 5e6;
  const MillingProcess p = Slot();
  const double a_closed = std::abs(k1 - k2) / (p.teeth * p.coefficients.Kt / 2.0);
  const Eigen::Matrix3d Kc = CuttingStiffnessPerDepth(p);
  Eigen::MatrixXd M = m * Eigen::MatrixXd::Identity(3, 3);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(3, 3);
  Eigen::MatrixXd K = Eigen::Vector3d(k1, k2, k3).asDiagonal();
  ModeCouplingOptions opt;
  opt.max_depth = 0.05;
  opt.depth_tolerance = 1e-6;
  const ModeCouplingResult r = CriticalDepthModeCoupling(M, C, K, Matrix3Xd::Identity(3, 3), Kc, opt);
  ASSERT_EQ(r.status, ModeCouplingStatus::kFound);
  EXPECT_TRUE(r.flutter);
  // Bisection stops at a bracket of 1e-6 relative around the crossing; the
  // 1e-9|λ| growth threshold moves it by ~(1e-9)² (Re λ ∝ √(a − a_c)).
  EXPECT_NEAR(r.critical_depth, a_closed, 1e-6 * a_closed);
  // At the flutter point the coalescing frequency is that of the mean
  // stiffness: ω² = (k1 + k2 + 2 a c r)/(2m) (trace/2 of M⁻¹(K + aK_c)).
  const double c = p.teeth * p.coefficients.Kt / 4.0, rr = p.coefficients.Kr / p.coefficients.Kt;
  const double w = std::sqrt((k1 + k2 + 2.0 * a_closed * c * rr) / (2.0 * m));
  // Near coalescence Im λ moves by O(√(a − a_c)) ~ √1e-6 relative.
  EXPECT_NEAR(r.chatter_freq_hz, w / (2.0 * kPi), 2e-3 * w / (2.0 * kPi));

  // The closed form (2) of the header gives the same number (exactly the
  // same algebra, evaluated by the quadratic formula: rounding only).
  const Eigen::Matrix2d S = K.topLeftCorner(2, 2);
  EXPECT_NEAR(FlutterDepthClosedForm(S, Kc.topLeftCorner<2, 2>()), a_closed, 1e-12 * a_closed);
}

// Rotating the structure leaves the 2-DOF flutter condition of a
// general (non-diagonal) S: the eigenvalue search and the quadratic (2)
// agree for arbitrary orientation of the principal stiffness axes.
TEST(ModeCoupling, RotatedStructureEigenvalueSearchMatchesQuadratic) {
  const double m = 15.0;
  const MillingProcess p = [] {
    MillingProcess q = Slot();
    q.radial_immersion = 0.4;
    q.direction = MillingDirection::kUp;
    return q;
  }();
  const Eigen::Matrix2d Kc = CuttingStiffnessPerDepth(p).topLeftCorner<2, 2>();
  for (double angle_deg : {0.0, 20.0, 45.0, 70.0, 110.0, 160.0}) {
    const double t = DegToRad(angle_deg);
    Eigen::Matrix2d R;
    R << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
    const Eigen::Matrix2d S = R * Eigen::Vector2d(1.5e6, 4.0e6).asDiagonal() * R.transpose();
    const double a_q = FlutterDepthClosedForm(S, Kc);
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3, 3);
    K.topLeftCorner(2, 2) = S;
    K(2, 2) = 1e7;
    ModeCouplingOptions opt;
    opt.max_depth = 1.0;
    opt.scan_points = 30;
    opt.depth_tolerance = 1e-7;
    Eigen::Matrix3d Kc3 = Eigen::Matrix3d::Zero();
    Kc3.topLeftCorner<2, 2>() = Kc;
    const ModeCouplingResult r =
        CriticalDepthModeCoupling(m * Eigen::MatrixXd::Identity(3, 3), Eigen::MatrixXd::Zero(3, 3), K,
                                  Matrix3Xd::Identity(3, 3), Kc3, opt);
    if (std::isinf(a_q)) {
      EXPECT_EQ(r.status, ModeCouplingStatus::kStableUpToMax) << angle_deg;
      continue;
    }
    ASSERT_EQ(r.status, ModeCouplingStatus::kFound) << angle_deg;
    // Bracket 1e-7 relative; the growth threshold is negligible (above).
    EXPECT_NEAR(r.critical_depth, a_q, 2e-7 * a_q) << angle_deg << " deg";
  }
}

// Damping delays the onset: with C = 2ζ√(km) per axis the crossing needs a
// larger depth than the undamped flutter point (a necessary property, not
// a number: damping only moves eigenvalues left at a = a_c).
TEST(ModeCoupling, DampingRaisesTheCriticalDepth) {
  const double m = 20.0, k1 = 2.0e6, k2 = 3.1e6;
  const Eigen::Matrix3d Kc = CuttingStiffnessPerDepth(Slot());
  Eigen::MatrixXd K = Eigen::Vector3d(k1, k2, 5e6).asDiagonal();
  Eigen::MatrixXd M = m * Eigen::MatrixXd::Identity(3, 3);
  Eigen::MatrixXd C = Eigen::Vector3d(2 * 0.02 * std::sqrt(k1 * m), 2 * 0.02 * std::sqrt(k2 * m),
                                      2 * 0.02 * std::sqrt(5e6 * m)).asDiagonal();
  const auto undamped = CriticalDepthModeCoupling(M, Eigen::MatrixXd::Zero(3, 3), K,
                                                  Matrix3Xd::Identity(3, 3), Kc);
  const auto damped = CriticalDepthModeCoupling(M, C, K, Matrix3Xd::Identity(3, 3), Kc);
  ASSERT_EQ(damped.status, ModeCouplingStatus::kFound);
  EXPECT_GT(damped.critical_depth, undamped.critical_depth * (1.0 + 1e-3));
}

}  // namespace
}  // namespace robomach::stability
