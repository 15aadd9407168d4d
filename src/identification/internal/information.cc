#include "identification/internal/information.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace robomach::identification::internal {

Eigen::VectorXd MarginalStdFromInformation(const Eigen::MatrixXd& info) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int p = static_cast<int>(info.rows());
  Eigen::VectorXd out = Eigen::VectorXd::Constant(p, kInf);
  if (p == 0) return out;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(info);
  const Eigen::VectorXd& lam = es.eigenvalues();
  const double floor = 1e-12 * std::max(lam.maxCoeff(), 0.0);
  for (int i = 0; i < p; ++i) {
    double var = 0.0;
    for (int k = 0; k < p; ++k) {
      const double v2 = es.eigenvectors()(i, k) * es.eigenvectors()(i, k);
      if (lam(k) <= floor || lam(k) <= 0.0) {
        if (v2 > 1e-12) var = kInf;
      } else {
        var += v2 / lam(k);
      }
    }
    out(i) = std::sqrt(var);
  }
  return out;
}

}  // namespace robomach::identification::internal
