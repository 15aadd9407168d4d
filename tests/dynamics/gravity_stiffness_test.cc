// The gravity_stiffness effect: ∂G/∂q (the Hessian of the gravitational
// potential) added to the joint stiffness.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <kdl/chaindynparam.hpp>

#include "effect_test_support.h"
#include "robomach/common/units.h"
#include "robomach/kinematics/modified_dh.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::ExpectValidSystem;
using robomach::testing::Kr210;
using robomach::testing::Kr210With;
using robomach::testing::RandomPosture;

constexpr double kG = kStandardGravity;  // [m/s²]

using robomach::testing::Pendulum;  // V = m g l_c sin q (test_models.h)

// Closed form of the single pendulum; the products in (1) round at ~eps of
// m g l_c, so 1e-12 relative.
TEST(GravityStiffness, SinglePendulumMatchesClosedFormWithSign) {
  constexpr double m = 12.0, lc = 0.7, k = 1e5;
  RobotDescription d = Pendulum(m, lc);
  d.effects.push_back({"gravity_stiffness", {}});
  const auto model = RobotModel::Build(d);
  for (double q : {-kPi / 2, -1.0, 0.0, 0.4, kPi / 2, 2.5}) {
    const PostureDynamics pd = EvaluatePosture(model, Eigen::VectorXd::Constant(1, q));
    const double expected = k - m * kG * lc * std::sin(q);
    EXPECT_NEAR(pd.system.K(0, 0), expected, 1e-12 * k) << "q = " << q;
  }
  // Hanging down stiffens, upright softens.
  EXPECT_GT(EvaluatePosture(model, Eigen::VectorXd::Constant(1, -kPi / 2)).system.K(0, 0), k);
  EXPECT_LT(EvaluatePosture(model, Eigen::VectorXd::Constant(1, kPi / 2)).system.K(0, 0), k);
}

// Second method on the KR210: central differences of KDL's gravity torque
// G(q) (ChainDynParam::JntToGravity, recursive Newton–Euler), which shares
// nothing with the effect's closed form but the chain. |G| ≈ 1e4 N·m and
// its third derivatives are of the same order, so with h = 1e-4 rad the
// truncation is ≈ h²/6·1e4 ≈ 2e-5 and the round-off ≈ eps·1e4/h ≈ 2e-8 N·m;
// 1e-3 N·m/rad against Hessian entries of 1e3–1e4 leaves margin.
TEST(GravityStiffness, MatchesFiniteDifferencesOfKdlGravityTorque) {
  const auto base = Kr210();
  const auto model = Kr210With({{"gravity_stiffness", {}}});
  KDL::ChainDynParam dyn(model->chain().kdl(), KDL::Vector(0.0, 0.0, -kG));
  auto G = [&](const Eigen::VectorXd& q) {
    KDL::JntArray jq(6), g(6);
    jq.data = q;
    dyn.JntToGravity(jq, g);
    return Eigen::VectorXd(g.data);
  };
  std::mt19937 rng(12);
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const PostureDynamics p0 = EvaluatePosture(base, q);
    const PostureDynamics p1 = EvaluatePosture(model, q);
    ExpectValidSystem(p1.system);
    const Eigen::MatrixXd dK = p1.K_q() - p0.K_q();
    Eigen::MatrixXd fd(6, 6);
    const double h = 1e-4;
    for (int j = 0; j < 6; ++j) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(6, j);
      fd.col(j) = (G(q + h * e) - G(q - h * e)) / (2 * h);
    }
    EXPECT_LE((dK - fd).cwiseAbs().maxCoeff(), 1e-3) << "trial " << trial << "\n" << dK << "\n" << fd;
    EXPECT_GT(dK.cwiseAbs().maxCoeff(), 1e2);  // the effect is not empty
  }
}

// gravity_scale = 0 switches it off exactly; the term is linear in the scale.
TEST(GravityStiffness, IsLinearInTheGravityScale) {
  const auto base = Kr210();
  const auto half = Kr210With({{"gravity_stiffness", {{"gravity_scale", 0.5}}}});
  const auto full = Kr210With({{"gravity_stiffness", {}}});
  const auto none = Kr210With({{"gravity_stiffness", {{"gravity_scale", 0.0}}}});
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.1, -1.3, 1.7, 0.2, 0.6, 0.3).finished();
  const Eigen::MatrixXd K0 = EvaluatePosture(base, q).K_q();
  EXPECT_EQ(EvaluatePosture(none, q).K_q(), K0);
  const Eigen::MatrixXd dh = EvaluatePosture(half, q).K_q() - K0;
  const Eigen::MatrixXd df = EvaluatePosture(full, q).K_q() - K0;
  // Rounding of K0 + ΔK − K0 at K0 ≈ 4e6: ≈ eps·4e6 ≈ 1e-9 N·m/rad.
  EXPECT_LE((df - 2.0 * dh).cwiseAbs().maxCoeff(), 1e-8);
}

}  // namespace
}  // namespace robomach::dynamics
