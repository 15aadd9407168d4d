#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include <kdl/chainiksolverpos_lma.hpp>

#include "robomach/common/units.h"
#include "robomach/kinematics/inverse_kinematics.h"
#include "robomach/kinematics/modified_dh.h"
#include "kr210_chain.h"

namespace robomach::kinematics {
namespace {

using testing::Kr210;

Eigen::VectorXd MillingPosture() {
  Eigen::VectorXd q(6);
  q << 0.0, -1.5707963, 1.5707963, 0.0, 0.7853982, 0.0;
  return q;
}

// The rotation log against Eigen's AngleAxis (acos-based, accurate away from
// 0 and π), over angles from 1e-3 to just below π and random axes; and at
// angles where acos loses digits, against the angle the rotation was made
// with.
TEST(PoseError, RotationLogMatchesAngleAxis) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  for (const double angle : {1e-9, 1e-6, 1e-3, 0.3, 1.0, 2.0, 3.0, 3.14, kPi - 1e-7}) {
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d axis = Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized();
      Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
      X.linear() = Eigen::AngleAxisd(n01(rng), Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized())
                       .toRotationMatrix();
      X.translation() = Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      Eigen::Isometry3d T = X;
      T.linear() = Eigen::AngleAxisd(angle, axis).toRotationMatrix() * X.linear();
      T.translation() += Eigen::Vector3d(0.1, -0.2, 0.3);
      const Vector6d e = PoseError(T, X);
      EXPECT_NEAR((e.head<3>() - Eigen::Vector3d(0.1, -0.2, 0.3)).norm(), 0.0, 1e-15 * 4);
      // Rounding of the rotation products: a few 1e-16 absolute in the
      // axis-angle vector; within 1e-6 of π (PoseError's branch there) the
      // axis comes from R + Rᵀ + 2I, whose entries carry ~1e-16/(π − θ)
      // (1e-9 at π − 1e-7) of relative error in its direction.
      const double tol = kPi - angle < 1e-6 ? 1e-8 : 1e-12;
      EXPECT_NEAR((e.tail<3>() - angle * axis).norm(), 0.0, tol) << angle;
    }
  }
}

// Solutions from a seed 0.2 rad away reach the pose to 1e-12 m and give back
// the posture the pose was made from (the same branch), as KDL's
// Levenberg-Marquardt solver does from the same seed.
TEST(IkSolver, ReachesPosesAndAgreesWithKdlLma) {
  const SerialChain chain = Kr210();
  IkSolver ik(chain);
  const KDL::Chain kdl_copy = chain.kdl();
  KDL::ChainIkSolverPos_LMA lma(kdl_copy, 1e-12, 1000, 1e-15);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int compared = 0;
  double max_lma_error = 0.0;
  for (int k = 0; k < 200; ++k) {
    Eigen::VectorXd q_true = MillingPosture();
    for (int j = 0; j < 6; ++j) q_true(j) += 0.6 * u(rng);
    Eigen::VectorXd seed = q_true;
    for (int j = 0; j < 6; ++j) seed(j) += 0.2 * u(rng);
    const Eigen::Isometry3d X = ForwardKinematics(chain, q_true);
    Eigen::VectorXd q;
    ASSERT_TRUE(ik.Solve(X, seed, &q)) << k;
    EXPECT_LE(ik.last_iterations(), 12) << k;
    const Vector6d e = PoseError(X, ForwardKinematics(chain, q));
    EXPECT_LT(e.head<3>().norm(), 1e-11) << k;
    EXPECT_LT(e.tail<3>().norm(), 1e-11) << k;
    // Away from the wrist singularity (|q5| > 0.1) the solution is the
    // posture itself: the joints follow the pose with gain at most ~1/|sin q5|.
    if (std::abs(q_true(4)) > 0.1) {
      EXPECT_LT((q - q_true).cwiseAbs().maxCoeff(), 1e-9) << k;
      KDL::JntArray s(6), out(6);
      for (int j = 0; j < 6; ++j) s(j) = seed(j);
      if (lma.CartToJnt(s, ToKdl(X), out) >= 0) {
        Eigen::VectorXd q_lma(6);
        for (int j = 0; j < 6; ++j) q_lma(j) = out(j) - 2.0 * kPi * std::round((out(j) - seed(j)) / (2.0 * kPi));
        // The same branch: KDL's LMA stops at its weighted error (rotation
        // weighted 0.01), a few 1e-9..1e-7 of pose error, which the wrist
        // amplifies by up to ~1/|sin q5| in the joints; branches lie radians
        // apart. The Newton solution is the more accurate of the two.
        const Vector6d e_lma = PoseError(X, ForwardKinematics(chain, q_lma));
        EXPECT_LT((q - q_lma).cwiseAbs().maxCoeff(), 1e-5) << k;
        EXPECT_LE(e.norm(), e_lma.norm() + 1e-15) << k;
        max_lma_error = std::max(max_lma_error, e_lma.norm());
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 150);
  std::cout << compared << " solutions compared with KDL's LMA; its largest pose error " << max_lma_error << "\n";
}

// At the wrist singularity (q5 = 0) the Jacobian is rank 5: the damped steps
// still reach a pose there (any split of q4 + q6 is a solution).
TEST(IkSolver, ReachesAPoseAtTheWristSingularity) {
  const SerialChain chain = Kr210();
  IkSolver ik(chain);
  Eigen::VectorXd q_true = MillingPosture();
  q_true(4) = 0.0;
  Eigen::VectorXd seed = q_true;
  seed(3) += 0.1;
  seed(4) += 0.05;
  seed(5) -= 0.1;
  const Eigen::Isometry3d X = ForwardKinematics(chain, q_true);
  Eigen::VectorXd q;
  ASSERT_TRUE(ik.Solve(X, seed, &q));
  const Vector6d e = PoseError(X, ForwardKinematics(chain, q));
  EXPECT_LT(e.head<3>().norm(), 1e-5);
  EXPECT_LT(e.tail<3>().norm(), 1e-4);
}

// A target 10 m away is out of reach: false, with finite joints, no hang.
TEST(IkSolver, UnreachablePoseIsReportedAndBadSeedsRejected) {
  const SerialChain chain = Kr210();
  IkSolver ik(chain);
  Eigen::Isometry3d X = ForwardKinematics(chain, MillingPosture());
  X.translation() += Eigen::Vector3d(10.0, 0.0, 0.0);
  Eigen::VectorXd q;
  EXPECT_FALSE(ik.Solve(X, MillingPosture(), &q));
  EXPECT_TRUE(q.allFinite());
  EXPECT_THROW(ik.Solve(X, Eigen::VectorXd::Zero(5), &q), std::invalid_argument);
  IkOptions bad;
  bad.max_iterations = 0;
  EXPECT_THROW(IkSolver(chain, bad), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::kinematics
