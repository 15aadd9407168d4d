#include "robomach/calibration/modal_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "robomach/common/errors.h"
#include "robomach/common/golden_section.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "internal/lscf_poles.h"

namespace robomach::calibration {
namespace {

using cd = std::complex<double>;

using internal::Reciprocal;

// |H|² at a fractional position between lines i and i+1 crossing `level`.
double CrossingFreq(const Eigen::VectorXd& f, const Eigen::VectorXd& p2, int i, int j, double level) {
  // p2(i) >= level > p2(j) or the reverse; linear interpolation in |H|².
  const double t = (level - p2(i)) / (p2(j) - p2(i));
  return f(i) + t * (f(j) - f(i));
}

// |H| of the data at the line nearest to f.
double LocalLevel(const dynamics::Frf& frf, double f_hz) {
  const Eigen::VectorXd& f = frf.freq_hz();
  const auto it = std::lower_bound(f.data(), f.data() + f.size(), f_hz);
  int i = static_cast<int>(it - f.data());
  if (i >= f.size()) i = static_cast<int>(f.size()) - 1;
  if (i > 0 && std::abs(f(i - 1) - f_hz) < std::abs(f(i) - f_hz)) --i;
  return std::abs(frf.receptance()(i));
}

}  // namespace

Eigen::VectorXd ModalFitWeights(const dynamics::Frf& frf) {
  Eigen::VectorXd w(frf.size());
  for (int k = 0; k < frf.size(); ++k) {
    if (frf.noise_sigma()) {
      w(k) = 1.0 / (*frf.noise_sigma())(k);
    } else {
      const double a = std::abs(frf.receptance()(k));
      w(k) = a > 0.0 ? 1.0 / a : 0.0;
    }
  }
  return w;
}

void PeakPickOptions::Validate() const {
  CheckOptionRange("min_relative_height", min_relative_height, 0.0, 1.0);
  CheckOptionAtLeast("half_window_lines", half_window_lines, 1);
}

void ModalFitOptions::Validate() const {
  CheckOptionBand("fmin_hz", fmin_hz, "fmax_hz", fmax_hz);
  CheckOptionAtLeast("min_order", min_order, 1);
  if (max_order < min_order) {
    throw OptionError("max_order", "max_order: expected a value >= min_order " + std::to_string(min_order) +
                                       ", got " + std::to_string(max_order));
  }
  CheckOptionAbove("stable_freq_tol", stable_freq_tol, 0.0);
  CheckOptionAbove("stable_damping_tol", stable_damping_tol, 0.0);
  CheckOptionAtLeast("min_stable_orders", min_stable_orders, 1);
  CheckOptionAbove("max_damping_ratio", max_damping_ratio, 0.0);
  CheckOptionRange("max_damping_ratio", max_damping_ratio, 0.0, 1.0);
  CheckOptionAtLeast("min_relative_contribution", min_relative_contribution, 0.0);
  CheckOptionAtLeast("max_added_modes", max_added_modes, 0);
}

std::vector<PeakEstimate> PickPeaks(const dynamics::Frf& frf, const PeakPickOptions& options) {
  options.Validate();
  const Eigen::VectorXd& f = frf.freq_hz();
  const Eigen::VectorXd mag = frf.receptance().cwiseAbs();
  const Eigen::VectorXd p2 = mag.cwiseAbs2();
  const int n = frf.size();
  std::vector<PeakEstimate> out;
  if (n < 3) return out;
  const double floor = options.min_relative_height * mag.maxCoeff();
  const int w = std::max(1, options.half_window_lines);
  for (int i = 1; i + 1 < n; ++i) {
    if (mag(i) < floor) continue;
    bool is_max = true;
    for (int j = std::max(0, i - w); j <= std::min(n - 1, i + w) && is_max; ++j) {
      if (j < i && mag(j) >= mag(i)) is_max = false;
      if (j > i && mag(j) > mag(i)) is_max = false;
    }
    if (!is_max) continue;
    PeakEstimate e;
    e.peak_magnitude = mag(i);
    // Parabolic interpolation of |H| through three lines (even spacing assumed
    // locally; on an uneven grid the vertex of the parabola through the three
    // points is used).
    {
      const double x0 = f(i - 1), x1 = f(i), x2 = f(i + 1);
      const double y0 = mag(i - 1), y1 = mag(i), y2 = mag(i + 1);
      const double den = (x0 - x1) * (x0 - x2) * (x1 - x2);
      const double A = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den;
      const double B = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / den;
      e.peak_freq_hz = A < 0.0 ? std::clamp(-B / (2 * A), x0, x2) : x1;
    }
    const double level = 0.5 * p2(i);
    double f1 = NAN, f2 = NAN;
    for (int j = i; j > 0; --j) {
      if (p2(j - 1) < level) {
        f1 = CrossingFreq(f, p2, j, j - 1, level);
        break;
      }
    }
    for (int j = i; j + 1 < n; ++j) {
      if (p2(j + 1) < level) {
        f2 = CrossingFreq(f, p2, j, j + 1, level);
        break;
      }
    }
    if (std::isfinite(f1) && std::isfinite(f2)) {
      e.damping_ratio = (f2 - f1) / (2.0 * e.peak_freq_hz);
      e.two_sided = true;
    } else if (std::isfinite(f1)) {
      e.damping_ratio = (e.peak_freq_hz - f1) / e.peak_freq_hz;
    } else if (std::isfinite(f2)) {
      e.damping_ratio = (f2 - e.peak_freq_hz) / e.peak_freq_hz;
    }
    out.push_back(e);
  }
  return out;
}

std::complex<double> ModalFitResult::Evaluate(double freq_hz) const {
  const cd s(0.0, HzToRadPerSec(freq_hz));
  cd h = upper_residual;
  if (lower_residual != cd(0.0) && freq_hz > 0.0) h += lower_residual / (s * s);
  if (upper_residual_slope != cd(0.0)) h += upper_residual_slope * (s * s);
  for (const FittedMode& m : modes) {
    h += m.residue * Reciprocal(s - m.pole) + std::conj(m.residue) * Reciprocal(s - std::conj(m.pole));
  }
  return h;
}

std::pair<double, double> ModalFitResult::PeakIn(double f_lo, double f_hi) const {
  // A 200-point grid, then golden-section refinement within one grid cell
  // on each side of its best point.
  return MaximiseOnGrid([&](double f) { return std::abs(Evaluate(f)); }, f_lo, f_hi, 200, 60, 1e-12);
}

void FitResidues(const dynamics::Frf& frf, const std::vector<std::complex<double>>& poles,
                 bool lower_residual, ModalFitResult* result) {
  const int n = frf.size();
  const int nm = static_cast<int>(poles.size());
  const int nc = 2 * nm + 2 + (lower_residual ? 2 : 0);
  Eigen::MatrixXd A(2 * n, nc);
  Eigen::VectorXd b(2 * n);
  const Eigen::VectorXd weights = ModalFitWeights(frf);
  for (int k = 0; k < n; ++k) {
    const cd s(0.0, HzToRadPerSec(frf.freq_hz()(k)));
    const cd h = frf.receptance()(k);
    const double w = weights(k);
    auto put = [&](int col, cd v) {
      A(2 * k, col) = w * v.real();
      A(2 * k + 1, col) = w * v.imag();
    };
    for (int r = 0; r < nm; ++r) {
      const cd p = Reciprocal(s - poles[r]), q = Reciprocal(s - std::conj(poles[r]));
      put(2 * r, p + q);                        // Re R
      put(2 * r + 1, cd(0, 1) * p - cd(0, 1) * q);  // Im R
    }
    put(2 * nm, 1.0);
    put(2 * nm + 1, cd(0, 1));
    if (lower_residual) {
      const cd inv = s != cd(0.0) ? 1.0 / (s * s) : cd(0.0);
      put(2 * nm + 2, inv);
      put(2 * nm + 3, cd(0, 1) * inv);
    }
    b(2 * k) = w * h.real();
    b(2 * k + 1) = w * h.imag();
  }
  // Column scaling keeps the least-squares problem well conditioned (the
  // pole columns are ~1/(ζω) and the constant ~1).
  Eigen::VectorXd scale(nc);
  for (int c = 0; c < nc; ++c) {
    scale(c) = A.col(c).norm();
    if (scale(c) > 0.0) A.col(c) /= scale(c);
    else scale(c) = 1.0;
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(b).cwiseQuotient(scale);
  result->modes.clear();
  for (int r = 0; r < nm; ++r) {
    FittedMode m;
    m.pole = poles[r];
    m.freq_hz = RadPerSecToHz(std::abs(poles[r]));
    m.damping_ratio = -poles[r].real() / std::abs(poles[r]);
    m.residue = cd(x(2 * r), x(2 * r + 1));
    m.modal_constant = cd(0.0, 2.0 * poles[r].imag()) * m.residue;
    const double wn = std::abs(poles[r]);
    m.peak_contribution = std::abs(m.modal_constant) / (2.0 * m.damping_ratio * wn * wn);
    result->modes.push_back(m);
  }
  result->upper_residual = cd(x(2 * nm), x(2 * nm + 1));
  result->lower_residual = lower_residual ? cd(x(2 * nm + 2), x(2 * nm + 3)) : cd(0.0);
  double num = 0.0, den = 0.0;
  for (int k = 0; k < n; ++k) {
    num += std::norm(result->Evaluate(frf.freq_hz()(k)) - frf.receptance()(k));
    den += std::norm(frf.receptance()(k));
  }
  result->relative_rms_error = den > 0.0 ? std::sqrt(num / den) : NAN;
}

namespace {

// Weighted nonlinear least squares of poles, residues and residual terms
// together (Levenberg–Marquardt with the analytic Jacobian), starting from
// the LSCF/LSFD estimate: minimises Σ |(H_fit(ω) − H(ω)) / |H(ω)||², the
// maximum-likelihood criterion for complex noise proportional to |H|. This
// removes the bias of the linearised LSCF equation error.
void RefineAll(const dynamics::Frf& frf, bool lower, ModalFitResult* res) {
  const int N = frf.size();
  const int nm = static_cast<int>(res->modes.size());
  const int np = 4 * nm + 2 + (lower ? 2 : 0);
  Eigen::VectorXd th(np);
  for (int r = 0; r < nm; ++r) {
    th(4 * r) = res->modes[r].pole.real();
    th(4 * r + 1) = res->modes[r].pole.imag();
    th(4 * r + 2) = res->modes[r].residue.real();
    th(4 * r + 3) = res->modes[r].residue.imag();
  }
  th(4 * nm) = res->upper_residual.real();
  th(4 * nm + 1) = res->upper_residual.imag();
  if (lower) {
    th(4 * nm + 2) = res->lower_residual.real();
    th(4 * nm + 3) = res->lower_residual.imag();
  }
  std::vector<cd> sk(N);
  const Eigen::VectorXd wk = ModalFitWeights(frf);
  for (int k = 0; k < N; ++k) sk[k] = cd(0.0, HzToRadPerSec(frf.freq_hz()(k)));
  auto residual = [&](const Eigen::VectorXd& t, Eigen::VectorXd* e, Eigen::MatrixXd* J) {
    e->resize(2 * N);
    if (J) J->setZero(2 * N, np);
    for (int k = 0; k < N; ++k) {
      const cd s = sk[k];
      cd h(t(4 * nm), t(4 * nm + 1));
      cd inv2 = 0.0;
      if (lower && s != cd(0.0)) {
        inv2 = 1.0 / (s * s);
        h += cd(t(4 * nm + 2), t(4 * nm + 3)) * inv2;
      }
      for (int r = 0; r < nm; ++r) {
        const cd lam(t(4 * r), t(4 * r + 1)), R(t(4 * r + 2), t(4 * r + 3));
        const cd p = Reciprocal(s - lam), q = Reciprocal(s - std::conj(lam));
        h += R * p + std::conj(R) * q;
        if (J) {
          const cd d_sigma = R * p * p + std::conj(R) * q * q;
          const cd d_omega = cd(0, 1) * (R * p * p - std::conj(R) * q * q);
          const cd d_re = p + q;
          const cd d_im = cd(0, 1) * (p - q);
          const cd d[4] = {d_sigma, d_omega, d_re, d_im};
          for (int c = 0; c < 4; ++c) {
            (*J)(2 * k, 4 * r + c) = wk(k) * d[c].real();
            (*J)(2 * k + 1, 4 * r + c) = wk(k) * d[c].imag();
          }
        }
      }
      if (J) {
        (*J)(2 * k, 4 * nm) = wk(k);
        (*J)(2 * k + 1, 4 * nm + 1) = wk(k);
        if (lower) {
          (*J)(2 * k, 4 * nm + 2) = wk(k) * inv2.real();
          (*J)(2 * k + 1, 4 * nm + 2) = wk(k) * inv2.imag();
          (*J)(2 * k, 4 * nm + 3) = -wk(k) * inv2.imag();
          (*J)(2 * k + 1, 4 * nm + 3) = wk(k) * inv2.real();
        }
      }
      const cd e_k = wk(k) * (h - frf.receptance()(k));
      (*e)(2 * k) = e_k.real();
      (*e)(2 * k + 1) = e_k.imag();
    }
  };
  Eigen::VectorXd e, e_new;
  Eigen::MatrixXd J;
  residual(th, &e, &J);
  double cost = e.squaredNorm();
  double mu = 1e-3;
  for (int it = 0; it < 100; ++it) {
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * e;
    bool improved = false;
    for (int tries = 0; tries < 12; ++tries) {
      Eigen::MatrixXd A = JtJ;
      A.diagonal() += mu * JtJ.diagonal().cwiseMax(1e-300);
      const Eigen::VectorXd step = A.ldlt().solve(-g);
      if (!step.allFinite()) {
        mu *= 10.0;
        continue;
      }
      Eigen::VectorXd t2 = th + step;
      residual(t2, &e_new, nullptr);
      const double c2 = e_new.squaredNorm();
      if (c2 < cost) {
        const double rel = (cost - c2) / cost;
        th = t2;
        cost = c2;
        mu = std::max(mu / 10.0, 1e-12);
        improved = true;
        if (rel < 1e-10) it = 1000;
        break;
      }
      mu *= 10.0;
    }
    if (!improved) break;
    residual(th, &e, &J);
  }
  for (int r = 0; r < nm; ++r) {
    FittedMode& m = res->modes[r];
    m.pole = cd(th(4 * r), th(4 * r + 1));
    m.residue = cd(th(4 * r + 2), th(4 * r + 3));
    const double wn = std::abs(m.pole);
    m.freq_hz = RadPerSecToHz(wn);
    m.damping_ratio = -m.pole.real() / wn;
    m.modal_constant = cd(0.0, 2.0 * m.pole.imag()) * m.residue;
    m.peak_contribution = std::abs(m.modal_constant) / (2.0 * m.damping_ratio * wn * wn);
  }
  res->upper_residual = cd(th(4 * nm), th(4 * nm + 1));
  res->lower_residual = lower ? cd(th(4 * nm + 2), th(4 * nm + 3)) : cd(0.0);
  double num = 0.0, den = 0.0;
  for (int k = 0; k < N; ++k) {
    num += std::norm(res->Evaluate(frf.freq_hz()(k)) - frf.receptance()(k));
    den += std::norm(frf.receptance()(k));
  }
  res->relative_rms_error = den > 0.0 ? std::sqrt(num / den) : NAN;
}

// One pole of one LSCF order as the pole selection needs it: its λ and how
// many consecutive orders it has been stable over.
struct OrderPole {
  double f_hz, zeta;
  cd lambda;
  int chain;  // consecutive stable orders ending here
};

// The Toeplitz sequences of the LSCF normal equations, formed once for the
// highest order so that every lower order uses their leading blocks.
struct LscfSums {
  int nmax;
  std::vector<cd> r, s, t;
  double R(int j, int l) const { return r[l - j + nmax].real(); }
  double S(int j, int l) const { return -s[l - j + nmax].real(); }
  double T(int j, int l) const { return t[l - j + nmax].real(); }
  // Note S is not symmetric: S_jl = −Re Σ W² conj(Ω_j) H Ω_l, which depends
  // on l − j only through the sign of the exponent (conj(Ω_j) Ω_l).
};

// Stage 1 of FitModes: the sums of the band's lines, in O(N max_order).
LscfSums ToeplitzSums(const dynamics::Frf& frf, int nmax, double dt) {
  const int N = frf.size();
  // Toeplitz sequences r_m, s_m, t_m for m = -nmax..nmax (index m + nmax):
  //   R_jl = Re Σ W² e^{iωΔt(l−j)}, S_jl = −Re Σ W² H e^{iωΔt(l−j)},
  //   T_jl = Re Σ W² |H|² e^{iωΔt(l−j)}.
  // The pole estimate is unweighted (W = 1, classical LSCF): with relative
  // weights 1/|H| the linearised equation error of noisy data merged modes
  // 3 % apart in our tests, while W = 1 resolves them; the weighted
  // nonlinear refinement below then removes the linearisation bias.
  const int L = 2 * nmax + 1;
  LscfSums sums{nmax, std::vector<cd>(L, 0.0), std::vector<cd>(L, 0.0), std::vector<cd>(L, 0.0)};
  std::vector<cd>& r = sums.r;
  std::vector<cd>& s = sums.s;
  std::vector<cd>& t = sums.t;
  for (int k = 0; k < N; ++k) {
    const cd h = frf.receptance()(k);
    const double a2 = std::norm(h);
    if (!(a2 > 0.0)) continue;
    const double w2 = 1.0;
    const double th = HzToRadPerSec(frf.freq_hz()(k)) * dt;
    const cd step = std::polar(1.0, th);
    cd e = std::polar(1.0, -th * nmax);
    for (int m = 0; m < L; ++m) {
      r[m] += w2 * e;
      s[m] += w2 * h * e;
      t[m] += w2 * a2 * e;
      e *= step;
      if ((m & 31) == 31) e = std::polar(1.0, th * (m + 1 - nmax));  // limit drift
    }
  }
  return sums;
}

// Stage 2 of FitModes: the poles of every order from min_order to max_order,
// each matched with the nearest pole of the order below to grow its stability
// chain. Every pole also goes into result->stabilisation (the diagram).
std::vector<std::vector<OrderPole>> StabilisationDiagram(const LscfSums& sums, const ModalFitOptions& o, double dt,
                                                         ModalFitResult* result) {
  const int nmax = sums.nmax;
  std::vector<std::vector<OrderPole>> by_order(nmax + 1);
  for (int n = o.min_order; n <= nmax; ++n) {
    const int m = n + 1;
    Eigen::MatrixXd Rm(m, m), Sm(m, m), Tm(m, m);
    for (int j = 0; j < m; ++j) {
      for (int l = 0; l < m; ++l) {
        Rm(j, l) = sums.R(j, l);
        Sm(j, l) = sums.S(j, l);
        Tm(j, l) = sums.T(j, l);
      }
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(Rm);
    if (ldlt.info() != Eigen::Success) continue;
    const Eigen::MatrixXd M = Tm - Sm.transpose() * ldlt.solve(Sm);
    for (const internal::LscfPole& pole :
         internal::PolesOfOrder(M, n, dt, o.max_damping_ratio, result->fmin_hz, result->fmax_hz)) {
      const double f_hz = pole.f_hz, zeta = pole.zeta;
      OrderPole p{pole.f_hz, pole.zeta, pole.lambda, 1};
      bool stable = false;
      if (n > o.min_order) {
        const OrderPole* best = nullptr;
        double best_d = 1e300;
        for (const OrderPole& q : by_order[n - 1]) {
          const double df = std::abs(q.f_hz - f_hz) / f_hz;
          const double dz = std::abs(q.zeta - zeta) / zeta;
          if (df < o.stable_freq_tol && dz < o.stable_damping_tol && df < best_d) {
            best = &q;
            best_d = df;
          }
        }
        if (best) {
          stable = true;
          p.chain = best->chain + 1;
        }
      }
      by_order[n].push_back(p);
      result->stabilisation.push_back({n, f_hz, zeta, stable});
    }
  }
  return by_order;
}

// What every candidate pole set is fitted against: the band's lines, the
// options, the band's limits and the weights of the error (formed once).
// Stages 3 to 5 of FitModes all fit pole sets through FitWith.
struct PoleSetFitter {
  const dynamics::Frf& frf;
  const ModalFitOptions& o;
  double fmin_hz, fmax_hz;
  Eigen::VectorXd weights;

  // A lower residual where the band starts above a fifth of the lowest pole.
  bool LowerFor(const std::vector<cd>& poles) const {
    double lowest = 1e300;
    for (const cd& p : poles) lowest = std::min(lowest, RadPerSecToHz(std::abs(p)));
    return fmin_hz > 0.2 * lowest;
  }

  // The poles (and stability chains) of r's modes that are physical,
  // significant and distinct.
  std::pair<std::vector<cd>, std::vector<int>> Prune(const ModalFitResult& r) const {
    std::vector<cd> keep;
    std::vector<int> chain;
    std::vector<const FittedMode*> kept;
    // Strongest first, so that of two unresolvable poles the weaker goes.
    std::vector<const FittedMode*> order;
    for (const FittedMode& m : r.modes) order.push_back(&m);
    std::sort(order.begin(), order.end(), [](const FittedMode* a, const FittedMode* b) {
      return a->peak_contribution > b->peak_contribution;
    });
    for (const FittedMode* mp : order) {
      const FittedMode& m = *mp;
      if (!(m.damping_ratio > 0.0 && m.damping_ratio < o.max_damping_ratio && std::isfinite(m.freq_hz) &&
            m.freq_hz >= fmin_hz && m.freq_hz <= fmax_hz &&
            m.peak_contribution >= o.min_relative_contribution * LocalLevel(frf, m.freq_hz))) {
        continue;
      }
      // Two poles closer than a fifth of the half-power bandwidth are one
      // mode split in two (a degenerate fit), not two resolvable modes.
      bool duplicate = false;
      for (const FittedMode* k : kept) {
        const double zbar = 0.5 * (k->damping_ratio + m.damping_ratio);
        if (std::abs(k->freq_hz - m.freq_hz) < 0.2 * zbar * m.freq_hz) duplicate = true;
      }
      if (duplicate) continue;
      kept.push_back(mp);
      keep.push_back(m.pole);
      chain.push_back(m.stable_orders);
    }
    return std::pair{keep, chain};
  }

  // The squared weighted error of `r` at line k.
  double LineError(const ModalFitResult& r, int k) const {
    return std::norm((r.Evaluate(frf.freq_hz()(k)) - frf.receptance()(k)) * weights(k));
  }

  // LSFD, prune, refine, prune again; returns the squared weighted error.
  // `refine_first`: refine before the first pruning (for a pole added by
  // guess, whose linear residue alone may look negligible).
  double FitWith(std::vector<cd> poles, std::vector<int> chains, ModalFitResult* r, bool refine_first = false) const {
    for (int pass = 0; pass < 4 && !poles.empty(); ++pass) {
      FitResidues(frf, poles, LowerFor(poles), r);
      for (size_t i = 0; i < r->modes.size(); ++i) r->modes[i].stable_orders = chains[i];
      if (pass > 0 || refine_first) RefineAll(frf, LowerFor(poles), r);
      auto [keep, chain] = Prune(*r);
      if (keep.size() == r->modes.size() && (pass > 0 || refine_first)) break;
      poles = keep;
      chains = chain;
      if (pass == 3 && !poles.empty()) {
        FitResidues(frf, poles, LowerFor(poles), r);
        for (size_t i = 0; i < r->modes.size(); ++i) r->modes[i].stable_orders = chains[i];
        RefineAll(frf, LowerFor(poles), r);
      }
    }
    if (poles.empty()) {
      r->modes.clear();
      return 1e300;
    }
    double cost = 0.0;
    for (int k = 0; k < frf.size(); ++k) cost += LineError(*r, k);
    return cost;
  }
};

// The best fit so far (cost 1e300: none), and how it was reached (for the
// message).
struct Selection {
  ModalFitResult fit;
  double cost{1e300};
  bool from_peaks{false};
  int added{0};  // modes added from the residual
};

// Stage 3 of FitModes. Candidate pole sets: the stable poles of each of the
// five highest orders. Each is fitted (LSFD, pruning, refinement) and the one
// with the smallest refined error wins: a close pair may lose its stability
// at one order where noise poles crowd it, and refinement from a poor start
// can end in a local minimum. `base` is the result before any fit.
Selection FitStablePoleSets(const PoleSetFitter& fitter, const std::vector<std::vector<OrderPole>>& by_order,
                            const ModalFitResult& base) {
  const ModalFitOptions& o = fitter.o;
  const int nmax = o.max_order;
  Selection best;
  best.fit = base;
  for (int n = nmax; n >= std::max(o.min_order, nmax - 4); --n) {
    std::vector<cd> poles;
    std::vector<int> chains;
    for (const OrderPole& p : by_order[n]) {
      if (p.chain >= o.min_stable_orders) {
        poles.push_back(p.lambda);
        chains.push_back(p.chain);
      }
    }
    if (poles.empty()) continue;
    ModalFitResult r = base;
    const double cost = fitter.FitWith(poles, chains, &r);
    if (cost < best.cost) {
      best.cost = cost;
      best.fit = r;
      best.fit.order_used = n;
    }
  }
  return best;
}

// Stage 3, when no pole was stable: start from the peaks of |H| instead
// (half-power damping, 2 % where a side does not reach half power), so that
// a clear resonance is never reported as "no mode"; the refinement and the
// pruning still decide whether each is a mode.
void FitFromPeaks(const PoleSetFitter& fitter, const ModalFitResult& base, Selection* best) {
  std::vector<cd> poles;
  std::vector<int> chains;
  // At most as many peaks as the highest LSCF order has modes (the
  // largest): data without physical poles (an active FRF, Im H > 0) have
  // a local maximum every few lines, and refining 48 such poles took
  // 80 s on 2000 lines.
  std::vector<PeakEstimate> peaks = PickPeaks(fitter.frf);
  const size_t max_peaks = static_cast<size_t>(std::max(1, fitter.o.max_order / 2));
  if (peaks.size() > max_peaks) {
    std::sort(peaks.begin(), peaks.end(),
              [](const PeakEstimate& a, const PeakEstimate& b) { return a.peak_magnitude > b.peak_magnitude; });
    peaks.resize(max_peaks);
    std::sort(peaks.begin(), peaks.end(),
              [](const PeakEstimate& a, const PeakEstimate& b) { return a.peak_freq_hz < b.peak_freq_hz; });
  }
  for (const PeakEstimate& p : peaks) {
    const double z = std::isfinite(p.damping_ratio) ? std::clamp(p.damping_ratio, 1e-3, 0.2) : 0.02;
    const double wn = HzToRadPerSec(p.peak_freq_hz) / std::sqrt(std::max(1e-6, 1.0 - 2.0 * z * z));
    poles.push_back(cd(-z * wn, wn * std::sqrt(1.0 - z * z)));
    chains.push_back(0);
  }
  if (!poles.empty()) {
    ModalFitResult r = base;
    const double cost = fitter.FitWith(poles, chains, &r, true);
    if (cost < 1e300) {
      best->fit = r;
      best->cost = cost;
      best->fit.order_used = 0;
      best->from_peaks = true;
    }
  }
}

// The Bayesian information criterion 2N ln(F) + p ln(2N) of a fit with
// squared weighted error c and `modes` modes over n2 = 2N real residuals.
double Bic(double c, size_t modes, int n2) {
  return n2 * std::log(std::max(c, 1e-300)) + (4.0 * modes + 2.0) * std::log(static_cast<double>(n2));
}

// The line where the weighted residual of `fit` is structured (its local
// mean square over ±W lines exceeds 4 times the median, i.e. it is not
// noise), or -1 where it is not.
int StructuredResidualLine(const PoleSetFitter& fitter, const ModalFitResult& fit) {
  const int N = fitter.frf.size();
  Eigen::VectorXd e2(N);
  for (int k = 0; k < N; ++k) e2(k) = fitter.LineError(fit, k);
  const int W = std::max(3, N / 200);
  Eigen::VectorXd local(N);
  Eigen::VectorXd csum(N + 1);
  csum(0) = 0.0;
  for (int k = 0; k < N; ++k) csum(k + 1) = csum(k) + e2(k);
  for (int k = 0; k < N; ++k) {
    const int a = std::max(0, k - W), b = std::min(N, k + W + 1);
    local(k) = (csum(b) - csum(a)) / (b - a);
  }
  std::vector<double> sorted(local.data(), local.data() + N);
  std::nth_element(sorted.begin(), sorted.begin() + N / 2, sorted.end());
  const double median = sorted[N / 2];
  int kmax = 0;
  local.maxCoeff(&kmax);
  if (!(local(kmax) > 4.0 * median)) return -1;
  return kmax;
}

// Stage 4 of FitModes. Residual-driven additions: where the weighted residual
// is structured (its local mean square over ±W lines exceeds 4 times the
// median, i.e. it is not noise), a mode is missing; add a pole there, refit,
// and keep it if the Bayesian information criterion 2N ln(F) + p ln(2N) falls
// (p the number of real parameters, 4 per mode).
void AddModesFromResidual(const PoleSetFitter& fitter, const ModalFitResult& base, Selection* best) {
  const int N2 = 2 * fitter.frf.size();
  for (int attempt = 0; attempt < fitter.o.max_added_modes; ++attempt) {
    const int kmax = StructuredResidualLine(fitter, best->fit);
    if (kmax < 0) break;
    // The missing pole may hide under an existing one (a close pair fitted as
    // one mode), so try it at the residual's peak and at ±2ζ and ±4ζ of it,
    // ζ from the nearest fitted mode; keep the best fit.
    const double f_peak = fitter.frf.freq_hz()(kmax);
    double z0 = 0.03, nearest = 1e300;
    for (const FittedMode& m : best->fit.modes) {
      if (std::abs(m.freq_hz - f_peak) < nearest) {
        nearest = std::abs(m.freq_hz - f_peak);
        z0 = m.damping_ratio;
      }
    }
    ModalFitResult r;
    double cost = 1e300;
    for (double shift : {0.0, -2.0, 2.0, -4.0, 4.0}) {
      const double wn = HzToRadPerSec(f_peak * (1.0 + shift * z0));
      if (!(wn > 0.0)) continue;
      std::vector<cd> poles;
      std::vector<int> chains;
      for (const FittedMode& m : best->fit.modes) {
        poles.push_back(m.pole);
        chains.push_back(m.stable_orders);
      }
      poles.push_back(cd(-z0 * wn, wn * std::sqrt(1 - z0 * z0)));
      chains.push_back(0);
      ModalFitResult trial = base;
      const double c = fitter.FitWith(poles, chains, &trial, true);
      if (trial.modes.size() > best->fit.modes.size() && c < cost) {
        cost = c;
        r = trial;
      }
    }
    if (cost < 1e300 && Bic(cost, r.modes.size(), N2) < Bic(best->cost, best->fit.modes.size(), N2) &&
        r.modes.size() > best->fit.modes.size()) {
      r.order_used = best->fit.order_used;
      best->fit = r;
      best->cost = cost;
      ++best->added;
    } else {
      break;
    }
  }
}

// Stage 5 of FitModes. Backward elimination: drop the weakest mode while that
// lowers the BIC (a pole that only fits noise does not pay for its four
// parameters).
void EliminateWeakModes(const PoleSetFitter& fitter, const ModalFitResult& base, Selection* best) {
  const int N2 = 2 * fitter.frf.size();
  for (int attempt = 0; attempt < 8 && best->fit.modes.size() > 1; ++attempt) {
    const std::vector<FittedMode>& modes = best->fit.modes;
    auto weakest = std::min_element(modes.begin(), modes.end(), [&](const FittedMode& a, const FittedMode& b) {
      return a.peak_contribution / LocalLevel(fitter.frf, a.freq_hz) <
             b.peak_contribution / LocalLevel(fitter.frf, b.freq_hz);
    });
    std::vector<cd> poles;
    std::vector<int> chains;
    for (auto it = modes.begin(); it != modes.end(); ++it) {
      if (it == weakest) continue;
      poles.push_back(it->pole);
      chains.push_back(it->stable_orders);
    }
    ModalFitResult r = base;
    const double cost = fitter.FitWith(poles, chains, &r);
    if (cost < 1e300 && Bic(cost, r.modes.size(), N2) < Bic(best->cost, best->fit.modes.size(), N2)) {
      r.order_used = best->fit.order_used;
      best->fit = r;
      best->cost = cost;
    } else {
      break;
    }
  }
}

}  // namespace

ModalFitResult FitModes(const dynamics::Frf& full, const ModalFitOptions& o) {
  o.Validate();
  ModalFitResult result;
  const dynamics::Frf frf = full.Band(o.fmin_hz, o.fmax_hz);
  const int N = frf.size();
  if (N == 0) {
    result.message = "no frequency lines in the band";
    return result;
  }
  result.fmin_hz = frf.freq_hz()(0);
  result.fmax_hz = frf.freq_hz()(N - 1);
  const int nmax = o.max_order;
  if (o.min_order < 1 || nmax < o.min_order || 2 * (nmax + 1) > N) {
    result.message = "too few lines (" + std::to_string(N) + ") for model order " + std::to_string(nmax);
    return result;
  }
  const double dt = 1.0 / (2.0 * result.fmax_hz);
  const std::vector<std::vector<OrderPole>> by_order = StabilisationDiagram(ToeplitzSums(frf, nmax, dt), o, dt, &result);
  const PoleSetFitter fitter{frf, o, result.fmin_hz, result.fmax_hz, ModalFitWeights(frf)};
  Selection best = FitStablePoleSets(fitter, by_order, result);
  if (best.cost >= 1e300) FitFromPeaks(fitter, result, &best);
  if (best.cost >= 1e300) {
    result.status = SolverStatus::kFailed;
    result.message = "no pole was stable over " + std::to_string(o.min_stable_orders) +
                     " consecutive orders up to " + std::to_string(nmax) +
                     " with a significant residue, and no peak of |H| fitted as a mode";
    return result;
  }
  AddModesFromResidual(fitter, result, &best);
  EliminateWeakModes(fitter, result, &best);
  result = best.fit;
  std::sort(result.modes.begin(), result.modes.end(),
            [](const FittedMode& a, const FittedMode& b) { return a.freq_hz < b.freq_hz; });
  result.status = SolverStatus::kConverged;
  result.message = std::to_string(result.modes.size()) + " modes: " +
                   (best.from_peaks ? std::string("no pole stable over ") + std::to_string(o.min_stable_orders) +
                                          " orders, poles from the peaks of |H|"
                                    : "stable poles of order " + std::to_string(result.order_used)) +
                   ", refined" +
                   (best.added > 0 ? ", " + std::to_string(best.added) + " added from the residual" : "");
  return result;
}

}  // namespace robomach::calibration
