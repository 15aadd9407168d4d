#include "robomach/stability/semi_discretization.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include "robomach/common/parallel.h"
#include "robomach/common/units.h"

namespace robomach::stability {

SdMonodromy FirstOrderSdMonodromy(int d, int n_u, double period, double delay, int steps,
                                  const SdStepCoefficients& coefficients) {
  if (steps < 1 || d < 1 || n_u < 1 || n_u > d || !(period > 0.0) || !(delay > 0.0)) {
    throw std::invalid_argument("semi-discretization: need steps >= 1, 1 <= n_u <= d, T > 0, tau > 0");
  }
  const double dt = period / steps;
  const int m = static_cast<int>(std::lround(delay / dt));
  if (m < 1) throw std::invalid_argument("semi-discretization: the delay is shorter than half a step");
  const int D = d + m * n_u;

  // Z holds the product of the step matrices applied so far, as rows of
  // z = [y (d); u_{i-1}; ...; u_{i-m}] (block l at row d + (l-1) n_u).
  Eigen::MatrixXd Z = Eigen::MatrixXd::Identity(D, D);
  Eigen::MatrixXd A(d, d), B(d, n_u), E(3 * d, 3 * d), top(d, D);
  for (int i = 0; i < steps; ++i) {
    A.setZero();
    B.setZero();
    coefficients(i, i * dt, (i + 1) * dt, &A, &B);
    // Van Loan: exp([[A, I, 0], [0, 0, I], [0, 0, 0]] Δt) has blocks
    // (1,1) = e^{AΔt}, (1,2) = Γ0, (1,3) = Γ1.
    E.setZero();
    E.block(0, 0, d, d) = A * dt;
    E.block(0, d, d, d) = Eigen::MatrixXd::Identity(d, d) * dt;
    E.block(d, 2 * d, d, d) = Eigen::MatrixXd::Identity(d, d) * dt;
    const Eigen::MatrixXd X = E.exp();
    // With u' = v, v' = 0 appended to y' = A y + u, the flow over Δt from
    // (0, I, 0) is Γ0 and from (0, 0, I) is Γ1 (u grows as s).
    const Eigen::MatrixXd P = X.block(0, 0, d, d);
    const Eigen::MatrixXd G0 = X.block(0, d, d, d);
    const Eigen::MatrixXd G1 = X.block(0, 2 * d, d, d);
    const Eigen::MatrixXd R1 = (G1 / dt) * B;        // weight of u_{i-m+1}
    const Eigen::MatrixXd R0 = (G0 - G1 / dt) * B;   // weight of u_{i-m}
    auto u_rows = [&](int l) {  // rows of u_{i-l} in Z, l = 0..m
      return l == 0 ? Z.middleRows(0, n_u) : Z.middleRows(d + (l - 1) * n_u, n_u);
    };
    top.noalias() = P * Z.topRows(d);
    top.noalias() += R1 * u_rows(m - 1);
    top.noalias() += R0 * u_rows(m);
    // Shift the delay line down by one block, then insert u_i and y_{i+1}.
    for (int l = m; l >= 2; --l) Z.middleRows(d + (l - 1) * n_u, n_u) = Z.middleRows(d + (l - 2) * n_u, n_u);
    Z.middleRows(d, n_u) = Z.topRows(n_u);
    Z.topRows(d) = top;
  }
  SdMonodromy out;
  out.dimension = D;
  Eigen::EigenSolver<Eigen::MatrixXd> es(Z, false);
  const Eigen::VectorXcd ev = es.eigenvalues();
  Eigen::Index imax = 0;
  ev.cwiseAbs().maxCoeff(&imax);
  out.critical_multiplier = ev(imax);
  out.spectral_radius = std::abs(ev(imax));
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

int SdStepsPerPeriod(const TipModalModel& modes_C, const MillingProcess& process, double spindle_speed_rad_s,
                     const SdOptions& options, bool* capped) {
  if (capped) *capped = false;
  if (options.steps_per_period > 0) return options.steps_per_period;
  if (!(options.steps_per_mode_period > 0.0) || options.min_steps_per_period < 1 ||
      options.max_monodromy_dimension < 1) {
    throw std::invalid_argument(
        "SD steps: need steps_per_mode_period > 0, min_steps_per_period >= 1 and max_monodromy_dimension >= 1");
  }
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
  if (!(spindle_speed_rad_s > 0.0) || !(options.max_depth > 0.0) || options.depth_scan_points < 1) {
    throw std::invalid_argument("SD critical depth: need a speed > 0, max_depth > 0, scan points >= 1");
  }
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
