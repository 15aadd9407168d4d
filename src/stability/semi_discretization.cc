#include "robomach/stability/semi_discretization.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include "robomach/common/option_validate.h"
#include "robomach/common/parallel.h"
#include "robomach/common/units.h"

namespace robomach::stability {

namespace {

// The dominant eigenvalue of the monodromy matrix Φ (D × D), given only
// its product with vectors, by Arnoldi's method [Saad 2011, §6.3]: the
// eigenvalues of the Hessenberg matrix H_K of the Krylov space of dimension
// K (Ritz values) approximate the outermost eigenvalues of Φ first. The
// monodromy of a semi-discretised delay equation has few such eigenvalues
// (about two per mode) and D − O(d) crowded near zero (the delay line), so
// K of a few d captures the dominant one. It is accepted only when its Ritz
// residual |h_{K+1,K} s_K| is below 1e-12 of |θ| (then θ is an eigenvalue of
// a matrix within that of Φ); otherwise K doubles, and at K = D the Krylov
// space is the whole space and H_K is similar to Φ: the dense answer.
template <class Apply>
std::complex<double> DominantEigenvalue(int D, int d, const Apply& apply) {
  int K = std::min(D, std::max(40, 4 * d));
  for (;;) {
    Eigen::MatrixXd V(D, K + 1), H = Eigen::MatrixXd::Zero(K + 1, K);
    // A fixed start with every component non-zero (reproducible results).
    for (int i = 0; i < D; ++i) V(i, 0) = 1.0 + 0.5 * std::sin(1.0 + 0.7 * i);
    V.col(0).normalize();
    int k_used = K;
    Eigen::VectorXd w(D);
    for (int j = 0; j < K; ++j) {
      apply(V.col(j), &w);
      for (int pass = 0; pass < 2; ++pass) {  // Gram-Schmidt twice: orthogonal to rounding
        const Eigen::VectorXd h = V.leftCols(j + 1).transpose() * w;
        w.noalias() -= V.leftCols(j + 1) * h;
        H.col(j).head(j + 1) += h;
      }
      H(j + 1, j) = w.norm();
      if (H(j + 1, j) <= 1e-14 * H.col(j).head(j + 1).norm()) {  // invariant subspace: exact
        k_used = j + 1;
        break;
      }
      V.col(j + 1) = w / H(j + 1, j);
    }
    Eigen::EigenSolver<Eigen::MatrixXd> es(H.topLeftCorner(k_used, k_used), true);
    const Eigen::VectorXcd theta = es.eigenvalues();
    Eigen::Index imax = 0;
    theta.cwiseAbs().maxCoeff(&imax);
    const Eigen::VectorXcd s = es.eigenvectors().col(imax);
    const double residual = k_used < K || k_used == D ? 0.0 : H(k_used, k_used - 1) * std::abs(s(k_used - 1)) / s.norm();
    if (residual <= 1e-12 * std::max(std::abs(theta(imax)), 1e-300) || K >= D) return theta(imax);
    K = std::min(D, 2 * K);
  }
}

}  // namespace

SdMonodromy FirstOrderSdMonodromy(int d, int n_u, double period, double delay, int steps,
                                  const SdStepCoefficients& coefficients) {
  if (steps < 1 || d < 1 || n_u < 1 || n_u > d || !(period > 0.0) || !(delay > 0.0)) {
    throw std::invalid_argument("semi-discretization: need steps >= 1, 1 <= n_u <= d, T > 0, tau > 0");
  }
  const double dt = period / steps;
  const int m = static_cast<int>(std::lround(delay / dt));
  if (m < 1) throw std::invalid_argument("semi-discretization: the delay is shorter than half a step");
  const int D = d + m * n_u;

  // The step matrices: y_{i+1} = P_i y_i + R1_i u_{i-m+1} + R0_i u_{i-m},
  // u_j = the first n_u entries of y_j.
  std::vector<Eigen::MatrixXd> P(steps), R1(steps), R0(steps);
  Eigen::MatrixXd A(d, d), B(d, n_u), E(d + 2 * n_u, d + 2 * n_u);
  for (int i = 0; i < steps; ++i) {
    A.setZero();
    B.setZero();
    coefficients(i, i * dt, (i + 1) * dt, &A, &B);
    // Van Loan: with u' = v, v' = 0 appended to y' = A y + B u, the flow
    // over Δt, exp([[A, B, 0], [0, 0, I], [0, 0, 0]] Δt), has the blocks
    // (1,1) = e^{AΔt}, (1,2) = Γ0 B (from u = I, v = 0) and (1,3) = Γ1 B
    // (from u = 0, v = I: u grows as s). Of size d + 2 n_u, not the 3d of
    // Γ0 and Γ1 themselves: (24/36)³ of the work for six modes.
    E.setZero();
    E.topLeftCorner(d, d) = A * dt;
    E.block(0, d, d, n_u) = B * dt;
    E.block(d, d + n_u, n_u, n_u) = Eigen::MatrixXd::Identity(n_u, n_u) * dt;
    const Eigen::MatrixXd X = E.exp();
    P[i] = X.topLeftCorner(d, d);
    const Eigen::MatrixXd G1B = X.block(0, d + n_u, d, n_u) / dt;
    R1[i] = G1B;                               // weight of u_{i-m+1}
    R0[i] = X.block(0, d, d, n_u) - G1B;       // weight of u_{i-m}
  }
  // Φ z for z = [y_0; u_{-1}; ...; u_{-m}]: the k steps, the delay line as
  // one array U of u_j, j = -m .. k-1 (U.col(j + m)); Φ z = [y_k; u_{k-1};
  // ...; u_{k-m}]. O(k d (d + n_u)) per product, against O(k d² D) to form
  // Φ and O(D³) for its dense eigenvalues (issue #34: the SD of a tap test
  // took 30 s in those, at D = 396).
  Eigen::MatrixXd U(n_u, m + steps);
  Eigen::VectorXd y(d), y_next(d);
  auto apply = [&](const Eigen::Ref<const Eigen::VectorXd>& z, Eigen::VectorXd* out) {
    y = z.head(d);
    for (int l = 1; l <= m; ++l) U.col(m - l) = z.segment(d + (l - 1) * n_u, n_u);
    for (int i = 0; i < steps; ++i) {
      U.col(m + i) = y.head(n_u);
      y_next.noalias() = P[i] * y;
      y_next.noalias() += R1[i] * U.col(i + 1);  // u_{i-m+1}
      y_next.noalias() += R0[i] * U.col(i);      // u_{i-m}
      y.swap(y_next);
    }
    out->head(d) = y;
    for (int l = 1; l <= m; ++l) out->segment(d + (l - 1) * n_u, n_u) = U.col(m + steps - l);
  };
  SdMonodromy out;
  out.dimension = D;
  out.critical_multiplier = DominantEigenvalue(D, d, apply);
  out.spectral_radius = std::abs(out.critical_multiplier);
  return out;
}

SdMonodromy MillingMonodromy(const TipModalModel& modes_C, const MillingProcess& process,
                             double spindle_speed_rad_s, double depth, int steps) {
  const int n = modes_C.num_modes();
  const double tau = 2.0 * kPi / (process.teeth * spindle_speed_rad_s);
  const Eigen::MatrixXd P = modes_C.p.topRows(2);  // 2 × n, in-plane shapes
  const Eigen::VectorXd w2 = modes_C.omega_rad_s.array().square();
  const Eigen::VectorXd c = 2.0 * modes_C.zeta.array() * modes_C.omega_rad_s.array();
  auto coeff = [&](int, double t0, double t1, Eigen::MatrixXd* A, Eigen::MatrixXd* B) {
    const Eigen::Matrix2d Hbar =
        MeanDirectionalMatrix(process, spindle_speed_rad_s * t0, spindle_speed_rad_s * t1)
            .topRows<2>();
    const Eigen::MatrixXd W = depth * P.transpose() * Hbar * P;
    A->topRightCorner(n, n).setIdentity();
    A->bottomLeftCorner(n, n) = -W;
    A->bottomLeftCorner(n, n).diagonal() -= w2;
    A->bottomRightCorner(n, n).diagonal() = -c;
    B->bottomRows(n) = W;
  };
  return FirstOrderSdMonodromy(2 * n, n, tau, tau, steps, coeff);
}

namespace {

double ChatterFrequencyHz(const TipModalModel& m, std::complex<double> mu, double tau) {
  const double arg = std::abs(std::arg(mu));  // in [0, π]
  const double f_max = 3.0 * RadPerSecToHz(m.omega_rad_s.maxCoeff()) + 2.0 / tau;
  double best = NAN, best_dist = INFINITY;
  for (int j = 0;; ++j) {
    bool any = false;
    for (double sgn : {1.0, -1.0}) {
      const double f = (sgn * arg + 2.0 * kPi * j) / (2.0 * kPi * tau);
      if (f <= 0.0 || f > f_max) continue;
      any = true;
      for (int k = 0; k < m.num_modes(); ++k) {
        const double dist = std::abs(f - RadPerSecToHz(m.omega_rad_s(k)));
        if (dist < best_dist) {
          best_dist = dist;
          best = f;
        }
      }
    }
    if (!any && j > 0) break;
  }
  return best;
}

}  // namespace

void SdOptions::Validate() const {
  CheckOptionAtLeast("steps_per_period", steps_per_period, 0);
  CheckOptionFinite("steps_per_mode_period", steps_per_mode_period);
  CheckOptionAbove("steps_per_mode_period", steps_per_mode_period, 0.0);
  CheckOptionAtLeast("min_steps_per_period", min_steps_per_period, 1);
  CheckOptionAtLeast("max_monodromy_dimension", max_monodromy_dimension, 1);
  CheckOptionFinite("max_depth", max_depth);
  CheckOptionAbove("max_depth", max_depth, 0.0);
  CheckOptionAtLeast("depth_scan_points", depth_scan_points, 1);
  CheckOptionFinite("depth_tolerance", depth_tolerance);
  CheckOptionAbove("depth_tolerance", depth_tolerance, 0.0);
}

int SdStepsPerPeriod(const TipModalModel& modes_C, const MillingProcess& process, double spindle_speed_rad_s,
                     const SdOptions& options, bool* capped) {
  if (capped) *capped = false;
  options.Validate();
  if (options.steps_per_period > 0) return options.steps_per_period;
  if (!(spindle_speed_rad_s > 0.0) || process.teeth < 1) {
    throw std::invalid_argument("SD steps: need a spindle speed > 0 and at least one tooth");
  }
  const double tau = 2.0 * kPi / (process.teeth * spindle_speed_rad_s);
  const double f_max = modes_C.num_modes() > 0 ? RadPerSecToHz(modes_C.omega_rad_s.maxCoeff()) : 0.0;
  const int n = std::max(1, modes_C.num_modes());
  const int k_max = (options.max_monodromy_dimension - 2 * n) / n;
  const double want = std::ceil(options.steps_per_mode_period * f_max * tau);
  int k = want < 1e6 ? static_cast<int>(want) : 1000000;
  if (k > k_max) {
    k = k_max;
    if (capped) *capped = true;
  }
  return std::max(options.min_steps_per_period, k);
}

LobePoint SdCriticalDepth(const TipModalModel& modes_C, const MillingProcess& process,
                          double spindle_speed_rad_s, const SdOptions& options) {
  process.Validate();
  modes_C.Validate();
  options.Validate();
  if (!(spindle_speed_rad_s > 0.0)) throw std::invalid_argument("SD critical depth: need a speed > 0");
  LobePoint out;
  out.spindle_speed_rad_s = spindle_speed_rad_s;
  const double tau = 2.0 * kPi / (process.teeth * spindle_speed_rad_s);
  const int steps = SdStepsPerPeriod(modes_C, process, spindle_speed_rad_s, options);
  out.sd_steps = steps;
  auto rho = [&](double a) { return MillingMonodromy(modes_C, process, spindle_speed_rad_s, a, steps); };
  const SdMonodromy zero = rho(0.0);
  if (zero.spectral_radius >= 1.0) {
    out.status = LobeStatus::kUnstableAtZero;
    return out;
  }
  double lo = 0.0, hi = NAN, rho_lo = zero.spectral_radius;
  SdMonodromy at_hi;
  for (int j = 1; j <= options.depth_scan_points; ++j) {
    const double a = options.max_depth * j / options.depth_scan_points;
    const SdMonodromy r = rho(a);
    if (r.spectral_radius >= 1.0) {
      hi = a;
      at_hi = r;
      break;
    }
    lo = a;
    rho_lo = r.spectral_radius;
  }
  if (!std::isfinite(hi)) {
    out.status = LobeStatus::kStableUpToMax;
    out.critical_depth = options.max_depth;
    return out;
  }
  // Shrink the bracket [lo, hi] of ρ(a) = 1 by the Illinois variant of
  // regula falsi on g(a) = ρ(a) − 1 (the retained end's g is halved when
  // the same end is kept twice), which needs about half the monodromy
  // evaluations of bisection for the same final width; the new point is
  // kept a quarter of the tolerance inside the bracket, so that the bracket
  // closes once the estimate has converged. ρ(a) is only piecewise smooth
  // (the critical multiplier can switch): if three steps have not halved
  // the bracket, the next step is a bisection. Either way the result is a
  // bracket of relative width depth_tolerance with ρ(lo) < 1 <= ρ(hi).
  double g_lo = rho_lo - 1.0, g_hi = at_hi.spectral_radius - 1.0;
  int last_moved = 0;  // +1 hi, −1 lo
  int steps_in_window = 0;
  double window_width = hi - lo;
  bool bisect = false;
  while (hi - lo > options.depth_tolerance * hi) {
    const double w = hi - lo, eps = 0.25 * options.depth_tolerance * hi;
    double x = 0.5 * (lo + hi);
    if (!bisect) x = std::clamp(lo - g_lo * w / (g_hi - g_lo), lo + eps, hi - eps);
    const SdMonodromy r = rho(x);
    const double g = r.spectral_radius - 1.0;
    if (g >= 0.0) {
      hi = x;
      g_hi = g;
      at_hi = r;
      if (last_moved == +1) g_lo *= 0.5;
      last_moved = +1;
    } else {
      lo = x;
      g_lo = g;
      if (last_moved == -1) g_hi *= 0.5;
      last_moved = -1;
    }
    bisect = false;
    if (++steps_in_window == 3) {
      bisect = hi - lo > 0.5 * window_width;
      steps_in_window = 0;
      window_width = hi - lo;
    }
  }
  out.critical_depth = 0.5 * (lo + hi);
  out.chatter_freq_hz = ChatterFrequencyHz(modes_C, at_hi.critical_multiplier, tau);
  // The lobe index of the chatter frequency: f τ = k + fraction.
  out.lobe_index = static_cast<int>(std::floor(out.chatter_freq_hz * tau));
  out.status = LobeStatus::kOk;
  return out;
}

std::vector<LobePoint> SdLobes(const TipModalModel& modes_C, const MillingProcess& process,
                               const Eigen::VectorXd& speeds, const SdOptions& options, int threads,
                               const ProgressCallback& progress) {
  process.Validate();
  modes_C.Validate();
  options.Validate();  // before the threads: SdCriticalDepth's check would throw from each
  const long n = speeds.size();
  std::vector<LobePoint> out(n);
  ParallelForOptions po;
  po.threads = std::max(0, threads);  // <= 0: all cores, as documented
  po.chunk_size = 1;                  // one speed is a whole depth search (milliseconds)
  po.progress = progress;
  ParallelFor(0, n, [&](long i, int) { out[i] = SdCriticalDepth(modes_C, process, speeds(i), options); }, po);
  return out;
}

}  // namespace robomach::stability
