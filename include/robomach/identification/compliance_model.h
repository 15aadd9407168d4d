#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/common/eigen_types.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/identification/load_case.h"

namespace robomach::identification {

/// Shifts the reference point of a geometric Jacobian (rows [v; ω], in B):
/// a point P rigidly attached to the tip moves with v_P = v_T + ω × r_TP, so
/// J_BP = [J_v − [r_TP]× J_ω; J_ω], with r_TP the vector from the Jacobian's
/// reference point to P, expressed in B [m].
Matrix6Xd ShiftJacobian(const Matrix6Xd& J_BT, const Eigen::Vector3d& r_TP_B);

/// Geometry of one load case, evaluated once per case: the translational
/// Jacobians of the load point L and the target T (3×n, in B), and the
/// positions of both in B.
struct CaseKinematics {
  Matrix3Xd Jv_L;             // ∂p_L/∂q [m/rad]
  Matrix3Xd Jv_T;             // ∂p_T/∂q [m/rad]
  Eigen::Vector3d p_BL{Eigen::Vector3d::Zero()};   // [m]
  Eigen::Vector3d p_BT{Eigen::Vector3d::Zero()};   // [m]
};

/// Evaluates the kinematics of a case on the model's arm (base to the tip
/// frame); absent load/target points default to the model's tool centre point.
/// @throws std::invalid_argument if q has the wrong size.
CaseKinematics EvaluateCaseKinematics(const dynamics::RobotModel& model, const LoadCase& c);

/// The tool centre point in the arm's tip frame [m] (model geometry, m6/d6 applied).
Eigen::Vector3d TcpInTip(const dynamics::RobotModel& model);

/// The compliance model of the issue, linear in the joint compliances
/// c_i = 1/k_i:
/// <pre>
///   D = J_T,v K_q⁻¹ J_Lᵀ W,   W = [F; 0] (F about the load point L)      (1)
///     = Σ_i c_i τ_i J_T,v[:, i],   τ_i = J_L,v[:, i] · F                 (2)
/// </pre>
/// With L = T this is the seed's F = J⁻ᵀ K_q J⁻¹ D (its eq. (6)). Returns
/// the 3×n matrix A with D = A c: column i is τ_i J_T,v[:, i] [m·N·m/rad].
Matrix3Xd DisplacementPerCompliance(const CaseKinematics& k, const Eigen::Vector3d& force);

/// D of (1) for stiffness `kq` [N·m/rad] [m, in B].
Eigen::Vector3d PredictDisplacement(const dynamics::RobotModel& model, const LoadCase& c,
                                    const Eigen::VectorXd& kq);

/// Second method (large-displacement static equilibrium, no linearisation):
/// finds Δq with K_q Δq = J_L(q + Δq)ᵀ [F; 0] by Newton-like fixed-point
/// iteration and returns p_T(q + Δq) − p_T(q) [m, in B]. For loads that turn
/// the joints by ~1e-3 rad it differs from (1) by O(|Δq|²·reach).
/// @throws std::runtime_error if the iteration does not converge in 100 steps
///   (only for loads far beyond the linear range).
Eigen::Vector3d SolveStaticDeflection(const dynamics::RobotModel& model, const LoadCase& c,
                                      const Eigen::VectorXd& kq);

}  // namespace robomach::identification
