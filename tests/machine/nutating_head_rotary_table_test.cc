// Kinematics of the 45° nutating head + C table (formats.md §8.3) against an
// independent homogeneous 4x4 transform chain built with Eigen's AngleAxis,
// and the inverse against the forward.
#include "robomach/machine/nutating_head_rotary_table.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "robomach/common/units.h"
#include "robomach/machine/kinematics_kinds.h"

namespace robomach::machine {
namespace {

NutatingHeadGeometry SeedLike(bool errors) {
  NutatingHeadGeometry g;
  g.nutation = DegToRad(45.0);
  g.pivot_length = 0.300;
  g.tool_length = 0.120;
  g.c_centre = {0.400, -0.500};
  g.zero_offset = {0.350, -0.520, -0.600};
  if (errors) {
    g.b_eccentricity = {4e-6, -3e-6};
    g.pivot_length_error = 6e-6;
    g.c_eccentricity = {5e-6, 2e-6};
  }
  return g;
}

// The seed's chain workpiece - C - Y - X - Z - B - tool written as 4x4
// homogeneous transforms [seed 002, eqs. (6)-(12)]: T_WM maps machine to
// workpiece coordinates, T_MT the tool frame (tip at its origin, tool axis its
// z) to machine coordinates.
ToolPose ChainOf4x4(const NutatingHeadGeometry& g, const Eigen::Matrix<double, 5, 1>& q) {
  using Eigen::Affine3d;
  using Eigen::AngleAxisd;
  using Eigen::Translation3d;
  using Eigen::Vector3d;
  const Vector3d u(0.0, std::sin(g.nutation), std::cos(g.nutation));
  const double L = g.pivot_length, t1 = g.tool_length, dL = g.pivot_length_error;
  const Affine3d T_lin(Translation3d(q(0), q(1), q(2)));                                    // eq. (6)
  const Affine3d T_B = Translation3d(g.b_eccentricity[0], g.b_eccentricity[1], L + t1) *   // eq. (11)
                       AngleAxisd(q(3), u) * Translation3d(0.0, 0.0, -(L + dL + t1));
  const Vector3d c(g.c_centre[0] + g.c_eccentricity[0], g.c_centre[1] + g.c_eccentricity[1], 0.0);
  const Vector3d o(g.zero_offset[0], g.zero_offset[1], g.zero_offset[2]);
  const Affine3d T_o(Translation3d(-o));                                                      // eq. (8)
  const Affine3d T_C = Translation3d(c) * AngleAxisd(-q(4), Vector3d::UnitZ()) * Translation3d(-c);  // (9), (12)
  const Eigen::Matrix4d T = (T_o * T_C * T_lin * T_B).matrix();
  ToolPose p;
  p.p_W = T.block<3, 1>(0, 3);
  p.k_W = T.block<3, 1>(0, 2);
  return p;
}

Eigen::VectorXd RandomQ(std::mt19937& rng) {
  std::uniform_real_distribution<double> x(0.0, 0.8), y(-1.05, 0.0), z(-0.85, 0.0), b(DegToRad(-180), DegToRad(-30)),
      c(0.0, 2.0 * kPi);
  Eigen::VectorXd q(5);
  q << x(rng), y(rng), z(rng), b(rng), c(rng);
  return q;
}

TEST(NutatingHeadRotaryTable, ForwardMatchesIndependent4x4Chain) {
  std::mt19937 rng(42);
  for (bool errors : {false, true}) {
    const NutatingHeadRotaryTable m(SeedLike(errors));
    for (int i = 0; i < 200; ++i) {
      const Eigen::VectorXd q = RandomQ(rng);
      const ToolPose a = m.Forward(q);
      const ToolPose b = ChainOf4x4(SeedLike(errors), q);
      // Both are a handful of products of O(1 m) terms: 1e-14 m is ~50 ulps.
      EXPECT_LT((a.p_W - b.p_W).norm(), 1e-14);
      EXPECT_LT((a.k_W - b.k_W).norm(), 1e-14);
    }
  }
}

TEST(NutatingHeadRotaryTable, BZeroWithoutErrorsPutsTipAtXYZ) {
  NutatingHeadGeometry g = SeedLike(false);
  g.zero_offset = {0.0, 0.0, 0.0};
  const NutatingHeadRotaryTable m(g);
  Eigen::VectorXd q(5);
  q << 0.123, -0.456, -0.321, 0.0, 0.0;
  const ToolPose p = m.Forward(q);
  EXPECT_LT((p.p_W - q.head<3>()).norm(), 1e-15);
  EXPECT_LT((p.k_W - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
}

TEST(NutatingHeadRotaryTable, BMinus180Gives90DegreeToolAxis) {
  // A 45° nutating head swings the spindle from vertical (B = 0) to
  // horizontal (B = ±180°): R(u, B) e_z = cos B e_z + sin B (u x e_z) + (1 - cos B)(u.e_z) u
  // = (sn sin B, cn sn (1 - cos B), cn^2 + sn^2 cos B) = (0, 2 sn cn, 0) = (0, 1, 0).
  const NutatingHeadRotaryTable m(SeedLike(false));
  Eigen::VectorXd q(5);
  q << 0.4, -0.5, -0.3, DegToRad(-180.0), 0.0;
  EXPECT_LT((m.Forward(q).k_W - Eigen::Vector3d(0.0, 1.0, 0.0)).norm(), 1e-15);
}

TEST(NutatingHeadRotaryTable, InverseOfForwardIsIdentityForBothBSolutions) {
  std::mt19937 rng(7);
  for (bool errors : {false, true}) {
    const NutatingHeadRotaryTable m(SeedLike(errors));
    for (int i = 0; i < 500; ++i) {
      const Eigen::VectorXd q = RandomQ(rng);
      const ToolPose pose = m.Forward(q);
      const auto sols = m.InverseSolutions(pose, q);
      ASSERT_EQ(sols.size(), 2u);
      int matches = 0;
      for (const auto& s : sols) {
        // Every solution reproduces the pose.
        const ToolPose back = m.Forward(s);
        EXPECT_LT((back.p_W - pose.p_W).norm(), 1e-9);
        EXPECT_LT((back.k_W - pose.k_W).norm(), 1e-9);
        const double dB = std::remainder(s(3) - q(3), 2 * kPi), dC = std::remainder(s(4) - q(4), 2 * kPi);
        if ((s.head<3>() - q.head<3>()).norm() < 1e-9 && std::abs(dB) < 1e-9 && std::abs(dC) < 1e-9) ++matches;
      }
      EXPECT_EQ(matches, 1) << "q = " << q.transpose();
      // The nearest-previous choice gives back q itself, unwrapped.
      Eigen::VectorXd prev = q;
      prev(3) += 0.01;
      prev(4) -= 0.01;
      const InverseResult r = m.Inverse(pose, prev);
      ASSERT_EQ(r.status, InverseStatus::kOk);
      EXPECT_LT((r.q - q).norm(), 1e-9);
      // From near the other solution it picks the other one.
      const Eigen::VectorXd& other = std::abs(std::remainder(sols[0](3) - q(3), 2 * kPi)) < 1e-9 ? sols[1] : sols[0];
      EXPECT_LT(std::abs(std::remainder(m.Inverse(pose, other).q(3) - other(3), 2 * kPi)), 1e-9);
    }
  }
}

TEST(NutatingHeadRotaryTable, InverseUnwrapsCByWholeTurns) {
  const NutatingHeadRotaryTable m(SeedLike(true));
  Eigen::VectorXd q(5);
  q << 0.3, -0.4, -0.2, DegToRad(-60.0), DegToRad(725.0);  // two turns and 5°
  const InverseResult r = m.Inverse(m.Forward(q), q);
  EXPECT_NEAR(r.q(4), q(4), 1e-9);
}

TEST(NutatingHeadRotaryTable, UnreachableToolAxisIsAStatus) {
  const NutatingHeadRotaryTable m(SeedLike(false));
  ToolPose p;
  p.k_W = Eigen::Vector3d(0.0, 0.0, -1.0);  // pointing up from below: beyond 90° of tilt
  Eigen::VectorXd prev = Eigen::VectorXd::Zero(5);
  EXPECT_EQ(m.Inverse(p, prev).status, InverseStatus::kUnreachableAxis);
}

TEST(NutatingHeadRotaryTable, RejectsBadGeometry) {
  NutatingHeadGeometry g;
  g.nutation = 0.0;
  EXPECT_THROW(NutatingHeadRotaryTable{g}, std::invalid_argument);
}

// Issue #36: the machine file's kinematics types are one registry; its one
// kind builds this class from the geometry, and an unknown type is refused
// naming the known ones.
TEST(KinematicsKinds, BuildTheNutatingHeadByName) {
  EXPECT_EQ(KinematicsKinds().Names(), (std::vector<std::string>{"nutating_head_rotary_table"}));
  const NutatingHeadGeometry g = SeedLike(true);
  const std::shared_ptr<const MachineKinematics> k = KinematicsKinds().Find("nutating_head_rotary_table")(g);
  const auto* head = dynamic_cast<const NutatingHeadRotaryTable*>(k.get());
  ASSERT_NE(head, nullptr);
  EXPECT_EQ(head->geometry().pivot_length_error, g.pivot_length_error);
  try {
    KinematicsKinds().Find("table_table");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "unknown kinematics type 'table_table': expected nutating_head_rotary_table");
  }
}

}  // namespace
}  // namespace robomach::machine
