#pragma once

#include <vector>

#include <Eigen/Core>

namespace robomach::identification::internal {

/// Marginal standard deviations √diag(I⁻¹) of an information matrix I,
/// computed through its eigen-decomposition so that numerically null
/// directions give +inf instead of a huge, meaningless number. Eigenvalues
/// below 1e-12 λ_max are rounding noise of a zero: a 6×6 symmetric
/// eigensolver is accurate to ~1e-14 relative.
Eigen::VectorXd MarginalStdFromInformation(const Eigen::MatrixXd& information);

/// What an information matrix I (Fisher information, JᵀWJ, of parameters
/// in relative units) says about each parameter.
///
/// The rule (the identifiability rule of kq-identify, README):
/// - a parameter is *not determined* only when the problem is numerically
///   rank-deficient in it: I has an eigenvalue below kNullEigenvalue·λ_max
///   (rounding of an exact zero; the noise-weighted Jacobian then has
///   singular values below 1e-6 of its largest) whose eigenvector has a
///   component above 1e-3 on the parameter (kNullComponent on its square).
///   Its cause is `no_sensitivity` when its own diagonal I_jj is such a zero
///   (the data do not depend on it at all), otherwise an exact trade-off
///   with `null_partners` (only a combination is fixed). The check is
///   repeated on the remaining parameters until their sub-matrix has full
///   numerical rank.
/// - every other parameter has a finite standard deviation (that of the
///   sub-problem with the not-determined parameters held), however large;
///   how large, and why, is for the caller to report: the conditional
///   standard deviation 1/√I_jj (all others known) measures its own
///   sensitivity, and the variance inflation σ²/σ²_cond ≥ 1 how much of its
///   variance comes from near trade-offs with other parameters (with the
///   correlations naming them).
struct Identifiability {
  std::vector<bool> null;                        // not determined
  std::vector<bool> no_sensitivity;              // null because I_jj ≈ 0
  std::vector<std::vector<int>> null_partners;   // joints sharing a null direction
  Eigen::VectorXd marginal_std;                  // +inf for null parameters
  Eigen::VectorXd conditional_std;               // 1/√I_jj (+inf if I_jj ≈ 0)
  Eigen::VectorXd variance_inflation;            // marginal² / conditional² (NaN if null)
  Eigen::MatrixXd correlation;                   // NaN rows/columns for null parameters
};

constexpr double kNullEigenvalue = 1e-12;
constexpr double kNullComponent = 1e-6;

Identifiability AnalyseIdentifiability(const Eigen::MatrixXd& information);

}  // namespace robomach::identification::internal
