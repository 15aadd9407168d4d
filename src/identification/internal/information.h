#pragma once

#include <Eigen/Core>

namespace robomach::identification::internal {

/// Marginal standard deviations √diag(I⁻¹) of an information matrix I,
/// computed through its eigen-decomposition so that numerically null
/// directions give +inf instead of a huge, meaningless number. Eigenvalues
/// below 1e-12 λ_max are rounding noise of a zero: a 6×6 symmetric
/// eigensolver is accurate to ~1e-14 relative.
Eigen::VectorXd MarginalStdFromInformation(const Eigen::MatrixXd& information);

}  // namespace robomach::identification::internal
