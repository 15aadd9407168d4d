#include "robomach/kinematics/serial_chain.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "kinematics/internal/kdl_status.h"

namespace robomach::kinematics {

std::optional<std::string> CheckInertial(const Inertial& b) {
  if (!std::isfinite(b.mass) || b.mass < 0.0) {
    return "mass must be finite and >= 0, got " + std::to_string(b.mass) + " kg";
  }
  if (!b.com.allFinite() || !b.inertia_com.allFinite()) return "non-finite COM or inertia";
  const Eigen::Matrix3d& I = b.inertia_com;
  // Symmetry to rounding of the inputs: 1e-12 of the largest entry.
  const double scale = std::max(I.cwiseAbs().maxCoeff(), 1e-300);
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) return "inertia is not symmetric";
  if (b.mass == 0.0 && I.isZero(0.0)) return std::nullopt;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(I);
  const Eigen::Vector3d p = es.eigenvalues();  // ascending
  if (!(p(0) > 0.0)) {
    return "inertia is not positive definite (smallest principal moment " +
           std::to_string(p(0)) + " kg·m²)";
  }
  // Triangle inequality of principal moments, with a relative slack of 1e-9
  // for thin rods and discs stored with rounded digits.
  if (p(0) + p(1) < p(2) * (1.0 - 1e-9)) {
    return "principal moments " + std::to_string(p(0)) + ", " + std::to_string(p(1)) + ", " +
           std::to_string(p(2)) + " kg·m² violate the triangle inequality I1 + I2 >= I3";
  }
  if (b.mass == 0.0) return "a body with zero mass must have zero inertia";
  return std::nullopt;
}

Inertial TransformInertial(const Inertial& in_B, const Eigen::Isometry3d& X_AB) {
  Inertial out;
  out.mass = in_B.mass;
  out.com = X_AB * in_B.com;
  const Eigen::Matrix3d R = X_AB.linear();
  out.inertia_com = R * in_B.inertia_com * R.transpose();
  return out;
}

Inertial CombineInertials(const Inertial& a, const Inertial& b) {
  Inertial c;
  c.mass = a.mass + b.mass;
  if (c.mass == 0.0) return c;
  c.com = (a.mass * a.com + b.mass * b.com) / c.mass;
  auto shift = [&](const Inertial& x) {
    const Eigen::Vector3d d = x.com - c.com;
    return Eigen::Matrix3d(x.inertia_com +
                           x.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose()));
  };
  c.inertia_com = shift(a) + shift(b);
  return c;
}

Eigen::Isometry3d ToEigen(const KDL::Frame& f) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) X.linear()(r, c) = f.M(r, c);
    X.translation()(r) = f.p(r);
  }
  return X;
}

KDL::Frame ToKdl(const Eigen::Isometry3d& X) {
  const Eigen::Matrix3d& R = X.linear();
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0),
                                  R(2, 1), R(2, 2)),
                    KDL::Vector(X.translation()(0), X.translation()(1), X.translation()(2)));
}

KDL::RigidBodyInertia ToKdl(const Inertial& b) {
  const Eigen::Matrix3d& I = b.inertia_com;
  // KDL: cog relative to the segment tip frame, rotational inertia about the cog.
  return KDL::RigidBodyInertia(
      b.mass, KDL::Vector(b.com(0), b.com(1), b.com(2)),
      KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
}

SerialChain::SerialChain(KDL::Chain chain, std::vector<std::string> joint_names,
                         std::vector<JointLimits> limits, std::string base_name,
                         std::string tip_name)
    : chain_(std::make_shared<const KDL::Chain>(std::move(chain))),
      joint_names_(std::move(joint_names)),
      limits_(std::move(limits)),
      base_name_(std::move(base_name)),
      tip_name_(std::move(tip_name)) {
  const int nj = static_cast<int>(chain_->getNrOfJoints());
  if (nj != static_cast<int>(joint_names_.size()) || nj != static_cast<int>(limits_.size())) {
    throw std::invalid_argument("SerialChain: " + std::to_string(nj) + " movable joints but " +
                                std::to_string(joint_names_.size()) + " names and " +
                                std::to_string(limits_.size()) + " limits");
  }
  for (unsigned i = 0; i < chain_->getNrOfSegments(); ++i) {
    const KDL::Joint::JointType t = chain_->getSegment(i).getJoint().getType();
    if (t != KDL::Joint::None && t != KDL::Joint::RotAxis && t != KDL::Joint::RotX &&
        t != KDL::Joint::RotY && t != KDL::Joint::RotZ) {
      throw std::invalid_argument("SerialChain: joint '" +
                                  chain_->getSegment(i).getJoint().getName() +
                                  "' is prismatic; only revolute joints are supported");
    }
  }
}

Inertial SerialChain::segment_inertial(int i) const {
  const KDL::RigidBodyInertia& I = chain_->getSegment(i).getInertia();
  Inertial b;
  b.mass = I.getMass();
  for (int r = 0; r < 3; ++r) b.com(r) = I.getCOG()(r);
  // KDL stores the rotational inertia about the segment frame origin.
  const KDL::RotationalInertia Io = I.getRotationalInertia();
  Eigen::Matrix3d I_o;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) I_o(r, c) = Io.data[3 * r + c];
  }
  const Eigen::Vector3d d = b.com;
  b.inertia_com = I_o - b.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  return b;
}

int SerialChain::last_moving_segment() const {
  for (int i = num_segments() - 1; i >= 0; --i) {
    if (chain_->getSegment(i).getJoint().getType() != KDL::Joint::None) return i;
  }
  return -1;
}

SerialChain SerialChain::WithSegmentInertial(int i, const Inertial& inertial) const {
  KDL::Chain c;
  for (int s = 0; s < num_segments(); ++s) {
    KDL::Segment seg = chain_->getSegment(s);
    if (s == i) seg.setInertia(ToKdl(inertial));
    c.addSegment(seg);
  }
  return SerialChain(std::move(c), joint_names_, limits_, base_name_, tip_name_);
}

SerialChain SerialChain::WithFixedSegment(const std::string& name,
                                          const Eigen::Isometry3d& X_tip_new,
                                          const Inertial& inertial) const {
  KDL::Chain c = *chain_;
  c.addSegment(KDL::Segment(name, KDL::Joint(name, KDL::Joint::None), ToKdl(X_tip_new),
                            ToKdl(inertial)));
  return SerialChain(std::move(c), joint_names_, limits_, base_name_, name);
}

std::vector<int> SerialChain::JointsOutsideLimits(const Eigen::VectorXd& q) const {
  std::vector<int> out;
  for (int j = 0; j < num_joints(); ++j) {
    if (!limits_[j].bounded) continue;
    if (q(j) < limits_[j].lower - 1e-9 || q(j) > limits_[j].upper + 1e-9) out.push_back(j);
  }
  return out;
}

void CheckJointVector(const SerialChain& chain, const Eigen::VectorXd& q) {
  if (q.size() != chain.num_joints()) {
    throw std::invalid_argument("q has " + std::to_string(q.size()) + " entries, the robot has " +
                                std::to_string(chain.num_joints()) + " joints");
  }
  if (!q.allFinite()) throw std::invalid_argument("q has a non-finite entry");
}

namespace {
KDL::JntArray ToJnt(const Eigen::VectorXd& q) {
  KDL::JntArray a(q.size());
  a.data = q;
  return a;
}
}  // namespace

// The one-off solvers below work on a private copy of the KDL chain:
// KDL::Joint::pose() writes a cache in mutable members, so evaluating a
// shared chain from two threads would race.
Eigen::Isometry3d SegmentPose(const SerialChain& chain, const Eigen::VectorXd& q, int segment) {
  CheckJointVector(chain, q);
  const KDL::Chain own = chain.kdl();
  KDL::ChainFkSolverPos_recursive fk(own);
  KDL::Frame f;
  internal::ThrowIfKdlFailed(fk.JntToCart(ToJnt(q), f, segment + 1), fk, "forward kinematics");
  return ToEigen(f);
}

Eigen::Isometry3d ForwardKinematics(const SerialChain& chain, const Eigen::VectorXd& q) {
  return SegmentPose(chain, q, chain.num_segments() - 1);
}

Matrix6Xd Jacobian(const SerialChain& chain, const Eigen::VectorXd& q) {
  CheckJointVector(chain, q);
  const KDL::Chain own = chain.kdl();
  KDL::ChainJntToJacSolver solver(own);
  KDL::Jacobian J(chain.num_joints());
  internal::ThrowIfKdlFailed(solver.JntToJac(ToJnt(q), J), solver, "Jacobian");
  return J.data;
}

}  // namespace robomach::kinematics
