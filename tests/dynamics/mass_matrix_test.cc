// Joint-space inertia and Jacobian of the KR210 against independent
// computations: the kinetic energy of every link from finite-differenced link
// poses, and finite differences of the forward kinematics.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/kinematics/serial_chain.h"
#include "test_models.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::Kr210;
using robomach::testing::RandomPosture;

// Angular velocity from two rotations h apart: log(R(q+h) R(q-h)ᵀ) / 2h.
Eigen::Vector3d AngularVelocity(const Eigen::Matrix3d& Rp, const Eigen::Matrix3d& Rm, double h) {
  const Eigen::AngleAxisd aa(Rp * Rm.transpose());
  return aa.axis() * aa.angle() / (2.0 * h);
}

// Kinetic energy T = ½ q̇ᵀ M_q q̇ = Σ_links ½ m |v_c|² + ½ ωᵀ I_c ω, with every
// link's COM velocity and angular velocity from central differences of its
// pose along q(t) = q0 + t q̇. Polarisation over q̇ = e_i + e_j gives every
// entry of M_q without KDL's composite-rigid-body recursion.
//
// Step and tolerance: the pose error of a central difference is
// ≈ h²/6 |∂³p/∂t³| with |q̇| ≤ 2 rad/s and a reach of ≈ 3 m, so ≈ 4 h² m/s;
// round-off ≈ eps · 3 m / h. At h = 1e-5 both are ≈ 4e-10 m/s relative to
// velocities of order 1 m/s, so T is accurate to ≈ 1e-9 relative. M_q entries
// come from differences of energies of order ½ · 2500 kg·m² (joint 1); the
// tolerance 1e-6 · max|M_q| keeps a margin of about 100 over that.
TEST(MassMatrix, MatchesKineticEnergyOfFiniteDifferencedLinkMotion) {
  const auto model = Kr210();
  const kinematics::SerialChain& chain = model->chain();
  std::mt19937 rng(7);
  const double h = 1e-5;
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q0 = RandomPosture(*model, rng);
    const Eigen::MatrixXd M = EvaluatePosture(model, q0).M_q();
    const int n = model->num_joints();
    auto energy = [&](const Eigen::VectorXd& qdot) {
      double T = 0.0;
      for (int s = 0; s < chain.num_segments(); ++s) {
        const kinematics::Inertial b = chain.segment_inertial(s);
        if (b.mass == 0.0) continue;
        const Eigen::Isometry3d Xp = kinematics::SegmentPose(chain, q0 + h * qdot, s);
        const Eigen::Isometry3d Xm = kinematics::SegmentPose(chain, q0 - h * qdot, s);
        const Eigen::Vector3d v = (Xp * b.com - Xm * b.com) / (2.0 * h);
        const Eigen::Vector3d w = AngularVelocity(Xp.linear(), Xm.linear(), h);
        const Eigen::Matrix3d R = kinematics::SegmentPose(chain, q0, s).linear();
        const Eigen::Matrix3d I_world = R * b.inertia_com * R.transpose();
        T += 0.5 * b.mass * v.squaredNorm() + 0.5 * w.dot(I_world * w);
      }
      return T;
    };
    Eigen::MatrixXd M_energy(n, n);
    for (int i = 0; i < n; ++i) {
      M_energy(i, i) = 2.0 * energy(Eigen::VectorXd::Unit(n, i));
    }
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        const double Tij = energy(Eigen::VectorXd::Unit(n, i) + Eigen::VectorXd::Unit(n, j));
        M_energy(i, j) = M_energy(j, i) = Tij - 0.5 * (M_energy(i, i) + M_energy(j, j));
      }
    }
    const double tol = 1e-6 * M.cwiseAbs().maxCoeff();
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        EXPECT_NEAR(M(i, j), M_energy(i, j), tol) << "trial " << trial << " M(" << i << "," << j << ")";
      }
    }
    // M_q is symmetric positive definite (an invariant of any inertia matrix).
    EXPECT_LE((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-12 * M.cwiseAbs().maxCoeff());
    EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(M).info(), Eigen::Success);
  }
}

// Central differences of the TCP position and orientation against KDL's
// geometric Jacobian. Truncation ≈ h²/6 · R with R ≈ 3 m, round-off ≈
// 100 eps R / h; at h = 4e-5 rad both are ≈ 1e-9 m/rad. Tolerance 1e-7 keeps
// a 100× margin (style.md §2.12).
TEST(Jacobian, MatchesFiniteDifferencesOfForwardKinematics) {
  const auto model = Kr210();
  std::mt19937 rng(11);
  constexpr double kStep = 4e-5;
  constexpr double kTol = 1e-7;
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const Matrix6Xd J = kinematics::Jacobian(model->chain(), q);
    for (int j = 0; j < model->num_joints(); ++j) {
      Eigen::VectorXd qp = q, qm = q;
      qp(j) += kStep;
      qm(j) -= kStep;
      const Eigen::Isometry3d Xp = kinematics::ForwardKinematics(model->chain(), qp);
      const Eigen::Isometry3d Xm = kinematics::ForwardKinematics(model->chain(), qm);
      const Eigen::Vector3d v = (Xp.translation() - Xm.translation()) / (2 * kStep);
      const Eigen::Vector3d w = AngularVelocity(Xp.linear(), Xm.linear(), kStep);
      for (int r = 0; r < 3; ++r) {
        EXPECT_NEAR(J(r, j), v(r), kTol) << "trial " << trial << " joint " << j << " row " << r;
        EXPECT_NEAR(J(3 + r, j), w(r), kTol) << "trial " << trial << " joint " << j << " row " << 3 + r;
      }
    }
  }
}

// The URDF and the modified-DH description of the KR210 are two independent
// paths to KDL (urdfdom + our converter vs. DH_Craig1989 frames); they must
// agree on J and M_q at any posture to rounding (1e-9 relative leaves room
// for the rounding of the DH file's 17-digit inertia values).
TEST(RobotInput, UrdfAndModifiedDhGiveTheSameJacobianAndMassMatrix) {
  const auto urdf = Kr210("config/kr210.yaml");
  const auto dh = Kr210("config/kr210_dh.yaml");
  std::mt19937 rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*urdf, rng);
    const PostureDynamics a = EvaluatePosture(urdf, q);
    const PostureDynamics b = EvaluatePosture(dh, q);
    EXPECT_LE((a.J_BT - b.J_BT).cwiseAbs().maxCoeff(), 1e-9 * a.J_BT.cwiseAbs().maxCoeff());
    EXPECT_LE((a.M_q() - b.M_q()).cwiseAbs().maxCoeff(), 1e-9 * a.M_q().cwiseAbs().maxCoeff());
    EXPECT_LE((a.X_BT.translation() - b.X_BT.translation()).norm(), 1e-9);
  }
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(urdf->chain().limits()[j].lower, dh->chain().limits()[j].lower, 1e-12);
    EXPECT_NEAR(urdf->chain().limits()[j].upper, dh->chain().limits()[j].upper, 1e-12);
  }
}

// Second formula for the Cartesian inertia: where J is square and regular,
// J⁻ᵀ M_q J⁻¹ equals Khatib's operational-space inertia (J M_q⁻¹ Jᵀ)⁻¹, and
// K_X = J⁻ᵀ K_q J⁻¹ inverts to J K_q⁻¹ Jᵀ. At cond(J) ≈ 1e2..1e3 and
// cond(M_q) ≈ 1e4 the two routes differ by ≈ cond² eps ≈ 1e-9 relative.
TEST(Cartesian, CongruenceEqualsOperationalSpaceFormula) {
  const auto model = Kr210();
  std::mt19937 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
    ASSERT_FALSE(d.near_singular);
    const Eigen::MatrixXd Mq = d.M_q();
    const Matrix6d khatib = (d.J_BT * Mq.inverse() * d.J_BT.transpose()).inverse();
    EXPECT_LE((d.M_X - khatib).norm(), 1e-7 * khatib.norm()) << trial;
    const Matrix6d compliance = d.J_BT * d.K_q().inverse() * d.J_BT.transpose();
    EXPECT_LE((d.K_X.inverse() - compliance).norm(), 1e-7 * compliance.norm()) << trial;
  }
}

// Eigenvalues of the Cartesian pair (K_X, M_X) equal those of (K_q, M_q): the
// congruence with an invertible J preserves the generalized spectrum.
TEST(Cartesian, EigenfrequenciesEqualJointSpaceAtRegularPostures) {
  const auto model = Kr210();
  std::mt19937 rng(9);
  for (int trial = 0; trial < 5; ++trial) {
    const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(Eigen::MatrixXd(d.K_X),
                                                                  Eigen::MatrixXd(d.M_X));
    for (int k = 0; k < 6; ++k) {
      const double f = std::sqrt(ges.eigenvalues()(k)) / (2 * kPi);
      EXPECT_NEAR(f, d.modes[k].freq_hz, 1e-7 * d.modes[k].freq_hz) << trial << " mode " << k;
    }
  }
}

}  // namespace
}  // namespace robomach::dynamics
