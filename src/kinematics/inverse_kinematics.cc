#include "robomach/kinematics/inverse_kinematics.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "kinematics/internal/kdl_status.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"

namespace robomach::kinematics {

Vector6d PoseError(const Eigen::Isometry3d& T, const Eigen::Isometry3d& X) {
  Vector6d e;
  e.head<3>() = T.translation() - X.translation();
  const Eigen::Matrix3d R = T.linear() * X.linear().transpose();
  // log(R): sin θ · axis from the skew part, cos θ from the trace.
  const Eigen::Vector3d s(0.5 * (R(2, 1) - R(1, 2)), 0.5 * (R(0, 2) - R(2, 0)), 0.5 * (R(1, 0) - R(0, 1)));
  const double sin_t = s.norm(), cos_t = 0.5 * (R.trace() - 1.0);
  const double theta = std::atan2(sin_t, cos_t);
  if (sin_t > 1e-6) {
    e.tail<3>() = (theta / sin_t) * s;
  } else if (cos_t > 0.0) {
    e.tail<3>() = s;  // θ ≈ sin θ to 1e-12 relative
  } else {
    // θ near π: the axis from the symmetric part of R,
    // (R + Rᵀ)/2 = cos θ I + (1 − cos θ) a aᵀ, so B = ((R + Rᵀ)/2 + I)/2 =
    // a aᵀ + (1 + cos θ)/2 (I − a aᵀ) ≈ a aᵀ; the sign from the skew part.
    const Eigen::Matrix3d B = 0.25 * (R + R.transpose()) + 0.5 * Eigen::Matrix3d::Identity();
    Eigen::Index k = 0;
    B.diagonal().maxCoeff(&k);
    Eigen::Vector3d a = B.col(k) / std::sqrt(std::max(B(k, k), 1e-300));
    if (a.dot(s) < 0.0) a = -a;
    e.tail<3>() = theta * a.normalized();
  }
  return e;
}

struct IkSolver::Kdl {
  explicit Kdl(const KDL::Chain& shared) : chain(shared), fk(chain), jac(chain) {}
  KDL::Chain chain;  // private copy (KDL joints cache their last pose)
  KDL::ChainFkSolverPos_recursive fk;
  KDL::ChainJntToJacSolver jac;
};

void IkOptions::Validate() const {
  CheckOptionAbove("position_tolerance_m", position_tolerance_m, 0.0);
  CheckOptionAbove("rotation_tolerance_rad", rotation_tolerance_rad, 0.0);
  CheckOptionAbove("converged_position_m", converged_position_m, 0.0);
  CheckOptionAbove("converged_rotation_rad", converged_rotation_rad, 0.0);
  CheckOptionAtLeast("max_iterations", max_iterations, 1);
}

IkSolver::IkSolver(const SerialChain& chain, IkOptions options)
    : n_(chain.num_joints()), options_(options), kdl_(std::make_unique<Kdl>(chain.kdl())) {
  options_.Validate();
}

IkSolver::~IkSolver() = default;

bool IkSolver::Solve(const Eigen::Isometry3d& X, const Eigen::VectorXd& seed, Eigen::VectorXd* q_out) {
  if (seed.size() != n_) {
    throw std::invalid_argument("inverse kinematics: the seed has " + std::to_string(seed.size()) +
                                " joints, the robot " + std::to_string(n_));
  }
  KDL::JntArray qk(n_);
  KDL::Frame F;
  KDL::Jacobian Jk(n_);
  // Pose error and Jacobian at q; false if KDL fails or the pose is not finite.
  const auto evaluate = [&](const Eigen::VectorXd& q, Vector6d* e, Matrix6Xd* J) {
    for (int j = 0; j < n_; ++j) qk(j) = q(j);
    internal::ThrowIfKdlFailed(kdl_->fk.JntToCart(qk, F), kdl_->fk, "inverse kinematics (pose)");
    internal::ThrowIfKdlFailed(kdl_->jac.JntToJac(qk, Jk), kdl_->jac, "inverse kinematics (Jacobian)");
    *e = PoseError(X, ToEigen(F));
    *J = Jk.data;
    return e->allFinite() && J->allFinite();
  };
  Eigen::VectorXd q = seed, q_try(n_);
  Vector6d e, e_try;
  Matrix6Xd J(6, n_), J_try(6, n_);
  bool ok = evaluate(q, &e, &J);
  double cost = e.squaredNorm();
  double mu = 0.0;  // Levenberg-Marquardt damping; 0 = Newton step
  last_iterations_ = 0;
  for (int it = 0; ok && it < options_.max_iterations; ++it) {
    if (e.head<3>().norm() < options_.converged_position_m && e.tail<3>().norm() < options_.converged_rotation_rad) {
      break;
    }
    ++last_iterations_;
    Eigen::VectorXd dq;
    if (mu == 0.0 && n_ == 6) {
      const Eigen::PartialPivLU<Matrix6d> lu{Matrix6d(J)};
      dq = lu.solve(e);
    } else {
      Eigen::MatrixXd H = J.transpose() * J;
      H.diagonal().array() += mu;
      dq = H.ldlt().solve(J.transpose() * e);
    }
    if (!dq.allFinite()) {
      mu = mu == 0.0 ? 1e-9 * std::max(1.0, (J.transpose() * J).trace()) : 10.0 * mu;
      continue;
    }
    q_try = q + dq;
    if (evaluate(q_try, &e_try, &J_try) && e_try.squaredNorm() < cost) {
      q.swap(q_try);
      e = e_try;
      J.swap(J_try);
      cost = e.squaredNorm();
      mu = mu < 1e-12 ? 0.0 : 0.1 * mu;
    } else {
      if (dq.norm() < 1e-15 * (1.0 + q.norm())) break;  // no step left that helps
      mu = mu == 0.0 ? 1e-9 * std::max(1.0, (J.transpose() * J).trace()) : 10.0 * mu;
    }
  }
  for (int j = 0; j < n_; ++j) q(j) -= 2.0 * kPi * std::round((q(j) - seed(j)) / (2.0 * kPi));
  *q_out = q;
  return ok && q.allFinite() && e.head<3>().norm() < options_.position_tolerance_m &&
         e.tail<3>().norm() < options_.rotation_tolerance_rad;
}

}  // namespace robomach::kinematics
