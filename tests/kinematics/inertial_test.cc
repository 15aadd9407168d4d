#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/kinematics/serial_chain.h"

namespace robomach::kinematics {
namespace {

using ::testing::HasSubstr;

TEST(CheckInertial, AcceptsPhysicalBodiesAndNamesTheViolation) {
  Inertial rod;  // a thin rod: I1 ≈ 0, I2 = I3 — the triangle inequality's edge
  rod.mass = 2.0;
  rod.inertia_com = Eigen::Vector3d(1e-9, 0.5, 0.5).asDiagonal();
  EXPECT_FALSE(CheckInertial(rod).has_value());
  Inertial massless;
  EXPECT_FALSE(CheckInertial(massless).has_value());
  Inertial bad = rod;
  bad.inertia_com(0, 0) = -0.1;
  EXPECT_THAT(*CheckInertial(bad), HasSubstr("not positive definite"));
  bad = rod;
  bad.inertia_com = Eigen::Vector3d(0.1, 0.1, 0.3).asDiagonal();
  EXPECT_THAT(*CheckInertial(bad), HasSubstr("triangle inequality"));
  bad = rod;
  bad.inertia_com(0, 1) = 0.2;
  EXPECT_THAT(*CheckInertial(bad), HasSubstr("not symmetric"));
  bad = rod;
  bad.mass = -1.0;
  EXPECT_THAT(*CheckInertial(bad), HasSubstr("mass must be finite and >= 0"));
}

// Two point masses 1 kg at x = ±0.5 m: the combined body has its COM at the
// origin and I_yy = I_zz = 2 · 1 · 0.25 = 0.5 kg·m² (parallel-axis theorem).
TEST(CombineInertials, ParallelAxisTheoremForTwoPointMasses) {
  Inertial a, b;
  a.mass = b.mass = 1.0;
  a.com = Eigen::Vector3d(0.5, 0, 0);
  b.com = Eigen::Vector3d(-0.5, 0, 0);
  const Inertial c = CombineInertials(a, b);
  EXPECT_DOUBLE_EQ(c.mass, 2.0);
  EXPECT_LE(c.com.norm(), 1e-15);
  EXPECT_LE((c.inertia_com - Eigen::Vector3d(0.0, 0.5, 0.5).asDiagonal().toDenseMatrix()).norm(), 1e-15);
}

// Rotating a body's frame rotates its inertia tensor: R I Rᵀ, COM X·c.
TEST(TransformInertial, RotatesTensorAndMovesCom) {
  Inertial b;
  b.mass = 3.0;
  b.com = Eigen::Vector3d(0.1, 0.0, 0.0);
  b.inertia_com = Eigen::Vector3d(0.1, 0.2, 0.3).asDiagonal();
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0, 0, 1);
  const Inertial t = TransformInertial(b, X);
  EXPECT_LE((t.com - Eigen::Vector3d(0, 0.1, 1)).norm(), 1e-15);
  EXPECT_NEAR(t.inertia_com(0, 0), 0.2, 1e-15);
  EXPECT_NEAR(t.inertia_com(1, 1), 0.1, 1e-15);
  EXPECT_NEAR(t.inertia_com(2, 2), 0.3, 1e-15);
}

}  // namespace
}  // namespace robomach::kinematics
