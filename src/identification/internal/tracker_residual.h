#pragma once

// Private to src/identification: the Ceres cost of one load case.

#include <cmath>

#include <ceres/ceres.h>
#include <Eigen/Core>

#include "robomach/common/eigen_types.h"

namespace robomach::identification::internal {

/// Weighted residual of one load case in the scaled log-stiffness
/// θ_i = log(k_i / k0_i), where k0 is the prior:
/// <pre>
///   r(θ) = y − B x(θ),   x_i = exp(−θ_i) = c_i k0_i,
///   y = D / σ_D,   B = A diag(1/k0) / σ_D                          (3)
/// </pre>
/// with A of compliance_model.h (D = A c). ∂r/∂θ_i = B[:, i] x_i (analytic:
/// the model is one exponential per column).
class TrackerResidual final : public ceres::CostFunction {
 public:
  TrackerResidual(const Eigen::Vector3d& y, const Matrix3Xd& B) : y_(y), B_(B) {
    set_num_residuals(3);
    mutable_parameter_block_sizes()->push_back(static_cast<int>(B.cols()));
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = static_cast<int>(B_.cols());
    const double* theta = parameters[0];
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = y_;
    for (int i = 0; i < n; ++i) {
      const double x = std::exp(-theta[i]);
      r -= B_.col(i) * x;
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        for (int a = 0; a < 3; ++a) jacobians[0][a * n + i] = B_(a, i) * x;  // row-major
      }
    }
    return r.allFinite();
  }

 private:
  Eigen::Vector3d y_;
  Matrix3Xd B_;
};

}  // namespace robomach::identification::internal
