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
/// Evaluated in real arithmetic, several lines at once in SIMD registers
/// (dynamics/internal/modal_sum.h).
/// @throws std::invalid_argument if `dynamics` has no modes, its damping is
///   not proportional (use ReceptanceComplexModal then) or it was evaluated
///   without damping ratios.
///
/// - [Ewins 2000] D. J. Ewins, Modal Testing: Theory, Practice and
///   Application, 2nd ed., Research Studies Press, 2000.
std::vector<Eigen::Matrix3cd> ReceptanceModal(const PostureDynamics& dynamics,
                                              const Eigen::VectorXd& freq_hz);
/// The same into `H` (resized to the number of lines), reusing its storage:
/// no allocation when it already has that size.
void ReceptanceModal(const PostureDynamics& dynamics, const Eigen::VectorXd& freq_hz,
                     std::vector<Eigen::Matrix3cd>* H);

/// Poles and residues of the first-order (state-space) form of the
/// assembled system; exact for non-proportional damping too.
ComplexModalModel ComputeComplexModes(const AssembledSystem& system);
std::vector<Eigen::Matrix3cd> ReceptanceComplexModal(const ComplexModalModel& modes,
                                                     const Eigen::VectorXd& freq_hz);

/// Modal superposition when damping is proportional, complex modes otherwise.
std::vector<Eigen::Matrix3cd> Receptance(const PostureDynamics& dynamics,
                                         const Eigen::VectorXd& freq_hz);

/// Single entries H_re of the tool-tip receptance at one posture, for fits
/// and error measures that need one direction pair on many lines: the modal
/// data (real modes for proportional damping, complex modes otherwise) are
/// prepared once, and each line costs one scalar term per mode instead of a
/// 3×3 matrix. Same values as Receptance(dynamics, f)(r, e).
class ReceptanceEvaluator {
 public:
  /// @throws std::runtime_error if the complex modal analysis fails.
  explicit ReceptanceEvaluator(const PostureDynamics& dynamics);
  /// H_re [m/N] at every line of `freq_hz` [Hz]; response r, excitation e in 0..2.
  Eigen::VectorXcd Entry(const Eigen::VectorXd& freq_hz, int response, int excitation) const;
  /// H_re at one frequency.
  std::complex<double> Entry(double freq_hz, int response, int excitation) const;

 private:
  bool real_modes_{false};
  // Real modes: ω_k², 2 ζ_k ω_k and p_T per mode (columns).
  Eigen::VectorXd w2_, c_;
  Eigen::Matrix3Xd p_;
  // Complex modes: poles λ_k and residue matrices.
  Eigen::VectorXcd poles_;
  std::vector<Eigen::Matrix3cd> residues_;
};

}  // namespace robomach::dynamics
