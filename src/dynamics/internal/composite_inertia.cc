#include "dynamics/internal/composite_inertia.h"

#include <Eigen/Geometry>
#include <kdl/frames.hpp>

#include "robomach/common/eigen_types.h"

namespace robomach::dynamics::internal {
namespace {

Eigen::Vector3d ToEigen(const KDL::Vector& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

}  // namespace

Matrix6d SpatialInertiaAtOrigin(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& I_c) {
  const Eigen::Matrix3d C = Skew(c);
  Matrix6d Phi;
  Phi.topLeftCorner<3, 3>() = m * Eigen::Matrix3d::Identity();
  Phi.topRightCorner<3, 3>() = -m * C;
  Phi.bottomLeftCorner<3, 3>() = m * C;
  Phi.bottomRightCorner<3, 3>() = I_c - m * C * C;
  return Phi;
}

CompositeInertia ComputeCompositeInertia(const KDL::Chain& chain, const Eigen::VectorXd& q) {
  const int S = static_cast<int>(chain.getNrOfSegments());
  CompositeInertia out;
  std::vector<Matrix6d> phi(S);
  std::vector<int> joint_segment;
  KDL::Frame F = KDL::Frame::Identity();
  for (int s = 0; s < S; ++s) {
    const KDL::Segment& seg = chain.getSegment(s);
    const KDL::Joint& joint = seg.getJoint();
    double qs = 0.0;
    if (joint.getType() != KDL::Joint::None) {
      const Eigen::Vector3d a = ToEigen(F.M * joint.JointAxis()).normalized();
      const Eigen::Vector3d o = ToEigen(F * joint.JointOrigin());
      Vector6d xi;
      xi << o.cross(a), a;
      out.joint_twist.push_back(xi);
      qs = q(static_cast<Eigen::Index>(joint_segment.size()));
      joint_segment.push_back(s);
    }
    F = F * seg.pose(qs);
    const KDL::RigidBodyInertia& I = seg.getInertia();
    const Eigen::Matrix3d R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(F.M.data);
    // KDL keeps the rotational inertia about the segment frame's origin.
    const KDL::RotationalInertia Io = I.getRotationalInertia();
    Eigen::Matrix3d I_o;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) I_o(r, c) = Io.data[3 * r + c];
    }
    const double m = I.getMass();
    const Eigen::Vector3d cog = ToEigen(I.getCOG());
    // About the COM, in the segment frame, then rotated to B.
    const Eigen::Matrix3d I_c_local = I_o + m * Skew(cog) * Skew(cog);
    phi[s] = SpatialInertiaAtOrigin(m, ToEigen(F * I.getCOG()), R * I_c_local * R.transpose());
    out.total += phi[s];
    out.total_mass += m;
  }
  const int n = static_cast<int>(joint_segment.size());
  out.composite.assign(n, Matrix6d::Zero());
  for (int j = 0; j < n; ++j) {
    for (int s = joint_segment[j]; s < S; ++s) out.composite[j] += phi[s];
  }
  return out;
}

Eigen::MatrixXd CompositeRigidBodyMassMatrix(const CompositeInertia& ci) {
  const int n = static_cast<int>(ci.joint_twist.size());
  Eigen::MatrixXd M(n, n);
  for (int j = 0; j < n; ++j) {
    for (int k = j; k < n; ++k) {
      M(j, k) = M(k, j) = ci.joint_twist[j].dot(ci.composite[k] * ci.joint_twist[k]);
    }
  }
  return M;
}

}  // namespace robomach::dynamics::internal
