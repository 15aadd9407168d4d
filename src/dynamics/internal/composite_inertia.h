#pragma once

// Spatial quantities of a serial chain at a posture, all at the origin of the
// base frame B and in B axes, with the [v; ω] order of frames.h:
// - each joint's unit twist ξ_j = [o_j × a_j; a_j] (a revolute joint with
//   unit axis a_j through o_j moves a point p at a_j × (p − o_j));
// - each segment's spatial inertia at the origin,
//   Φ = [m I, −m[c]×; m[c]×, I_c − m[c]×[c]×] (momentum [p; L_O] = Φ [v_O; ω])
//   [Featherstone 2008, §2.13];
// - the composite Φ_j^C of everything beyond joint j, and of the whole chain.
// The composite-rigid-body algorithm then gives M_q(j, k) = ξ_jᵀ Φ^C_max(j,k) ξ_k
// [Featherstone 2008, §6.2], and a base motion (twist β at the origin)
// couples to joint k by Φ_k^C ξ_k.
//
// - [Featherstone 2008] R. Featherstone, Rigid Body Dynamics Algorithms,
//   Springer, 2008.
#include <vector>

#include <Eigen/Core>
#include <kdl/chain.hpp>

#include "robomach/common/eigen_types.h"

namespace robomach::dynamics::internal {

struct CompositeInertia {
  std::vector<Vector6d> joint_twist;  // ξ_j, one per joint
  std::vector<Matrix6d> composite;    // Φ_j^C, one per joint
  Matrix6d total{Matrix6d::Zero()};   // the whole chain
  double total_mass{0.0};
};

/// @pre q has one entry per movable joint of `chain`.
CompositeInertia ComputeCompositeInertia(const KDL::Chain& chain, const Eigen::VectorXd& q);

/// Spatial inertia at the origin of a body of mass m, COM c and inertia I_c
/// (all in B).
Matrix6d SpatialInertiaAtOrigin(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& I_c);

/// M_q by the composite-rigid-body algorithm (a second route to KDL's).
Eigen::MatrixXd CompositeRigidBodyMassMatrix(const CompositeInertia& ci);

}  // namespace robomach::dynamics::internal
