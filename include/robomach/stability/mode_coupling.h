#pragma once

#include <string>

#include <Eigen/Core>

#include "robomach/common/eigen_types.h"
#include "robomach/stability/milling.h"
#include "robomach/stability/tool_tip_model.h"

namespace robomach::stability {

enum class ModeCouplingStatus {
  kFound,            // an eigenvalue crosses into the right half-plane at critical_depth
  kStableUpToMax,    // no crossing up to the maximum depth searched
  kUnstableAtZero,   // the structure alone is unstable (a bad model)
};
const char* ToString(ModeCouplingStatus s);
/// The inverse of ToString. @throws std::invalid_argument naming the three.
ModeCouplingStatus ParseModeCouplingStatus(const std::string& name);

struct ModeCouplingOptions {
  double max_depth{0.05};    // [m]
  int scan_points{12};       // geometric scan max_depth·2^(j−scan_points), j = 1..scan_points
  double depth_tolerance{1e-4};  // relative bracket width at the end

  /// @throws OptionError naming the field, its value and the bound:
  /// max_depth finite > 0 (the scan's top, halved scan_points times),
  /// scan_points >= 1, depth_tolerance finite > 0 (the bisection stops at a
  /// bracket that narrow; 0 would never stop).
  void Validate() const;
};

struct ModeCouplingResult {
  double critical_depth{NAN};   // [m]
  double chatter_freq_hz{NAN};  // |Im λ|/2π of the crossing eigenvalue
  bool flutter{false};          // complex pair (mode coupling) rather than a real root (divergence)
  ModeCouplingStatus status{ModeCouplingStatus::kStableUpToMax};
  int evaluations{0};
};

/// Largest real part of the eigenvalues of
/// <pre>
///   M z'' + C z' + (K + a Bᵀ K_c B) z = 0                                 (1)
/// </pre>
/// in first-order form, and the eigenvalue attaining it.
std::complex<double> RightmostEigenvalue(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                         const Eigen::MatrixXd& K, const Eigen::MatrixXd& Kc_z,
                                         double depth);

/// Mode-coupling chatter: the tool-tip force fed back by the current tool
/// displacement, F = −a K_c x (K_c = CuttingStiffnessPerDepth rotated into
/// the frame of B), makes the stiffness of (1) non-symmetric; the critical
/// depth is the smallest a where an eigenvalue of (1) reaches Re λ = 0
/// [Tlusty 2000, mode coupling; Pan et al. 2006]. Found by a geometric
/// scan and bisection; Re λ > 1e-9 |λ| counts as unstable, so an undamped
/// model is judged by the sign of the growth and not by rounding.
///
/// @param M, C, K  n×n system matrices (joint space, or the 3×3 Cartesian translational ones).
/// @param B        3×n map from z to the tool-tip translation (identity for Cartesian).
/// @param Kc_B     3×3 cutting stiffness per depth in the frame of B [N/m²].
ModeCouplingResult CriticalDepthModeCoupling(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                             const Eigen::MatrixXd& K, const Matrix3Xd& B,
                                             const Eigen::Matrix3d& Kc_B,
                                             const ModeCouplingOptions& options = {});

/// The same criterion in the modal coordinates of a proportionally damped
/// structure (all its modes kept, so the result is identical to the
/// joint-space form): M = I, C = diag(2ζω), K = diag(ω²), and the cutting
/// term Pᵀ K_c P with P the tool-tip shapes p_k (in the frame of K_c).
ModeCouplingResult CriticalDepthModeCouplingModal(const TipModalModel& modes, const Eigen::Matrix3d& Kc,
                                                  const ModeCouplingOptions& options = {});

/// The rightmost eigenvalue of the modal system of
/// CriticalDepthModeCouplingModal at depth a, and, when `d_lambda_d_depth`
/// is given, its derivative with respect to a from the left and right
/// eigenvectors y, x of the first-order system matrix A(a):
/// dλ/da = yᴴ (∂A/∂a) x / (yᴴ x) [Wilkinson 1965, §2.8]. NaN derivative
/// where the eigenvalue is defective (a coalescing pair). The critical
/// depth's sensitivity to the model's parameters uses both
/// (LocalCriticalDepth).
std::complex<double> RightmostEigenvalueModal(const TipModalModel& modes, const Eigen::Matrix3d& Kc, double depth,
                                              std::complex<double>* d_lambda_d_depth = nullptr);

/// The same for the joint-space system (1) of RightmostEigenvalue.
std::complex<double> RightmostEigenvalueAndDerivative(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                                      const Eigen::MatrixXd& K, const Eigen::MatrixXd& Kc_z,
                                                      double depth, std::complex<double>* d_lambda_d_depth);

/// The simplified closed-form criterion (our reading of the seed method;
/// the seed's text is not in this repository). The in-plane static
/// stiffness S = (G_C,xy)⁻¹ comes from the compliance G = B K⁻¹ Bᵀ rotated
/// into C (axial DOF statically condensed); with equal modal masses and no
/// damping, the eigenvalues of S + a K_c,xy turn complex (flutter) when
/// <pre>
///   D(a) = (s11 − s22 + a(c11 − c22))² + 4 (s12 + a c12)(s21 + a c21) < 0 (2)
/// </pre>
/// a quadratic in a whose smallest positive root is the critical depth.
/// The pose-dependent deformation-ratio coefficient is μ = G_yx / G_xx: the
/// deflection normal to the feed per unit deflection along it under a feed
/// force; with μ = 0 and c12 c21 ≥ 0 the 2-DOF cannot flutter.
struct ClosedFormModeCoupling {
  double critical_depth{INFINITY};  // [m]; infinite if D(a) ≥ 0 for all a > 0
  double deformation_ratio{NAN};    // μ [-]
  double k_min{NAN}, k_max{NAN};    // principal in-plane stiffnesses [N/m]
};
ClosedFormModeCoupling ModeCouplingClosedForm(const Eigen::Matrix3d& compliance_C,
                                              const Eigen::Matrix2d& Kc_C);
/// (2) for a given in-plane stiffness S [N/m] and cutting stiffness K_c [N/m²].
double FlutterDepthClosedForm(const Eigen::Matrix2d& S, const Eigen::Matrix2d& Kc);

/// - [Tlusty 2000] J. Tlusty, Manufacturing Processes and Equipment,
///   Prentice Hall, 2000.
/// - [Pan et al. 2006] Z. Pan, H. Zhang, Z. Zhu, J. Wang, Chatter analysis of
///   robotic machining process, J. Mater. Process. Technol. 173:301-309, 2006.

}  // namespace robomach::stability
