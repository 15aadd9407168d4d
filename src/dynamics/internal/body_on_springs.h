#pragma once

// A rigid body mounted on springs at a point of the body that carries the
// tool tip: the common core of flange_compliance and spindle_interface
// (and the kinematic part of base_compliance and tool_flexibility).
//
// Let P be the spring point, fixed on the tool-carrying body O (the body
// whose twist at T is AssembledSystem::V_T), S the spring frame (axes R_BS in
// B), and r ∈ R^k the body's small displacement relative to O at P: the
// selected components of [u; θ] (translation of P and small rotation, both in
// S axes). The body D then moves with the twist at P
//   v_P = V_P z' + R_BS E_u r',   ω = Ω z' + R_BS E_θ r',
//   V_P = [I  −[p_P − p_T]×; 0  I] V_T                                    (1)
// (a twist shifted from T to P), and its COM c with v_c = v_P + ω × (c − P).
// With A the 6×N map z' ↦ [v_c; ω] and Λ = diag(m I₃, I_c) in B, the kinetic
// energy of D is ½ z'ᵀ AᵀΛA z' [Featherstone 2008, §2.13]. At r = 0 the body
// moves with O, so the joint (and earlier-DOF) block of AᵀΛA is already in
// M, because D's inertia is part of the robot model; only the rows and
// columns of r are added:
//   M[r, :] += (AᵀΛA)[r, :],   M[:, r] += (AᵀΛA)[:, r],   K[r, r] += K_S. (2)
// If D carries the tool tip, V_T gains the columns [I −[p_T − p_P]×; 0 I] E
// and B = V_T's top rows.
//
// Damping. The model's Rayleigh term α K would give the springs' modes a
// damping ratio α ω/2 that grows with frequency (over 100 % for a holder
// at 3 kHz with the seed's α = 1e-4 s), so the mount replaces it with its
// own: C_extra[r, r] += C_S − α K_S, where C_S = M_rr Φ diag(2 ζ ω_i) Φᵀ M_rr
// gives every mode of D on its springs with the robot held fixed
// (K_S φ_i = ω_i² M_rr φ_i, φᵢᵀ M_rr φ_i = 1) the damping ratio ζ
// [Chopra 2012, §11.4 on classical damping from modal ratios]. What stays
// of the model's damping on r is β M, β/(2ω) ≪ ζ at these frequencies.
//
// - [Chopra 2012] A. K. Chopra, Dynamics of Structures, 4th ed., Prentice
//   Hall, 2012.
//
// - [Featherstone 2008] R. Featherstone, Rigid Body Dynamics Algorithms,
//   Springer, 2008.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/dynamics/effect.h"
#include "robomach/kinematics/serial_chain.h"

namespace robomach::dynamics::internal {

/// [I −[r]×; 0 I]: moves the reference point of a twist [v; ω] by r.
Matrix6d ShiftTwist(const Eigen::Vector3d& r);

struct SpringMount {
  Eigen::Vector3d p_BP{Eigen::Vector3d::Zero()};         // spring point in B [m]
  Eigen::Matrix3d R_BS{Eigen::Matrix3d::Identity()};     // spring-frame axes in B
  /// Free components of [u_x, u_y, u_z, θ_x, θ_y, θ_z] (in S), in the order
  /// of the extra DOFs; the others are rigid.
  std::vector<int> components;
  /// Stiffness on the free components (k×k, symmetric positive definite)
  /// [N/m, N/rad, N·m/rad].
  Eigen::MatrixXd K_S;
  /// The mounted body, expressed in B (com is its position in B).
  kinematics::Inertial body_B;
  bool carries_tool_tip{true};
  double damping_ratio{0.0};  // ζ of the mount's own modes [-]
};

/// C = M Φ diag(2 ζ ω_i) Φᵀ M for the modes of (K, M): the damping matrix
/// that gives every mode the ratio ζ. @pre M SPD, K symmetric PSD.
Eigen::MatrixXd ModalDampingMatrix(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K,
                                   double zeta);

/// The 6×k map from r' to the twist [v_P; ω] of the mounted body at P.
Matrix6Xd MountColumns(const SpringMount& mount);

/// Adds (2) and the damping for the extra DOFs [first_dof, first_dof + k).
/// `p_BT` is the tool tip in B, `alpha` the model's Rayleigh α [s].
/// @pre the body's inertia is already part of the model rigidly attached to
/// the tool-carrying body.
void MountBodyOnSprings(const SpringMount& mount, const Eigen::Vector3d& p_BT, double alpha,
                        int first_dof, AssembledSystem* sys);

/// The mounted body's 6×6 inertia Λ = diag(m I, I_c) at its COM, in B.
Matrix6d SpatialInertiaAtCom(const kinematics::Inertial& body_B);

}  // namespace robomach::dynamics::internal
