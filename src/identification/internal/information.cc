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

namespace robomach::identification::internal {

Identifiability AnalyseIdentifiability(const Eigen::MatrixXd& info) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const int n = static_cast<int>(info.rows());
  Identifiability out;
  out.null.assign(n, false);
  out.no_sensitivity.assign(n, false);
  out.null_partners.assign(n, {});
  out.marginal_std = Eigen::VectorXd::Constant(n, kInf);
  out.conditional_std = Eigen::VectorXd::Constant(n, kInf);
  out.variance_inflation = Eigen::VectorXd::Constant(n, kNaN);
  out.correlation = Eigen::MatrixXd::Constant(n, n, kNaN);
  if (n == 0) return out;
  const Eigen::MatrixXd sym = 0.5 * (info + info.transpose());
  const double lmax_all = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(sym, Eigen::EigenvaluesOnly)
                              .eigenvalues()
                              .maxCoeff();
  const double floor_all = kNullEigenvalue * std::max(lmax_all, 0.0);
  for (int j = 0; j < n; ++j) {
    if (!(sym(j, j) > floor_all)) {
      out.null[j] = true;
      out.no_sensitivity[j] = true;
    } else {
      out.conditional_std(j) = 1.0 / std::sqrt(sym(j, j));
    }
  }
  // Null directions of the joints with some sensitivity: exact trade-offs.
  // Repeated on what remains until the remaining sub-matrix has full rank.
  for (;;) {
    std::vector<int> rest;
    for (int j = 0; j < n; ++j) {
      if (!out.null[j]) rest.push_back(j);
    }
    const int r = static_cast<int>(rest.size());
    if (r == 0) break;
    Eigen::MatrixXd sub(r, r);
    for (int a = 0; a < r; ++a)
      for (int b = 0; b < r; ++b) sub(a, b) = sym(rest[a], rest[b]);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(sub);
    const Eigen::VectorXd& lam = es.eigenvalues();
    const Eigen::MatrixXd& V = es.eigenvectors();
    const double floor = kNullEigenvalue * std::max(lam.maxCoeff(), 0.0);
    Eigen::MatrixXd P = Eigen::MatrixXd::Zero(r, r);  // projector on the null space
    for (int k = 0; k < r; ++k) {
      if (lam(k) <= floor) P += V.col(k) * V.col(k).transpose();
    }
    std::vector<int> found;
    for (int a = 0; a < r; ++a) {
      if (P(a, a) > kNullComponent) found.push_back(a);
    }
    if (found.empty()) {
      // Full rank: marginal covariance of the rest.
      Eigen::MatrixXd C = Eigen::MatrixXd::Zero(r, r);
      for (int k = 0; k < r; ++k) C += V.col(k) * V.col(k).transpose() / lam(k);
      for (int a = 0; a < r; ++a) {
        const int j = rest[a];
        out.marginal_std(j) = std::sqrt(std::max(C(a, a), 0.0));
        out.variance_inflation(j) = C(a, a) * sym(j, j);
        for (int b = 0; b < r; ++b) out.correlation(j, rest[b]) = C(a, b) / std::sqrt(C(a, a) * C(b, b));
      }
      break;
    }
    for (int a : found) {
      const int j = rest[a];
      out.null[j] = true;
      for (int b : found) {
        if (b != a && std::abs(P(a, b)) > 1e-3 * std::sqrt(P(a, a) * P(b, b))) {
          out.null_partners[j].push_back(rest[b]);
        }
      }
    }
  }
  return out;
}

}  // namespace robomach::identification::internal
