#pragma once

// Forward kinematics, the tool-tip Jacobian and the joint-space inertia M_q of
// a serial chain in ONE pass over its segments, without allocation: what
// PostureEvaluator needs per posture. KDL's three solvers
// (ChainFkSolverPos_recursive, ChainJntToJacSolver, ChainDynParam::JntToMass)
// each redo the segment poses in KDL types; here the poses are formed once
// and every quantity is kept in base-frame axes, so composite inertias are
// plain sums [Featherstone 2008, §6.2 (CRBA)]:
// - joint j moves a point x at v_j(x) = v0_j + ω_j × (x − o_j): a revolute
//   joint has ω_j = rate · axis through the point o_j and v0_j = 0, a
//   prismatic one ω_j = 0 and v0_j = rate · axis;
// - Φ^C_j, the composite of all bodies from joint j's segment to the tip, is
//   kept as its mass m, centre of mass c and inertia I_G about c (parallel-
//   axis sums about the combined centre). Not about the base origin: there
//   the wrist's small inertias would be differences of terms ~m|c|² ≈ 1e4
//   times larger, and M_q's wrist entries would lose four digits;
// - M_q(k, j) = ξ_kᵀ Φ^C_j ξ_j (k <= j) = v_k(c)·p + ω_k·L with the
//   momentum of the composite moving with joint j, p = m v_j(c), L = I_G ω_j
//   (about c); KDL's joint (rotor) inertia is added to the diagonal, as
//   ChainDynParam does;
// - J_BT column j = [v_j(p_T); ω_j] at the tip p_T.
// The segment motion is KDL's own: Segment::pose(q) = rotation by rate·q
// about the joint axis through the joint origin (both in the segment's
// parent frame) applied to Segment::pose(0), or a translation along the axis
// for a prismatic joint; tests/dynamics/posture_fast_path_test.cc checks
// pose, J and M_q against KDL's solvers.
//
// - [Featherstone 2008] R. Featherstone, Rigid Body Dynamics Algorithms,
//   Springer, 2008.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <kdl/chain.hpp>

namespace robomach::dynamics::internal {

class RigidChain {
 public:
  /// Reads the segments of `chain` (not kept).
  explicit RigidChain(const KDL::Chain& chain);

  int num_joints() const { return num_joints_; }

  /// Pose of the chain's tip X_BT, its Jacobian J (6 × n, rows [v; ω], in B,
  /// about the tip) and M_q (n × n). q has n entries; J and M must already
  /// have their sizes. Not thread-safe (per-evaluation buffers are members).
  void Compute(const double* q, Eigen::Isometry3d* X_tip, Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> J,
               Eigen::Ref<Eigen::MatrixXd> M);

 private:
  enum class Kind { kFixed, kRevolute, kPrismatic };
  struct Segment {
    Kind kind{Kind::kFixed};
    int joint{-1};                  // index in q
    Eigen::Vector3d axis;           // unit joint axis, parent frame
    double rate{1.0};               // KDL joint scale (angle or displacement per unit q)
    Eigen::Vector3d origin;         // a point of the axis, parent frame
    Eigen::Matrix3d R0;             // Segment::pose(0), in the parent frame
    Eigen::Vector3d p0;
    double m{0.0};                  // body in the segment's tip frame
    Eigen::Vector3d c;              // centre of mass
    Eigen::Matrix3d I_com;          // about the centre of mass
    double rotor_inertia{0.0};      // KDL Joint::getInertia()
  };
  struct Moving {                   // per joint, per evaluation, in B
    int segment{0};
    Eigen::Vector3d w, v0, o;       // v(x) = v0 + w × (x − o)
  };
  std::vector<Segment> seg_;
  int num_joints_{0};
  // Per evaluation: composite of segment s and all after it, in B.
  std::vector<double> cm_;
  std::vector<Eigen::Vector3d> cc_;  // centre of mass
  std::vector<Eigen::Matrix3d> cI_;  // about cc_
  std::vector<Moving> moving_;
};

}  // namespace robomach::dynamics::internal
