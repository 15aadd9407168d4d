#include "robomach/stability/mode_coupling.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "robomach/common/enum_names.h"

namespace robomach::stability {

const char* ToString(ModeCouplingStatus s) {
  switch (s) {
    case ModeCouplingStatus::kFound: return "ok";
    case ModeCouplingStatus::kStableUpToMax: return "stable_up_to_max";
    case ModeCouplingStatus::kUnstableAtZero: return "unstable_at_zero";
  }
  return "?";
}

ModeCouplingStatus ParseModeCouplingStatus(const std::string& name) {
  constexpr ModeCouplingStatus kAll[] = {ModeCouplingStatus::kFound, ModeCouplingStatus::kStableUpToMax,
                                         ModeCouplingStatus::kUnstableAtZero};
  return ParseByName("mode-coupling status", name, kAll);
}

std::complex<double> RightmostEigenvalue(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                         const Eigen::MatrixXd& K, const Eigen::MatrixXd& Kc_z,
                                         double depth) {
  const Eigen::Index n = M.rows();
  const Eigen::LLT<Eigen::MatrixXd> llt(M);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -llt.solve(K + depth * Kc_z);
  A.bottomRightCorner(n, n) = -llt.solve(C);
  Eigen::EigenSolver<Eigen::MatrixXd> es(A, false);
  const Eigen::VectorXcd ev = es.eigenvalues();
  Eigen::Index imax = 0;
  ev.real().maxCoeff(&imax);
  return ev(imax);
}

void ModeCouplingOptions::Validate() const {
  CheckOptionFinite("max_depth", max_depth);
  CheckOptionAbove("max_depth", max_depth, 0.0);
  CheckOptionAtLeast("scan_points", scan_points, 1);
  CheckOptionFinite("depth_tolerance", depth_tolerance);
  CheckOptionAbove("depth_tolerance", depth_tolerance, 0.0);
}

namespace {

// Smallest depth in (0, max_depth] where the rightmost eigenvalue crosses
// into the right half-plane: a geometric scan brackets it, then a
// safeguarded regula falsi (Illinois, each step kept at least 5 % of the
// bracket from its ends) narrows the bracket to the tolerance.
//
// `stable_below` is a depth below which the system is known to be stable
// (a small-gain certificate, ModalSearch): the scan points below it are not
// evaluated, except the last one when the first unstable point follows it,
// so the bracket and the result are those of the full scan.
template <class Rightmost>
ModeCouplingResult SearchCriticalDepth(const Rightmost& rightmost, const ModeCouplingOptions& options,
                                       double stable_below = 0.0) {
  ModeCouplingResult out;  // options: validated by the public callers
  // An undamped stable system has Re λ = 0 up to rounding, ~eps·|λ|;
  // 1e-9 |λ| is far above that and, since Re λ grows like √(a − a_c)
  // past a flutter point, moves the crossing by only ~1e-18 relative.
  auto growth = [&](double a, std::complex<double>* lambda) {
    ++out.evaluations;
    *lambda = rightmost(a);
    return lambda->real() - 1e-9 * std::abs(*lambda);
  };
  std::complex<double> lam;
  // g_lo is NaN while lo is a certified point not evaluated.
  double lo = 0.0, hi = NAN, g_lo = stable_below > 0.0 ? NAN : growth(0.0, &lam), g_hi = 0.0;
  if (g_lo > 0.0) {
    out.status = ModeCouplingStatus::kUnstableAtZero;
    return out;
  }
  std::complex<double> lam_hi;
  for (int j = 1; j <= options.scan_points; ++j) {
    const double a = options.max_depth * std::ldexp(1.0, j - options.scan_points);
    if (a < stable_below) {
      lo = a;
      g_lo = NAN;
      continue;
    }
    const double g = growth(a, &lam);
    if (g > 0.0) {
      hi = a;
      g_hi = g;
      lam_hi = lam;
      break;
    }
    lo = a;
    g_lo = g;
  }
  if (std::isfinite(hi) && std::isnan(g_lo)) {
    g_lo = growth(lo, &lam);
    if (g_lo > 0.0) {
      // Not expected (the certificate says stable): the full scan decides.
      return SearchCriticalDepth(rightmost, options, 0.0);
    }
  }
  if (!std::isfinite(hi)) {
    out.status = ModeCouplingStatus::kStableUpToMax;
    out.critical_depth = options.max_depth;
    return out;
  }
  // Regula falsi with the Anderson-Björck weight: when the same end is kept
  // twice, its value is scaled by m = 1 − g_new/g_old of the moved end (by
  // 0.5 when m <= 0, Illinois) [Anderson & Björck 1973]. A trial point
  // within half the tolerance of an end is moved to half the tolerance from
  // it, so a good estimate closes the bracket in one step.
  int side = 0;  // which end was moved last time
  while (hi - lo > options.depth_tolerance * hi) {
    const double w = hi - lo;
    const double half_tol = 0.5 * options.depth_tolerance * hi;
    double x = (g_hi - g_lo) != 0.0 ? lo - g_lo * w / (g_hi - g_lo) : 0.5 * (lo + hi);
    x = std::clamp(x, lo + 0.05 * w, hi - 0.05 * w);
    if (x - lo < half_tol) x = lo + half_tol;
    if (hi - x < half_tol) x = hi - half_tol;
    const double g = growth(x, &lam);
    if (g > 0.0) {
      if (side == -1) {
        const double m = 1.0 - g / g_hi;
        g_lo *= m > 0.0 ? m : 0.5;
      }
      hi = x;
      g_hi = g;
      lam_hi = lam;
      side = -1;
    } else {
      if (side == 1) {
        const double m = 1.0 - g / g_lo;
        g_hi *= m > 0.0 ? m : 0.5;
      }
      lo = x;
      g_lo = g;
      side = 1;
    }
  }
  out.critical_depth = 0.5 * (lo + hi);
  out.chatter_freq_hz = std::abs(lam_hi.imag()) / (2.0 * kPi);
  out.flutter = std::abs(lam_hi.imag()) > 1e-6 * std::abs(lam_hi);
  out.status = ModeCouplingStatus::kFound;
  return out;
}

// The rightmost eigenvalue of first-order system matrices of one size,
// with the solver's storage kept between calls (the depth search calls it
// 20-30 times per posture, a stability map 10^5 times per thread). Rows =
// 2n at compile time where it is known (12 for a six-joint robot: Eigen
// then keeps everything on the stack), Eigen::Dynamic otherwise.
template <int Rows>
class RightmostSolver {
 public:
  using Matrix = Eigen::Matrix<double, Rows, Rows>;
  explicit RightmostSolver(Eigen::Index rows) : es_(rows) {}
  std::complex<double> operator()(const Matrix& A) {
    es_.compute(A, false);
    const auto& ev = es_.eigenvalues();
    Eigen::Index imax = 0;
    for (Eigen::Index i = 1; i < ev.size(); ++i) {
      if (ev(i).real() > ev(imax).real()) imax = i;  // the first of equal maxima, as maxCoeff
    }
    return ev(imax);
  }

 private:
  Eigen::EigenSolver<Matrix> es_;
};

// A depth below which the modal system is stable, by the small-gain
// theorem. On s = iω the characteristic matrix factors as
// Q(iω) + a K_q = Q(iω) (I + a Q⁻¹ pᵀ K_c p), Q = diag(ω_k² − ω² + 2iζ_kω_kω),
// and det(I + a Q⁻¹ pᵀ K_c p) = det(I₃ + a K_c G(iω)) with the tip
// receptance G = p Q⁻¹ pᵀ. While a‖K_c‖ ‖G(iω)‖ < 1 at every ω, or
// a ‖Q⁻¹‖ ‖K_q‖ < 1, no eigenvalue lies on the imaginary axis, so none can
// cross it between depth 0 (stable when every ζ_k > 0) and a. The peaks are
// bounded mode by mode: 1/|ω_k² − ω² + 2iζ_kω_kω| ≤ 1/(2ζ_kω_k²√(1 − ζ_k²)).
// Frobenius norms bound the 2-norms. Zero when a mode is undamped.
double SmallGainStableDepth(const TipModalModel& modes, const Eigen::Matrix3d& Kc, const Eigen::MatrixXd& Kc_q) {
  double sum_g = 0.0, max_q = 0.0;
  for (int k = 0; k < modes.num_modes(); ++k) {
    const double z = modes.zeta(k), w = modes.omega_rad_s(k);
    if (!(z > 0.0)) return 0.0;
    const double peak = 1.0 / (2.0 * z * w * w * std::sqrt(1.0 - z * z));
    sum_g += modes.p.col(k).squaredNorm() * peak;
    max_q = std::max(max_q, peak);
  }
  const double loop = std::min(Kc.norm() * sum_g, Kc_q.norm() * max_q);
  return loop > 0.0 && std::isfinite(loop) ? 1.0 / loop : 0.0;
}

template <int Rows>
ModeCouplingResult ModalSearch(const TipModalModel& modes, const Eigen::MatrixXd& Kc_q,
                               const ModeCouplingOptions& options, double stable_below) {
  const int n = modes.num_modes();
  using Matrix = typename RightmostSolver<Rows>::Matrix;
  // State (η, η̇/ω): A = S A₀ S⁻¹ with S = diag(I, Ω⁻¹) has the same
  // eigenvalues and entries of one scale (ω), which the QR iteration of the
  // eigensolver needs fewer steps for than the unscaled [0 I; −Ω² −2ZΩ].
  const Eigen::VectorXd& w = modes.omega_rad_s;
  Matrix A = Matrix::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).diagonal() = w;
  A.bottomRightCorner(n, n).diagonal() = -2.0 * modes.zeta.cwiseProduct(w);
  using Half = Eigen::Matrix<double, Rows == Eigen::Dynamic ? Eigen::Dynamic : Rows / 2,
                             Rows == Eigen::Dynamic ? Eigen::Dynamic : Rows / 2>;
  const Half Kc_scaled = w.cwiseInverse().asDiagonal() * Kc_q;
  RightmostSolver<Rows> rightmost(2 * n);
  return SearchCriticalDepth(
      [&](double a) {
        A.bottomLeftCorner(n, n) = -a * Kc_scaled;
        A.bottomLeftCorner(n, n).diagonal() -= w;
        return rightmost(A);
      },
      options, stable_below);
}

}  // namespace

ModeCouplingResult CriticalDepthModeCoupling(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                             const Eigen::MatrixXd& K, const Matrix3Xd& B,
                                             const Eigen::Matrix3d& Kc_B,
                                             const ModeCouplingOptions& options) {
  options.Validate();
  const Eigen::Index n = M.rows();
  if (M.cols() != n || C.rows() != n || C.cols() != n || K.rows() != n || K.cols() != n ||
      B.cols() != n) {
    throw std::invalid_argument("mode coupling: M, C, K must be n×n and B 3×n");
  }
  const Eigen::MatrixXd Kc_z = B.transpose() * Kc_B * B;
  const Eigen::LLT<Eigen::MatrixXd> llt(M);
  const Eigen::MatrixXd MiK = llt.solve(K), MiKc = llt.solve(Kc_z), MiC = llt.solve(C);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomRightCorner(n, n) = -MiC;
  RightmostSolver<Eigen::Dynamic> rightmost(2 * n);
  return SearchCriticalDepth(
      [&](double a) {
        A.bottomLeftCorner(n, n) = -(MiK + a * MiKc);
        return rightmost(A);
      },
      options);
}

ModeCouplingResult CriticalDepthModeCouplingModal(const TipModalModel& modes, const Eigen::Matrix3d& Kc,
                                                  const ModeCouplingOptions& options) {
  modes.Validate();
  options.Validate();
  const int n = modes.num_modes();
  const Eigen::MatrixXd Kc_q = modes.p.transpose() * Kc * modes.p;
  // Six modes (a six-joint robot): fixed-size matrices, no heap at all.
  const double stable_below = SmallGainStableDepth(modes, Kc, Kc_q);
  if (n == 6) return ModalSearch<12>(modes, Kc_q, options, stable_below);
  return ModalSearch<Eigen::Dynamic>(modes, Kc_q, options, stable_below);
}

namespace {

// The rightmost eigenvalue of A and, if asked, dλ/da = y (∂A/∂a) x with x
// the right eigenvector and y the row of V⁻¹ that belongs to it (so y x = 1).
template <class Matrix>
std::complex<double> RightmostWithDerivative(const Matrix& A, const Matrix& dA_da, std::complex<double>* d) {
  Eigen::EigenSolver<Matrix> es(A, d != nullptr);
  const auto& ev = es.eigenvalues();
  Eigen::Index imax = 0;
  for (Eigen::Index i = 1; i < ev.size(); ++i) {
    if (ev(i).real() > ev(imax).real()) imax = i;  // the first of equal maxima, as RightmostSolver
  }
  if (d != nullptr) {
    const Eigen::MatrixXcd V = es.eigenvectors();
    const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(V);
    // Row imax of V⁻¹: solve Vᵀ yᵀ = e_imax.
    Eigen::VectorXcd e = Eigen::VectorXcd::Zero(V.rows());
    e(imax) = 1.0;
    const Eigen::VectorXcd y = lu.transpose().solve(e);
    *d = y.transpose() * dA_da.template cast<std::complex<double>>() * V.col(imax);
    // The eigenvalue's condition number |y| |x| / |y x| (y x = 1 here): a
    // defective eigenvalue (two modes coalescing) has no derivative, and
    // near one the derivative is not to be trusted. 1e8: the derivative
    // then still has about 8 digits.
    const double condition = y.norm() * V.col(imax).norm();
    if (!(condition < 1e8) || !std::isfinite(d->real()) || !std::isfinite(d->imag())) {
      *d = std::complex<double>(NAN, NAN);
    }
  }
  return ev(imax);
}

template <int Rows>
std::complex<double> ModalRightmost(const TipModalModel& modes, const Eigen::MatrixXd& Kc_q, double depth,
                                    std::complex<double>* d) {
  const int n = modes.num_modes();
  using Matrix = Eigen::Matrix<double, Rows, Rows>;
  // The scaled state of ModalSearch: the same eigenvalues.
  const Eigen::VectorXd& w = modes.omega_rad_s;
  const Eigen::MatrixXd Kc_scaled = w.cwiseInverse().asDiagonal() * Kc_q;
  Matrix A = Matrix::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).diagonal() = w;
  A.bottomRightCorner(n, n).diagonal() = -2.0 * modes.zeta.cwiseProduct(w);
  A.bottomLeftCorner(n, n) = -depth * Kc_scaled;
  A.bottomLeftCorner(n, n).diagonal() -= w;
  Matrix dA = Matrix::Zero(2 * n, 2 * n);
  if (d != nullptr) dA.bottomLeftCorner(n, n) = -Kc_scaled;
  return RightmostWithDerivative(A, dA, d);
}

}  // namespace

std::complex<double> RightmostEigenvalueModal(const TipModalModel& modes, const Eigen::Matrix3d& Kc, double depth,
                                              std::complex<double>* d_lambda_d_depth) {
  modes.Validate();
  const Eigen::MatrixXd Kc_q = modes.p.transpose() * Kc * modes.p;
  if (modes.num_modes() == 6) return ModalRightmost<12>(modes, Kc_q, depth, d_lambda_d_depth);
  return ModalRightmost<Eigen::Dynamic>(modes, Kc_q, depth, d_lambda_d_depth);
}

std::complex<double> RightmostEigenvalueAndDerivative(const Eigen::MatrixXd& M, const Eigen::MatrixXd& C,
                                                      const Eigen::MatrixXd& K, const Eigen::MatrixXd& Kc_z,
                                                      double depth, std::complex<double>* d_lambda_d_depth) {
  const Eigen::Index n = M.rows();
  const Eigen::LLT<Eigen::MatrixXd> llt(M);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n), dA = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -llt.solve(K + depth * Kc_z);
  A.bottomRightCorner(n, n) = -llt.solve(C);
  if (d_lambda_d_depth != nullptr) dA.bottomLeftCorner(n, n) = -llt.solve(Kc_z);
  return RightmostWithDerivative(A, dA, d_lambda_d_depth);
}

double FlutterDepthClosedForm(const Eigen::Matrix2d& S, const Eigen::Matrix2d& Kc) {
  const double ds = S(0, 0) - S(1, 1), dc = Kc(0, 0) - Kc(1, 1);
  // D(a) = q2 a² + q1 a + q0
  const double q2 = dc * dc + 4.0 * Kc(0, 1) * Kc(1, 0);
  const double q1 = 2.0 * ds * dc + 4.0 * (S(0, 1) * Kc(1, 0) + Kc(0, 1) * S(1, 0));
  const double q0 = ds * ds + 4.0 * S(0, 1) * S(1, 0);
  if (q0 < 0.0) return 0.0;  // already complex without cutting
  // Smallest a > 0 where D changes sign from >= 0 to < 0.
  if (q2 == 0.0) {
    if (q1 < 0.0) return -q0 / q1;
    return INFINITY;
  }
  const double disc = q1 * q1 - 4.0 * q2 * q0;
  if (disc < 0.0) return INFINITY;  // D keeps the sign of q2 > 0 (q0 >= 0)
  const double sq = std::sqrt(disc);
  // Stable root formulas (no cancellation).
  const double qq = -0.5 * (q1 + std::copysign(sq, q1));
  double r1 = qq / q2, r2 = qq != 0.0 ? q0 / qq : -q1 / q2;
  if (r1 > r2) std::swap(r1, r2);
  // With q2 > 0, D < 0 between the roots; with q2 < 0, beyond the larger.
  if (q2 > 0.0) {
    if (r2 <= 0.0) return INFINITY;
    return r1 > 0.0 ? r1 : (q0 > 0.0 ? INFINITY : 0.0);
  }
  return r2 > 0.0 ? r2 : 0.0;
}

ClosedFormModeCoupling ModeCouplingClosedForm(const Eigen::Matrix3d& compliance_C,
                                              const Eigen::Matrix2d& Kc_C) {
  ClosedFormModeCoupling out;
  const Eigen::Matrix2d G = compliance_C.topLeftCorner<2, 2>();
  const Eigen::Matrix2d S = G.inverse();
  out.deformation_ratio = G(1, 0) / G(0, 0);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(0.5 * (S + S.transpose()));
  out.k_min = es.eigenvalues()(0);
  out.k_max = es.eigenvalues()(1);
  out.critical_depth = FlutterDepthClosedForm(S, Kc_C);
  return out;
}

}  // namespace robomach::stability
