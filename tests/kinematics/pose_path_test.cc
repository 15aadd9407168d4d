// CheckPosePath against forward kinematics: poses made by FK from a smooth
// joint path are all reached, to the tolerance, with the margins and
// condition numbers of the joint path; an unreachable pose, a pose outside
// the joint limits and a jump between IK branches are each counted and
// located.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/SVD>

#include "robomach/common/units.h"
#include "robomach/kinematics/pose_path.h"
#include "kr210_chain.h"

namespace robomach::kinematics {
namespace {

// The KR 210 R2700 arm of config/kr210_dh.yaml (kr210_chain.h).
SerialChain Arm() { return testing::Kr210(); }

// A smooth joint path well inside the limits and away from the wrist
// singularity (q5 = 0).
std::vector<Eigen::VectorXd> JointPath(int N) {
  std::vector<Eigen::VectorXd> q;
  for (int i = 0; i < N; ++i) {
    const double s = static_cast<double>(i) / (N - 1);
    Eigen::VectorXd v(6);
    v << 0.3 * std::sin(2.0 * s), -1.4 + 0.2 * s, 1.3 - 0.1 * s, 0.4 * s, 0.8 + 0.2 * std::cos(3.0 * s), -0.5 + s;
    q.push_back(v);
  }
  return q;
}

TEST(CheckPosePath, ReachesPosesMadeByForwardKinematics) {
  const SerialChain arm = Arm();
  const std::vector<Eigen::VectorXd> path = JointPath(40);
  std::vector<Eigen::Isometry3d> X;
  for (const auto& q : path) X.push_back(ForwardKinematics(arm, q));
  // Seeded 0.2 rad away from the first posture: the IK has to work.
  const Eigen::VectorXd seed = path[0] + Eigen::VectorXd::Constant(6, 0.2);
  const PosePathCheck c = CheckPosePath(arm, X, seed);
  EXPECT_TRUE(c.ok());
  EXPECT_EQ(c.first_bad_row, -1);
  ASSERT_EQ(c.q.size(), path.size());
  for (size_t r = 0; r < path.size(); ++r) {
    ASSERT_TRUE(c.reachable[r]) << r;
    const Eigen::Isometry3d got = ForwardKinematics(arm, c.q[r]);
    EXPECT_LT((got.translation() - X[r].translation()).norm(), 1e-9) << r;
    // A 6R arm has up to 8 IK branches; seeded nearby, the path's own.
    EXPECT_LT((c.q[r] - path[r]).cwiseAbs().maxCoeff(), 1e-6) << r;
    double margin = 1e300;
    for (int j = 0; j < 6; ++j) margin = std::min({margin, path[r](j) - arm.limits()[j].lower, arm.limits()[j].upper - path[r](j)});
    EXPECT_NEAR(c.limit_margin[r], margin, 1e-6) << r;
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Jacobian(arm, path[r]));
    const Eigen::VectorXd& sv = svd.singularValues();
    EXPECT_NEAR(c.condition[r], sv(0) / sv(5), 1e-6 * sv(0) / sv(5)) << r;
  }
}

TEST(CheckPosePath, CountsAndLocatesUnreachablePosesAndJumps) {
  const SerialChain arm = Arm();
  const std::vector<Eigen::VectorXd> path = JointPath(10);
  std::vector<Eigen::Isometry3d> X;
  for (const auto& q : path) X.push_back(ForwardKinematics(arm, q));
  // Row 3: 10 m away, beyond the arm's reach.
  X[3].translation() += Eigen::Vector3d(10.0, 0.0, 0.0);
  // Rows 7-9: joint 1 turned by 1 rad from row 6, a step the robot cannot
  // make between two rows; the path stays there (no second jump).
  Eigen::VectorXd far = path[6];
  far(0) += 1.0;
  for (int r = 7; r < 10; ++r) X[r] = ForwardKinematics(arm, far);
  const PosePathCheck c = CheckPosePath(arm, X, path[0]);
  EXPECT_FALSE(c.ok());
  EXPECT_EQ(c.num_unreachable, 1);
  EXPECT_FALSE(c.reachable[3]);
  EXPECT_EQ(c.q[3].size(), 0);
  EXPECT_TRUE(std::isnan(c.limit_margin[3]));
  EXPECT_TRUE(std::isnan(c.condition[3]));
  EXPECT_EQ(c.first_bad_row, 3);
  // Row 4 follows an unreachable row: it is not compared with row 2.
  EXPECT_EQ(c.num_jumps, 1);
  EXPECT_EQ(c.num_outside_limits, 0);
  for (int r = 7; r < 10; ++r) EXPECT_NEAR(c.q[r](0), far(0), 1e-6) << r;
}

TEST(CheckPosePath, CountsPosesOutsideTheJointLimits) {
  const SerialChain arm = Arm();
  // Joint 2 from -0.2 to 0 rad in steps of 0.02 rad: above its upper limit
  // of -5 deg (-0.0873 rad) from row 5 on. No 2π branch of it is inside.
  const double upper = -5.0 * kPi / 180.0;
  std::vector<Eigen::Isometry3d> X;
  Eigen::VectorXd q(6);
  q << 0.1, -0.2, 1.0, 0.3, 0.9, -0.2;
  for (int i = 0; i <= 10; ++i) {
    q(1) = -0.2 + 0.02 * i;
    X.push_back(ForwardKinematics(arm, q));
  }
  q(1) = -0.2;
  const PosePathCheck c = CheckPosePath(arm, X, q);
  int expected = 0;
  for (int i = 0; i <= 10; ++i) expected += -0.2 + 0.02 * i > upper;
  EXPECT_EQ(expected, 5);
  EXPECT_EQ(c.num_outside_limits, expected);
  EXPECT_EQ(c.first_bad_row, 10 - expected + 1);
  EXPECT_EQ(c.num_unreachable, 0);
  EXPECT_EQ(c.num_jumps, 0);
  EXPECT_NEAR(c.min_limit_margin, upper - 0.0, 1e-6);
  EXPECT_NEAR(c.limit_margin[10], upper, 1e-6);
}

TEST(CheckPosePath, RefusesASeedOfTheWrongSize) {
  const SerialChain arm = Arm();
  EXPECT_THROW(CheckPosePath(arm, {Eigen::Isometry3d::Identity()}, Eigen::VectorXd::Zero(5)), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::kinematics
