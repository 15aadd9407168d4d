// The joint_damping effect: non-proportional viscous damping at the joints.
#include <cmath>
#include <complex>

#include <gtest/gtest.h>

#include "effect_test_support.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/kinematics/modified_dh.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::ExpectValidSystem;
using robomach::testing::Kr210;
using robomach::testing::Kr210With;

// One joint about base z with a link of mass m, COM at l_c, and a tip at l:
// a 1-DOF torsional oscillator with I = m l_c² + I_zz, k, c, and the tip
// moving l·(−sin q, cos q, 0) per rad. Closed form:
//   H_T(ω) = J_v J_vᵀ / (k − ω² I + iω c).
// Both routes (direct solve, state-space complex modes) divide by the same
// scalar up to eigen-solver rounding: ≈ 1e-12 relative with ζ ≈ 5 %
// (the complex modes lose ≈ 1/(2ζ) digits near resonance); 1e-9 is safe.
TEST(JointDamping, SingleJointMatchesClosedFormByBothRoutes) {
  constexpr double m = 8.0, lc = 0.4, l = 0.9, Izz = 0.3, k = 2e4, c = 60.0;
  kinematics::ModifiedDhRow r;
  r.joint_name = "j1";
  r.inertial.mass = m;
  r.inertial.com = Eigen::Vector3d(lc, 0.0, 0.0);
  r.inertial.inertia_com = Eigen::Vector3d(0.05, Izz, Izz).asDiagonal();
  Eigen::Isometry3d X_nT = Eigen::Isometry3d::Identity();
  X_nT.translation() = Eigen::Vector3d(l, 0.0, 0.0);
  RobotDescription d;
  d.arm = kinematics::BuildModifiedDhChain({r}, Eigen::Isometry3d::Identity(), X_nT);
  d.joint_stiffness = Eigen::VectorXd::Constant(1, k);
  d.end_effector.p_tcp = Eigen::Vector3d::Zero();
  d.effects.push_back({"joint_damping", {{"c1_Nms_per_rad", c}}});
  const auto model = RobotModel::Build(d);
  const double q = 0.6;
  const PostureDynamics pd = EvaluatePosture(model, Eigen::VectorXd::Constant(1, q));
  EXPECT_FALSE(pd.proportional_damping);
  const double I = m * lc * lc + Izz;
  const Eigen::Vector3d Jv(-l * std::sin(q), l * std::cos(q), 0.0);
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(200, 1.0, 60.0);  // f_n ≈ 25 Hz
  const auto Hd = ReceptanceDirect(pd.system, f);
  const auto Hc = Receptance(pd, f);
  for (int i = 0; i < f.size(); ++i) {
    const double w = HzToRadPerSec(f(i));
    const Eigen::Matrix3cd H = (Jv * Jv.transpose()).cast<std::complex<double>>() /
                               std::complex<double>(k - w * w * I, w * c);
    EXPECT_LE((Hd[i] - H).norm(), 1e-9 * H.norm()) << f(i);
    EXPECT_LE((Hc[i] - H).norm(), 1e-9 * H.norm()) << f(i);
  }
  // The damping ratio reported for the mode: ζ = c / (2 √(k I)).
  ASSERT_EQ(pd.modes.size(), 1u);
  EXPECT_NEAR(pd.modes[0].damping_ratio, c / (2.0 * std::sqrt(k * I)), 1e-9);
}

// On the KR210: the FRF equals the direct formula assembled by hand from the
// base model's M_q, K_q, J_v, α, β and diag(c), and the state-space modal
// route agrees with it. Both are exact for non-proportional damping; the
// modal route's rounding near the lightly damped resonances (ζ ≈ 1–5 %) is
// ≈ 1e-11, so 1e-8 relative (per frequency, of |H|) is safe.
TEST(JointDamping, Kr210FrfEqualsHandAssembledDirectSolveAndComplexModes) {
  const auto base = Kr210();
  const auto model = Kr210With({{"joint_damping", {}}});
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.2, -1.2, 1.5, 0.3, 0.8, -0.5).finished();
  const PostureDynamics p0 = EvaluatePosture(base, q);
  const PostureDynamics p1 = EvaluatePosture(model, q);
  ExpectValidSystem(p1.system);
  Eigen::VectorXd c(6);
  for (int j = 0; j < 6; ++j) c(j) = model->parameters().Get("joint_damping.c" + std::to_string(j + 1) + "_Nms_per_rad");
  const Eigen::MatrixXd M = p0.M_q(), K = p0.K_q();
  const Eigen::MatrixXd C = base->alpha() * K + base->beta() * M + Eigen::MatrixXd(c.asDiagonal());
  const Eigen::MatrixXd Jv = p0.J_BT.topRows<3>();
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(300, 2.0, 400.0);
  const auto Hd = ReceptanceDirect(p1.system, f);
  const auto Hc = Receptance(p1, f);
  for (int i = 0; i < f.size(); ++i) {
    const double w = HzToRadPerSec(f(i));
    const Eigen::MatrixXcd Z = (K - w * w * M).cast<std::complex<double>>() +
                               std::complex<double>(0.0, w) * C.cast<std::complex<double>>();
    const Eigen::Matrix3cd H = Jv.cast<std::complex<double>>() *
                               Z.partialPivLu().solve(Jv.transpose().cast<std::complex<double>>());
    EXPECT_LE((Hd[i] - H).norm(), 1e-8 * H.norm()) << f(i);
    EXPECT_LE((Hc[i] - H).norm(), 1e-8 * H.norm()) << f(i);
  }
  // More damping than Rayleigh alone: every mode's damping ratio grows.
  for (size_t k = 0; k < p0.modes.size(); ++k) {
    EXPECT_GT(p1.modes[k].damping_ratio, p0.modes[k].damping_ratio) << "mode " << k;
  }
}

}  // namespace
}  // namespace robomach::dynamics
