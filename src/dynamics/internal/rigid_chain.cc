#include "dynamics/internal/rigid_chain.h"

#include <cmath>
#include <stdexcept>

namespace robomach::dynamics::internal {
namespace {

Eigen::Vector3d ToEigen(const KDL::Vector& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

Eigen::Matrix3d ToEigen(const KDL::Rotation& R) {
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out(r, c) = R(r, c);
  }
  return out;
}

// Rotation by angle t about the unit axis u (Rodrigues):
// R = cos t 1 + sin t [u]× + (1 − cos t) u uᵀ.
Eigen::Matrix3d AxisAngle(const Eigen::Vector3d& u, double t) {
  const double c = std::cos(t), s = std::sin(t), k = 1.0 - c;
  Eigen::Matrix3d R;
  R(0, 0) = c + k * u.x() * u.x();
  R(1, 1) = c + k * u.y() * u.y();
  R(2, 2) = c + k * u.z() * u.z();
  const double xy = k * u.x() * u.y(), xz = k * u.x() * u.z(), yz = k * u.y() * u.z();
  R(0, 1) = xy - s * u.z();
  R(1, 0) = xy + s * u.z();
  R(0, 2) = xz + s * u.y();
  R(2, 0) = xz - s * u.y();
  R(1, 2) = yz - s * u.x();
  R(2, 1) = yz + s * u.x();
  return R;
}

}  // namespace

RigidChain::RigidChain(const KDL::Chain& chain) {
  const int S = static_cast<int>(chain.getNrOfSegments());
  seg_.resize(S);
  for (int s = 0; s < S; ++s) {
    const KDL::Segment& ks = chain.getSegment(s);
    const KDL::Joint& kj = ks.getJoint();
    Segment& g = seg_[s];
    const KDL::Frame X0 = ks.pose(0.0);
    g.R0 = ToEigen(X0.M);
    g.p0 = ToEigen(X0.p);
    g.origin = ToEigen(kj.JointOrigin());
    if (kj.getType() != KDL::Joint::Fixed) {
      // The joint's twist per unit q in the parent frame carries KDL's scale
      // (and its sign): rotational part for revolute joints, else translational.
      const KDL::Twist t = kj.twist(1.0);
      const Eigen::Vector3d w = ToEigen(t.rot), v = ToEigen(t.vel);
      if (w.norm() > 0.0) {
        g.kind = Kind::kRevolute;
        g.rate = w.norm();
        g.axis = w / g.rate;
      } else if (v.norm() > 0.0) {
        g.kind = Kind::kPrismatic;
        g.rate = v.norm();
        g.axis = v / g.rate;
      } else {
        throw std::invalid_argument("segment " + ks.getName() + ": a movable joint with a zero axis");
      }
      g.joint = num_joints_++;
      g.rotor_inertia = kj.getInertia();
      moving_.push_back({s, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
    }
    const KDL::RigidBodyInertia& I = ks.getInertia();
    g.m = I.getMass();
    g.c = ToEigen(I.getCOG());
    // KDL keeps the rotational inertia about the tip frame's origin:
    // I_com = I_o − m (|c|² 1 − c cᵀ).
    const KDL::RotationalInertia Io = I.getRotationalInertia();
    Eigen::Matrix3d I_o;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) I_o(r, c) = Io.data[3 * r + c];
    }
    g.I_com = I_o - g.m * (g.c.squaredNorm() * Eigen::Matrix3d::Identity() - g.c * g.c.transpose());
  }
  cm_.resize(S);
  cc_.resize(S);
  cI_.resize(S);
}

void RigidChain::Compute(const double* q, Eigen::Isometry3d* X_tip,
                         Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> J, Eigen::Ref<Eigen::MatrixXd> M) {
  const int S = static_cast<int>(seg_.size());
  const int n = num_joints_;
  // Forward: poses, joint motions and each body's inertia in B axes.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int s = 0; s < S; ++s) {
    const Segment& g = seg_[s];
    Eigen::Matrix3d R_local;
    Eigen::Vector3d p_local;
    if (g.kind == Kind::kRevolute) {
      Moving& mv = moving_[g.joint];
      mv.w = g.rate * (R * g.axis);
      mv.v0.setZero();
      mv.o = R * g.origin + p;
      const Eigen::Matrix3d Rq = AxisAngle(g.axis, g.rate * q[g.joint]);
      R_local.noalias() = Rq * g.R0;
      p_local = g.origin + Rq * (g.p0 - g.origin);
    } else if (g.kind == Kind::kPrismatic) {
      Moving& mv = moving_[g.joint];
      mv.w.setZero();
      mv.v0 = g.rate * (R * g.axis);
      mv.o = p;
      R_local = g.R0;
      p_local = g.p0 + (g.rate * q[g.joint]) * g.axis;
    } else {
      R_local = g.R0;
      p_local = g.p0;
    }
    p += R * p_local;
    const Eigen::Matrix3d R_prev = R;
    R.noalias() = R_prev * R_local;
    cm_[s] = g.m;
    cc_[s] = R * g.c + p;
    cI_[s].noalias() = R * g.I_com * R.transpose();
  }
  X_tip->linear() = R;
  X_tip->translation() = p;
  X_tip->makeAffine();

  // Backward: composite of s = body s + composite of s + 1, both shifted to
  // their common centre of mass (parallel axes).
  for (int s = S - 2; s >= 0; --s) {
    const double m1 = cm_[s], m2 = cm_[s + 1], m = m1 + m2;
    if (m2 == 0.0) {
      cI_[s] += cI_[s + 1];
      continue;
    }
    if (m1 == 0.0) {
      cc_[s] = cc_[s + 1];
      cI_[s] += cI_[s + 1];
      cm_[s] = m2;
      continue;
    }
    const Eigen::Vector3d c = (m1 * cc_[s] + m2 * cc_[s + 1]) / m;
    const Eigen::Vector3d d1 = cc_[s] - c, d2 = cc_[s + 1] - c;
    // m1 (|d1|² 1 − d1 d1ᵀ) + m2 (|d2|² 1 − d2 d2ᵀ)
    Eigen::Matrix3d shift = -(m1 * d1) * d1.transpose();
    shift.noalias() -= (m2 * d2) * d2.transpose();
    shift.diagonal().array() += m1 * d1.squaredNorm() + m2 * d2.squaredNorm();
    cI_[s] += cI_[s + 1] + shift;
    cc_[s] = c;
    cm_[s] = m;
  }
  for (int j = n - 1; j >= 0; --j) {
    const Moving& mj = moving_[j];
    const int s = mj.segment;
    const Eigen::Vector3d& c = cc_[s];
    // Momentum of the composite moving with joint j, about its centre.
    const Eigen::Vector3d lin = cm_[s] * (mj.v0 + mj.w.cross(c - mj.o));
    const Eigen::Vector3d ang = cI_[s] * mj.w;
    for (int k = 0; k <= j; ++k) {
      const Moving& mk = moving_[k];
      const double mkj = (mk.v0 + mk.w.cross(c - mk.o)).dot(lin) + mk.w.dot(ang);
      M(k, j) = mkj;
      M(j, k) = mkj;
    }
    M(j, j) += seg_[s].rotor_inertia;
    J.col(j).head<3>() = mj.v0 + mj.w.cross(p - mj.o);
    J.col(j).tail<3>() = mj.w;
  }
}

}  // namespace robomach::dynamics::internal
