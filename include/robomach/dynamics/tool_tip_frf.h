#pragma once

#include <vector>

#include <Eigen/Core>

#include "robomach/dynamics/posture_dynamics.h"

namespace robomach::dynamics {

/// Tool-tip receptance by the direct solve of the assembled system,
/// <pre>
///   H_T(ω) = B (K − ω² M + iω C)⁻¹ Bᵀ,   ω = 2π f,                  (1)
/// </pre>
/// in joint space (plus effect DOFs): with only joints, B = J_v and (1) is
/// J_v (K_q − ω² M_q + iω C_q)⁻¹ J_vᵀ, identical to the Cartesian form
/// (K_X − ω² M_X + iω C_X)⁻¹ where J is invertible and finite where it is not.
/// @param freq_hz frequency lines [Hz], finite (0 gives the static compliance).
/// @returns one 3×3 receptance [m/N] per line, in B.
std::vector<Eigen::Matrix3cd> ReceptanceDirect(const AssembledSystem& system,
                                               const Eigen::VectorXd& freq_hz);

/// Tool-tip receptance by modal superposition of the mass-normalised real
/// modes [Ewins 2000, §2.3],
/// <pre>
///   H_ij(ω) = Σ_k p_ik p_jk / (ω_k² − ω² + 2i ζ_k ω_k ω),              (2)
/// </pre>
/// exact for proportional damping (2 ζ_k ω_k = alpha ω_k² + beta).
/// @throws std::invalid_argument if `dynamics` has no modes or its damping is
///   not proportional (use ReceptanceComplexModal then).
///
/// - [Ewins 2000] D. J. Ewins, Modal Testing: Theory, Practice and
///   Application, 2nd ed., Research Studies Press, 2000.
std::vector<Eigen::Matrix3cd> ReceptanceModal(const PostureDynamics& dynamics,
                                              const Eigen::VectorXd& freq_hz);

/// Poles and residues of the first-order (state-space) form of the
/// assembled system; exact for non-proportional damping too.
ComplexModalModel ComputeComplexModes(const AssembledSystem& system);
std::vector<Eigen::Matrix3cd> ReceptanceComplexModal(const ComplexModalModel& modes,
                                                     const Eigen::VectorXd& freq_hz);

/// Modal superposition when damping is proportional, complex modes otherwise.
std::vector<Eigen::Matrix3cd> Receptance(const PostureDynamics& dynamics,
                                         const Eigen::VectorXd& freq_hz);

}  // namespace robomach::dynamics
