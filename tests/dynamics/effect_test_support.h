#pragma once

// Helpers for the effect-library tests: the KR210 with effects switched on,
// matrix invariants, and an independent mass matrix from the kinetic energy
// of rigid bodies whose poses are finite-differenced.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/kinematics/serial_chain.h"
#include "test_models.h"

namespace robomach::testing {

/// The default KR210 with the given effects (name, parameter values).
inline std::shared_ptr<const dynamics::RobotModel> Kr210With(
    const std::vector<std::pair<std::string, std::map<std::string, double>>>& effects) {
  io::RobotConfig cfg = Kr210Config();
  for (const auto& [name, values] : effects) cfg.description.effects.push_back({name, values});
  return dynamics::RobotModel::Build(cfg.description, dynamics::DefaultParameters(cfg.description));
}

/// M symmetric positive definite and K symmetric (to rounding: the assembly
/// forms both halves by the same products, so 1e-12 of the largest entry).
inline void ExpectValidSystem(const dynamics::AssembledSystem& s) {
  const double m = s.M.cwiseAbs().maxCoeff(), k = s.K.cwiseAbs().maxCoeff();
  EXPECT_LE((s.M - s.M.transpose()).cwiseAbs().maxCoeff(), 1e-12 * m);
  EXPECT_LE((s.K - s.K.transpose()).cwiseAbs().maxCoeff(), 1e-12 * k);
  EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(s.M).info(), Eigen::Success) << "M not positive definite";
}

/// A rigid body whose pose in B is a function of the generalised
/// coordinates z; `inertial` is in the body's own frame.
struct PosedBody {
  kinematics::Inertial inertial;
  std::function<Eigen::Isometry3d(const Eigen::VectorXd& z)> pose;
};

/// Twist [v_com; ω] of a body for the velocity zd at z, by central
/// differences of its pose with step h along zd.
inline Vector6d FdTwist(const PosedBody& b, const Eigen::VectorXd& z, const Eigen::VectorXd& zd,
                        double h) {
  const Eigen::Isometry3d Xp = b.pose(z + h * zd), Xm = b.pose(z - h * zd);
  Vector6d t;
  t.head<3>() = (Xp * b.inertial.com - Xm * b.inertial.com) / (2.0 * h);
  const Eigen::AngleAxisd aa(Eigen::Matrix3d(Xp.linear() * Xm.linear().transpose()));
  t.tail<3>() = aa.angle() * aa.axis() / (2.0 * h);
  return t;
}

/// The mass matrix whose quadratic form is twice the bodies' kinetic energy,
/// Σ m |v_c|² + ωᵀ I ω [Featherstone 2008, §2.13], from finite-differenced
/// twists: M_ij = ½ (T(e_i + e_j) − T(e_i) − T(e_j)) with T = 2·energy
/// (polarisation; T is quadratic in the velocity).
inline Eigen::MatrixXd MassFromKineticEnergy(const std::vector<PosedBody>& bodies,
                                             const Eigen::VectorXd& z, double h) {
  const int N = static_cast<int>(z.size());
  auto T = [&](const Eigen::VectorXd& zd) {
    double e = 0.0;
    for (const PosedBody& b : bodies) {
      const Vector6d t = FdTwist(b, z, zd, h);
      const Eigen::Isometry3d X = b.pose(z);
      const Eigen::Matrix3d I = X.linear() * b.inertial.inertia_com * X.linear().transpose();
      e += b.inertial.mass * t.head<3>().squaredNorm() + t.tail<3>().dot(I * t.tail<3>());
    }
    return e;
  };
  Eigen::MatrixXd M(N, N);
  Eigen::VectorXd d(N);
  for (int i = 0; i < N; ++i) d(i) = T(Eigen::VectorXd::Unit(N, i));
  for (int i = 0; i < N; ++i) {
    M(i, i) = d(i);
    for (int j = i + 1; j < N; ++j) {
      M(i, j) = M(j, i) =
          0.5 * (T(Eigen::VectorXd::Unit(N, i) + Eigen::VectorXd::Unit(N, j)) - d(i) - d(j));
    }
  }
  return M;
}

/// Pose of a rigid displacement (u, θ) about point P, all in frame S:
/// x ↦ P + u + R(θ)(x − P), R(θ) the rotation vector θ's exponential.
inline Eigen::Isometry3d SpringDisplacement(const Eigen::Vector3d& P, const Eigen::Vector3d& u,
                                            const Eigen::Vector3d& theta) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  const double a = theta.norm();
  if (a > 0.0) X.linear() = Eigen::AngleAxisd(a, theta / a).toRotationMatrix();
  X.translation() = P + u - X.linear() * P;
  return X;
}

/// The links of a model's chain (every segment before "end_effector") as
/// posed bodies driven by the first n entries of z, optionally carried by
/// a base motion X_base(z).
inline std::vector<PosedBody> LinkBodies(
    const dynamics::RobotModel& model,
    std::function<Eigen::Isometry3d(const Eigen::VectorXd&)> base = nullptr) {
  std::vector<PosedBody> out;
  const auto& chain = model.chain();
  const int n = model.num_joints();
  for (int s = 0; s < chain.num_segments(); ++s) {
    if (chain.kdl().getSegment(s).getName() == "end_effector") break;
    PosedBody b;
    b.inertial = chain.segment_inertial(s);
    if (b.inertial.mass == 0.0) continue;
    b.pose = [&chain, s, n, base](const Eigen::VectorXd& z) {
      const Eigen::Isometry3d X = kinematics::SegmentPose(chain, z.head(n), s);
      return base ? Eigen::Isometry3d(base(z) * X) : X;
    };
    out.push_back(b);
  }
  return out;
}

/// Pose of the tip frame (tool0) in B at z, from the chain up to "end_effector".
inline Eigen::Isometry3d TipPose(const dynamics::RobotModel& model, const Eigen::VectorXd& z) {
  const auto& chain = model.chain();
  for (int s = 0; s < chain.num_segments(); ++s) {
    if (chain.kdl().getSegment(s).getName() == "end_effector") {
      return kinematics::SegmentPose(chain, z.head(model.num_joints()), s);
    }
  }
  ADD_FAILURE() << "no end_effector segment";
  return Eigen::Isometry3d::Identity();
}

/// Entry-wise comparison scaled per entry by √(M_ii M_jj), the Cauchy–Schwarz
/// bound of |M_ij| for a positive semi-definite M: a fair relative measure
/// when DOFs of very different inertia are mixed.
inline double MaxScaledDifference(const Eigen::MatrixXd& A, const Eigen::MatrixXd& R) {
  double worst = 0.0;
  for (int i = 0; i < R.rows(); ++i) {
    for (int j = 0; j < R.cols(); ++j) {
      worst = std::max(worst, std::abs(A(i, j) - R(i, j)) / std::sqrt(R(i, i) * R(j, j)));
    }
  }
  return worst;
}

}  // namespace robomach::testing
