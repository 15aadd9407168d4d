#include "robomach/drilling/drilling_sim.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "drilling/drilling_test_models.h"

namespace robomach::drilling {
namespace {

using testing::PlanarRodArm;
using testing::SeedDrives;
using testing::Q235Like;
using testing::SeedPosture;
using testing::SeedProcess;

TEST(DrillingScenario, DesiredPathFeedsTheTipAlongTheHoleAxis) {
  FlexibleJointRobot robot(PlanarRodArm(true), SeedDrives(5.0));
  const DrillingProcess p = SeedProcess(0.5);
  DrillingScenario sc(&robot, DrillGeometry{}, Q235Like(), p);
  const Eigen::Isometry3d X0 = robot.TipPose(p.initial_posture);
  const Eigen::Isometry3d X1 = robot.TipPose(sc.desired().col(sc.num_samples() - 1));
  // 0.10 mm/rev at 1500 rpm = 2.5 mm/s: 1.25 mm in 0.5 s along tip z.
  const Eigen::Vector3d expected = X0.translation() + 1.25e-3 * X0.linear().col(2);
  EXPECT_LT((X1.translation() - expected).norm(), 1e-10);
  EXPECT_LT((X1.linear() - X0.linear()).norm(), 1e-10);
  EXPECT_NEAR(p.feed_speed(), 2.5e-3, 1e-15);
  // Full engagement: d_full / v (drill_forces_test checks d_full).
  EXPECT_GT(sc.full_engagement_time(), 0.4);
  EXPECT_LT(sc.full_engagement_time(), 0.6);
}

TEST(DrillingScenario, RejectsAHoleAxisTheRobotCannotFeedAlong) {
  FlexibleJointRobot robot(PlanarRodArm(true), SeedDrives(5.0));
  DrillingProcess p = SeedProcess(0.1);
  p.hole_axis = HoleAxis::kTipX;   // tip x is along the joint axes: out of the plane
  try {
    DrillingScenario sc(&robot, DrillGeometry{}, Q235Like(), p);
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cannot feed along the hole axis"), std::string::npos) << e.what();
  }
}

TEST(DrillingScenario, ThrustLoadsTheJointsThroughTheJacobianTranspose) {
  // With the motors' PD very stiff the links still deflect by K^-1 J^T F in
  // the joint springs; here we check the sign: the thrust pushes the drill
  // back along -z_tip, so the link angles move to lower the tip.
  FlexibleJointRobot robot(PlanarRodArm(true), SeedDrives(5.0));
  const DrillingProcess p = SeedProcess(0.6);
  DrillingScenario sc(&robot, DrillGeometry{}, Q235Like(), p);
  auto ctl = MakeController(DefaultParameters("pd-tdc"), sc, Eigen::VectorXd::Constant(3, 10.0));
  SimOptions o;
  o.motor_torque_limit = Eigen::VectorXd::Constant(3, 10.0);
  const SimResult r = sc.Run(*ctl, o);
  ASSERT_FALSE(r.diverged);
  EXPECT_EQ(r.series.t.size(), 601u);
  // The thrust rises during entry and is constant-ish after.
  EXPECT_LT(r.series.thrust[10], r.series.thrust[400]);
  EXPECT_GT(r.series.thrust.back(), 500.0);
  // Tip displacement along the hole axis lags the desired one (pushed back).
  const int k = 500;
  const Eigen::Vector3d a = robot.TipPose(p.initial_posture).linear().col(2);
  const double actual = a.dot(robot.TipPose(r.series.q.col(k)).translation());
  const double desired = a.dot(robot.TipPose(sc.desired().col(k)).translation());
  EXPECT_LT(actual, desired);
}

// Issue #36: every HoleAxis goes through its name (a drill file's
// process.hole_axis) and back; another name is refused naming all three.
TEST(HoleAxis, RoundTripsThroughItsName) {
  for (HoleAxis a : {HoleAxis::kTipX, HoleAxis::kTipY, HoleAxis::kTipZ}) {
    EXPECT_EQ(ParseHoleAxis(ToString(a)), a) << ToString(a);
  }
  try {
    ParseHoleAxis("z");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "hole axis 'z': expected tip_x, tip_y or tip_z");
  }
}

}  // namespace
}  // namespace robomach::drilling
