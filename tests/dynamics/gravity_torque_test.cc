// GravityTorque (KDL's recursive Newton–Euler gravity term) against two
// independent references: the closed form of a pendulum, and central
// differences of the potential energy V(q) = −Σ m_i gᵀ c_i(q) summed body by
// body from the forward kinematics of each segment.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/dynamics/gravity_torque.h"
#include "robomach/kinematics/modified_dh.h"
#include "robomach/kinematics/serial_chain.h"
#include "test_models.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::Kr210;
using robomach::testing::RandomPosture;

using robomach::testing::Pendulum;  // V = m g l_c sin q (test_models.h)

// The recursion rounds at ~eps · m g l_c ≈ 1e-13 N·m; 1e-10 N·m leaves margin.
TEST(GravityTorque, PendulumMatchesClosedForm) {
  constexpr double m = 12.0, lc = 0.7;
  const auto model = RobotModel::Build(Pendulum(m, lc));
  for (double q : {-kPi / 2, -1.0, 0.0, 0.4, kPi / 2, 2.5}) {
    const Eigen::VectorXd G = GravityTorque(*model, Eigen::VectorXd::Constant(1, q));
    ASSERT_EQ(G.size(), 1);
    EXPECT_NEAR(G(0), m * kStandardGravity * lc * std::cos(q), 1e-10) << "q = " << q;
  }
  // Linear in the gravity magnitude (0 switches it off).
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, 0.3);
  EXPECT_NEAR(GravityTorque(*model, q, 2.0 * kStandardGravity)(0), 2.0 * GravityTorque(*model, q)(0), 1e-10);
  EXPECT_EQ(GravityTorque(*model, q, 0.0)(0), 0.0);
}

// Central differences of V. |V| ≈ 1e4 J on the KR210 (≈ 1300 kg about 1 m
// up) and its third derivatives are of the same order, so with h = 1e-4 rad
// the truncation is ≈ h²/6 · 1e4 ≈ 2e-5 N·m and the round-off
// ≈ eps · 1e4 / h ≈ 2e-8 N·m; 1e-3 N·m keeps a margin of 50 (the torques
// are 1e2–1e4 N·m at these postures).
TEST(GravityTorque, Kr210MatchesFiniteDifferencesOfPotentialEnergy) {
  const auto model = Kr210();
  const kinematics::SerialChain& chain = model->chain();
  auto V = [&](const Eigen::VectorXd& q) {
    double v = 0.0;
    for (int s = 0; s < chain.num_segments(); ++s) {
      const kinematics::Inertial b = chain.segment_inertial(s);
      if (b.mass == 0.0) continue;
      const Eigen::Vector3d c = kinematics::SegmentPose(chain, q, s) * b.com;
      v += b.mass * kStandardGravity * c.z();  // −m gᵀc with g = (0, 0, −g0)
    }
    return v;
  };
  std::mt19937 rng(21);
  const double h = 1e-4;
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const Eigen::VectorXd G = GravityTorque(*model, q);
    ASSERT_EQ(G.size(), 6);
    for (int j = 0; j < 6; ++j) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(6, j);
      const double fd = (V(q + h * e) - V(q - h * e)) / (2.0 * h);
      EXPECT_NEAR(G(j), fd, 1e-3) << "trial " << trial << ", joint " << j + 1;
    }
    EXPECT_GT(G.cwiseAbs().maxCoeff(), 1e2);  // not trivially zero
    // Joint 1 turns about the vertical: gravity does no work on it. Rounding
    // in KDL's frame products: ≈ eps · 1e4 N·m.
    EXPECT_NEAR(G(0), 0.0, 1e-9) << "joint 1";
  }
}

// The end effector is in the chain as built: 10 % more m6 (last link and end
// effector, about 30 kg, ≈ 1.5 m from joint 2 at this posture) adds tens of
// N·m on joint 2.
TEST(GravityTorque, IncludesTheEndEffectorAsBuilt) {
  const io::RobotConfig cfg = robomach::testing::Kr210Config();
  dynamics::ParameterSet heavier = cfg.parameters;
  heavier.Set("m6_kg", 1.1 * cfg.parameters.Get("m6_kg"));
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.0, -1.2, 1.4, 0.0, 0.8, 0.0).finished();
  const double g0 = GravityTorque(*RobotModel::Build(cfg.description, cfg.parameters), q)(1);
  const double g1 = GravityTorque(*RobotModel::Build(cfg.description, heavier), q)(1);
  EXPECT_GT(std::abs(g1 - g0), 10.0) << g0 << " vs " << g1;
}

TEST(GravityTorque, RejectsAWrongSizedPosture) {
  const auto model = Kr210();
  EXPECT_THROW(GravityTorque(*model, Eigen::VectorXd::Zero(5)), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::dynamics
