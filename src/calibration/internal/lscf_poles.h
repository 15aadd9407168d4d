#pragma once

// What the single-FRF fit (modal_fit.cc) and the global fit
// (global_modal_fit.cc) share of the LSCF: the physical poles of one model
// order from its reduced normal matrix, and a fast complex reciprocal.

#include <cmath>
#include <complex>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "robomach/common/units.h"

namespace robomach::calibration::internal {

/// 1/z as conj(z)/|z|²: std::complex's division (__divdc3, with its care for
/// infinities and scaling) was a sixth of the modal fit's time; the poles
/// and frequencies here are far from overflow.
inline std::complex<double> Reciprocal(std::complex<double> z) {
  const double n = z.real() * z.real() + z.imag() * z.imag();
  return {z.real() / n, -z.imag() / n};
}

struct LscfPole {
  double f_hz, zeta;
  std::complex<double> lambda;  // [rad/s]
};

/// The poles of order n from the (n+1)² reduced normal matrix M: the
/// denominator with a_n = 1 solves M[0:n,0:n] a = −M[0:n,n]; its roots z
/// (eigenvalues of the companion matrix) give λ = ln(z)/Δt. Kept: Im λ > 0,
/// 0 < ζ < max_damping_ratio, f in [fmin_hz, fmax_hz]. Empty when the
/// solve or the eigenproblem fails.
inline std::vector<LscfPole> PolesOfOrder(const Eigen::MatrixXd& M, int n, double dt, double max_damping_ratio,
                                          double fmin_hz, double fmax_hz) {
  std::vector<LscfPole> out;
  const Eigen::VectorXd a = M.topLeftCorner(n, n).ldlt().solve(-M.col(n).head(n));
  if (!a.allFinite()) return out;
  // Companion matrix of z^n + a_{n−1} z^{n−1} + ... + a_0.
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  for (int i = 1; i < n; ++i) C(i, i - 1) = 1.0;
  for (int i = 0; i < n; ++i) C(i, n - 1) = -a(i);
  const Eigen::EigenSolver<Eigen::MatrixXd> es(C, false);
  if (es.info() != Eigen::Success) return out;
  for (int i = 0; i < n; ++i) {
    const std::complex<double> z = es.eigenvalues()(i);
    if (std::abs(z) == 0.0) continue;
    const std::complex<double> lambda = std::log(z) / dt;
    if (!(lambda.imag() > 0.0)) continue;
    const double wn = std::abs(lambda);
    const double zeta = -lambda.real() / wn;
    const double f_hz = RadPerSecToHz(wn);
    if (!(zeta > 0.0 && zeta < max_damping_ratio)) continue;
    if (f_hz < fmin_hz || f_hz > fmax_hz) continue;
    out.push_back({f_hz, zeta, lambda});
  }
  return out;
}

}  // namespace robomach::calibration::internal
