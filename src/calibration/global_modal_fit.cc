#include "robomach/calibration/global_modal_fit.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "robomach/common/errors.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "internal/lscf_poles.h"

namespace robomach::calibration {
namespace {

using cd = std::complex<double>;

using internal::Reciprocal;

cd PowerOf(cd s, int p) {
  cd v = 1.0;
  for (int i = 0; i < p; ++i) v *= s;
  return v;
}

// |H| of the data at the line nearest to f.
double LevelAt(const dynamics::Frf& frf, double f_hz) {
  const Eigen::VectorXd& f = frf.freq_hz();
  const auto it = std::lower_bound(f.data(), f.data() + f.size(), f_hz);
  int i = static_cast<int>(it - f.data());
  if (i >= f.size()) i = static_cast<int>(f.size()) - 1;
  if (i > 0 && std::abs(f(i - 1) - f_hz) < std::abs(f(i) - f_hz)) --i;
  return std::abs(frf.receptance()(i));
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  const size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + h, v.end());
  if (v.size() % 2 == 1) return v[h];
  const double hi = v[h];
  std::nth_element(v.begin(), v.begin() + h - 1, v.end());
  return 0.5 * (hi + v[h - 1]);
}

cd PoleFrom(double f_hz, double zeta) {
  const double wn = HzToRadPerSec(f_hz);
  return cd(-zeta * wn, wn * std::sqrt(std::max(0.0, 1.0 - zeta * zeta)));
}

// The power p of iω (0, 1, 2) that makes (iω)^p H flattest: the smallest
// summed variance of ln|(iω)^p H| over the FRFs' nonzero lines.
int FlattestPower(const std::vector<dynamics::Frf>& frfs) {
  int best_p = 0;
  double best_v = 1e300;
  for (int p = 0; p <= 2; ++p) {
    double total = 0.0;
    for (const dynamics::Frf& frf : frfs) {
      double sum = 0.0, sum2 = 0.0;
      int n = 0;
      for (int k = 0; k < frf.size(); ++k) {
        const double a = std::abs(frf.receptance()(k)) * std::pow(HzToRadPerSec(frf.freq_hz()(k)), p);
        if (!(a > 0.0)) continue;
        const double l = std::log(a);
        sum += l;
        sum2 += l * l;
        ++n;
      }
      if (n > 1) total += sum2 / n - (sum / n) * (sum / n);
    }
    if (total < best_v) {
      best_v = total;
      best_p = p;
    }
  }
  return best_p;
}

struct OrderPole {
  double f_hz, zeta;
  cd lambda;
  int order;
  bool stable;
};

// The common-denominator LSCF for orders min..max: the poles of every order
// with their stability flag.
std::vector<std::vector<OrderPole>> LscfPoles(const std::vector<dynamics::Frf>& frfs, int power, int nmin, int nmax,
                                              double fmin_hz, double fmax_hz, const GlobalModalFitOptions& o) {
  const int N = frfs.front().size();
  const double dt = 1.0 / (2.0 * fmax_hz);
  const int L = 2 * nmax + 1;
  const int nf = static_cast<int>(frfs.size());
  std::vector<double> r(L, 0.0);
  std::vector<std::vector<double>> s(nf, std::vector<double>(L, 0.0)), t(nf, std::vector<double>(L, 0.0));
  // Each FRF scaled to unit rms, so that every FRF weighs the same in the
  // stacked equations whatever its level.
  std::vector<double> scale(nf, 1.0);
  std::vector<Eigen::VectorXcd> g(nf);
  for (int o_i = 0; o_i < nf; ++o_i) {
    g[o_i].resize(N);
    double ss = 0.0;
    for (int k = 0; k < N; ++k) {
      const cd sk(0.0, HzToRadPerSec(frfs[o_i].freq_hz()(k)));
      g[o_i](k) = PowerOf(sk, power) * frfs[o_i].receptance()(k);
      ss += std::norm(g[o_i](k));
    }
    scale[o_i] = ss > 0.0 ? 1.0 / std::sqrt(ss / N) : 1.0;
    g[o_i] *= scale[o_i];
  }
  std::vector<cd> e_row(L);
  for (int k = 0; k < N; ++k) {
    const double th = HzToRadPerSec(frfs.front().freq_hz()(k)) * dt;
    const cd step = std::polar(1.0, th);
    cd e = std::polar(1.0, -th * nmax);
    for (int m = 0; m < L; ++m) {
      e_row[m] = e;
      e *= step;
      if ((m & 31) == 31) e = std::polar(1.0, th * (m + 1 - nmax));  // limit drift
    }
    for (int m = 0; m < L; ++m) r[m] += e_row[m].real();
    for (int o_i = 0; o_i < nf; ++o_i) {
      const cd h = g[o_i](k);
      const double a2 = std::norm(h);
      std::vector<double>& so = s[o_i];
      std::vector<double>& to = t[o_i];
      for (int m = 0; m < L; ++m) {
        so[m] += (h * e_row[m]).real();
        to[m] += a2 * e_row[m].real();
      }
    }
  }
  std::vector<std::vector<OrderPole>> by_order(nmax + 1);
  for (int n = nmin; n <= nmax; ++n) {
    const int m = n + 1;
    Eigen::MatrixXd Rm(m, m);
    for (int j = 0; j < m; ++j)
      for (int l = 0; l < m; ++l) Rm(j, l) = r[l - j + nmax];
    const Eigen::LLT<Eigen::MatrixXd> llt(Rm);
    if (llt.info() != Eigen::Success) continue;
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(m, m);
    Eigen::MatrixXd Sm(m, m);
    for (int o_i = 0; o_i < nf; ++o_i) {
      for (int j = 0; j < m; ++j)
        for (int l = 0; l < m; ++l) {
          Sm(j, l) = -s[o_i][l - j + nmax];
          M(j, l) += t[o_i][l - j + nmax];
        }
      // Sᵀ R⁻¹ S = Yᵀ Y with Y = L⁻¹ S.
      const Eigen::MatrixXd Y = llt.matrixL().solve(Sm);
      M.noalias() -= Y.transpose() * Y;
    }
    for (const internal::LscfPole& pole : internal::PolesOfOrder(M, n, dt, o.max_damping_ratio, fmin_hz, fmax_hz)) {
      const double f_hz = pole.f_hz, zeta = pole.zeta;
      OrderPole p{pole.f_hz, pole.zeta, pole.lambda, n, false};
      if (n > nmin) {
        for (const OrderPole& q : by_order[n - 1]) {
          if (std::abs(q.f_hz - f_hz) / f_hz < o.stable_freq_tol &&
              std::abs(q.zeta - zeta) / zeta < o.stable_damping_tol) {
            p.stable = true;
            break;
          }
        }
      }
      by_order[n].push_back(p);
    }
  }
  return by_order;
}

struct Cluster {
  double f_hz, zeta;
  int orders;
};

// Stable poles clustered by frequency across orders; a cluster spanning at
// least `min_orders` distinct orders is a mode.
std::vector<Cluster> ClusterStablePoles(const std::vector<std::vector<OrderPole>>& by_order, int min_orders,
                                        double tol) {
  std::vector<const OrderPole*> stable;
  for (const auto& poles : by_order)
    for (const OrderPole& p : poles)
      if (p.stable) stable.push_back(&p);
  std::sort(stable.begin(), stable.end(), [](const OrderPole* a, const OrderPole* b) { return a->f_hz < b->f_hz; });
  std::vector<Cluster> out;
  size_t i = 0;
  while (i < stable.size()) {
    std::vector<const OrderPole*> members{stable[i]};
    double sum_f = stable[i]->f_hz;
    size_t j = i + 1;
    while (j < stable.size() && std::abs(stable[j]->f_hz - sum_f / members.size()) <= tol * stable[j]->f_hz) {
      members.push_back(stable[j]);
      sum_f += stable[j]->f_hz;
      ++j;
    }
    std::vector<int> orders;
    std::vector<double> fs, zs;
    for (const OrderPole* p : members) {
      orders.push_back(p->order);
      fs.push_back(p->f_hz);
      zs.push_back(p->zeta);
    }
    std::sort(orders.begin(), orders.end());
    const int distinct = static_cast<int>(std::unique(orders.begin(), orders.end()) - orders.begin());
    if (distinct >= min_orders) out.push_back({Median(fs), Median(zs), distinct});
    i = j;
  }
  return out;
}

// The fit of all FRFs for given common poles: residues per FRF by weighted
// linear least squares. Returns the summed squared weighted error.
struct SetFit {
  std::vector<ModalFitResult> per_frf;
  double cost{1e300};
};

class GlobalProblem {
 public:
  // `uniform_power` >= 0: weights |ω|^p / rms|(iω)^p H| (every line of
  // (iω)^p H alike, every FRF alike) instead of ModalFitWeights.
  // `force_lower`: the lower residual on every FRF, whatever the band.
  GlobalProblem(const std::vector<dynamics::Frf>& frfs, double fmin_hz, int uniform_power = -1,
                bool force_lower = false)
      : frfs_(frfs), fmin_hz_(fmin_hz), force_lower_(force_lower) {
    for (const dynamics::Frf& f : frfs_) {
      if (uniform_power < 0) {
        weights_.push_back(ModalFitWeights(f));
        continue;
      }
      Eigen::VectorXd w(f.size());
      double ss = 0.0;
      for (int k = 0; k < f.size(); ++k) {
        w(k) = std::pow(HzToRadPerSec(f.freq_hz()(k)), uniform_power);
        ss += std::norm(w(k) * f.receptance()(k));
      }
      const double rms = std::sqrt(ss / std::max(1, f.size()));
      weights_.push_back(rms > 0.0 ? Eigen::VectorXd(w / rms) : w);
    }
  }

  bool LowerResidual(const std::vector<cd>& poles) const {
    if (force_lower_) return true;
    double lowest = 1e300;
    for (const cd& p : poles) lowest = std::min(lowest, RadPerSecToHz(std::abs(p)));
    return fmin_hz_ > 0.2 * lowest;
  }

  // The weighted LSFD of one FRF for given poles, as FitResidues, keeping
  // what the Jacobian needs: the residues, the weighted residual
  // e = W (H_fit − H) (real, imaginary per line) and an orthonormal basis Q of
  // the weighted design matrix's columns.
  struct Lsfd {
    std::vector<cd> residues;
    cd upper{0.0}, lower{0.0}, slope{0.0};
    Eigen::VectorXd e;
    Eigen::MatrixXd Q;
  };
  Lsfd Solve(size_t o, const std::vector<cd>& poles, bool lower, bool want_q = false) const {
    const dynamics::Frf& frf = frfs_[o];
    const Eigen::VectorXd& w = weights_[o];
    const int n = frf.size();
    const int nm = static_cast<int>(poles.size());
    const int nc = 2 * nm + 4 + (lower ? 2 : 0);
    Eigen::MatrixXd A(2 * n, nc);
    Eigen::VectorXd b(2 * n);
    for (int k = 0; k < n; ++k) {
      const cd s(0.0, HzToRadPerSec(frf.freq_hz()(k)));
      auto put = [&](int col, cd v) {
        A(2 * k, col) = w(k) * v.real();
        A(2 * k + 1, col) = w(k) * v.imag();
      };
      for (int r = 0; r < nm; ++r) {
        const cd p = Reciprocal(s - poles[r]), q = Reciprocal(s - std::conj(poles[r]));
        put(2 * r, p + q);
        put(2 * r + 1, cd(0, 1) * (p - q));
      }
      put(2 * nm, 1.0);
      put(2 * nm + 1, cd(0, 1));
      put(2 * nm + 2, s * s);
      put(2 * nm + 3, cd(0, 1) * s * s);
      if (lower) {
        const cd inv = 1.0 / (s * s);
        put(2 * nm + 4, inv);
        put(2 * nm + 5, cd(0, 1) * inv);
      }
      b(2 * k) = w(k) * frf.receptance()(k).real();
      b(2 * k + 1) = w(k) * frf.receptance()(k).imag();
    }
    Eigen::VectorXd scale(nc);
    for (int c = 0; c < nc; ++c) {
      scale(c) = A.col(c).norm();
      if (scale(c) > 0.0) A.col(c) /= scale(c);
      else scale(c) = 1.0;
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    const Eigen::VectorXd xs = qr.solve(b);
    Lsfd out;
    out.e = A * xs - b;
    if (want_q) out.Q = qr.householderQ() * Eigen::MatrixXd::Identity(2 * n, std::min<int>(qr.rank(), nc));
    const Eigen::VectorXd x = xs.cwiseQuotient(scale);
    for (int r = 0; r < nm; ++r) out.residues.emplace_back(x(2 * r), x(2 * r + 1));
    out.upper = cd(x(2 * nm), x(2 * nm + 1));
    out.slope = cd(x(2 * nm + 2), x(2 * nm + 3));
    if (lower) out.lower = cd(x(2 * nm + 4), x(2 * nm + 5));
    return out;
  }

  // The fit of every FRF for given poles (residues and residual terms by
  // weighted linear least squares).
  SetFit Fit(const std::vector<cd>& poles) const {
    SetFit out;
    out.per_frf.resize(frfs_.size());
    const bool lower = LowerResidual(poles);
    double cost = 0.0;
    for (size_t o = 0; o < frfs_.size(); ++o) {
      const Lsfd sol = Solve(o, poles, lower);
      cost += sol.e.squaredNorm();
      ModalFitResult& r = out.per_frf[o];
      for (size_t k = 0; k < poles.size(); ++k) {
        FittedMode m;
        m.pole = poles[k];
        const double wn = std::abs(poles[k]);
        m.freq_hz = RadPerSecToHz(wn);
        m.damping_ratio = -poles[k].real() / wn;
        m.residue = sol.residues[k];
        m.modal_constant = cd(0.0, 2.0 * poles[k].imag()) * m.residue;
        m.peak_contribution = std::abs(m.modal_constant) / (2.0 * m.damping_ratio * wn * wn);
        r.modes.push_back(m);
      }
      r.upper_residual = sol.upper;
      r.lower_residual = sol.lower;
      r.upper_residual_slope = sol.slope;
      r.relative_rms_error = RelativeMisfit(r, frfs_[o], 0);
    }
    out.cost = std::isfinite(cost) ? cost : 1e300;
    return out;
  }

  // Levenberg–Marquardt on the poles (σ, ω of each), residues eliminated
  // (variable projection with Kaufman's Jacobian: the derivative of the model
  // with the residues held, projected onto the complement of the design
  // matrix's columns).
  // `free_from`: only the poles from this index on move (the others are
  // held), for a trial pole added to a refined set.
  std::vector<cd> Refine(std::vector<cd> poles, int free_from = 0, int max_iterations = 30,
                         double rel_tol = 1e-7) const {
    const int nm = static_cast<int>(poles.size());
    const int np = 2 * (nm - free_from);
    if (np <= 0) return poles;
    const bool lower = LowerResidual(poles);
    int rows = 0;
    for (const dynamics::Frf& f : frfs_) rows += 2 * f.size();
    auto evaluate = [&](const std::vector<cd>& p, Eigen::VectorXd* e, Eigen::MatrixXd* J) {
      e->resize(rows);
      if (J) J->resize(rows, np);
      int row = 0;
      for (size_t o = 0; o < frfs_.size(); ++o) {
        const Lsfd sol = Solve(o, p, lower, J != nullptr);
        const int n2 = static_cast<int>(sol.e.size());
        e->segment(row, n2) = sol.e;
        if (J) {
          const dynamics::Frf& frf = frfs_[o];
          Eigen::MatrixXd V(n2, np);
          for (int k = 0; k < frf.size(); ++k) {
            const cd s(0.0, HzToRadPerSec(frf.freq_hz()(k)));
            const double wk = weights_[o](k);
            for (int r = free_from; r < nm; ++r) {
              const cd R = sol.residues[r];
              const cd pp = Reciprocal(s - p[r]), qq = Reciprocal(s - std::conj(p[r]));
              const cd d_sigma = R * pp * pp + std::conj(R) * qq * qq;
              const cd d_omega = cd(0, 1) * (R * pp * pp - std::conj(R) * qq * qq);
              const int c = 2 * (r - free_from);
              V(2 * k, c) = wk * d_sigma.real();
              V(2 * k + 1, c) = wk * d_sigma.imag();
              V(2 * k, c + 1) = wk * d_omega.real();
              V(2 * k + 1, c + 1) = wk * d_omega.imag();
            }
          }
          J->middleRows(row, n2) = V - sol.Q * (sol.Q.transpose() * V);
        }
        row += n2;
      }
      const double c = e->squaredNorm();
      return std::isfinite(c) ? c : 1e300;
    };
    Eigen::VectorXd e, e2;
    Eigen::MatrixXd J;
    double cost = evaluate(poles, &e, &J);
    if (!(cost < 1e300)) return poles;
    double mu = 1e-3;
    for (int it = 0; it < max_iterations; ++it) {
      const Eigen::MatrixXd JtJ = J.transpose() * J;
      const Eigen::VectorXd grad = J.transpose() * e;
      bool improved = false;
      for (int tries = 0; tries < 10; ++tries) {
        Eigen::MatrixXd A = JtJ;
        A.diagonal() += mu * JtJ.diagonal().cwiseMax(1e-300);
        const Eigen::VectorXd step = A.ldlt().solve(-grad);
        if (!step.allFinite()) {
          mu *= 10.0;
          continue;
        }
        std::vector<cd> trial = poles;
        bool physical = true;
        for (int r = free_from; r < nm; ++r) {
          const int c = 2 * (r - free_from);
          trial[r] = poles[r] + cd(step(c), step(c + 1));
          physical = physical && trial[r].real() < 0.0 && trial[r].imag() > 0.0;
        }
        if (!physical) {
          mu *= 10.0;
          continue;
        }
        const double c2 = evaluate(trial, &e2, nullptr);
        if (c2 < cost) {
          const double rel = (cost - c2) / cost;
          poles = trial;
          cost = c2;
          mu = std::max(mu / 10.0, 1e-12);
          improved = true;
          if (rel < rel_tol) it = 1000;
          break;
        }
        mu *= 10.0;
      }
      if (!improved || it >= 1000) break;
      cost = evaluate(poles, &e, &J);
    }
    return poles;
  }

  const std::vector<dynamics::Frf>& frfs() const { return frfs_; }
  const Eigen::VectorXd& weights(size_t o) const { return weights_[o]; }

 private:
  const std::vector<dynamics::Frf>& frfs_;
  double fmin_hz_;
  std::vector<Eigen::VectorXd> weights_;
  bool force_lower_{false};
};

// A mode's largest peak contribution over the FRFs relative to the measured
// level at its frequency.
double RelativeStrength(const SetFit& fit, const std::vector<dynamics::Frf>& frfs, size_t r) {
  double best = 0.0;
  for (size_t o = 0; o < frfs.size(); ++o) {
    const FittedMode& m = fit.per_frf[o].modes[r];
    const double level = LevelAt(frfs[o], m.freq_hz);
    if (level > 0.0) best = std::max(best, m.peak_contribution / level);
  }
  return best;
}

// τ² with Σ_k |r_k|² / (σ_k² + τ²/ω_k^2p) = ν (0 if the misfit is within ν
// already): the left side falls monotonically with τ².
double ModelErrorVariance(const Eigen::VectorXd& r2, const Eigen::VectorXd& sigma2, const Eigen::VectorXd& w2,
                          double nu) {
  auto chi2 = [&](double t2) { return (r2.array() / (sigma2.array() + t2 / w2.array())).sum(); };
  if (!(chi2(0.0) > nu)) return 0.0;
  double lo = 0.0, hi = (r2.array() * w2.array()).maxCoeff();
  if (!(hi > 0.0)) return 0.0;
  while (chi2(hi) > nu) hi *= 4.0;
  for (int it = 0; it < 100 && hi - lo > 1e-6 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (chi2(mid) > nu ? lo : hi) = mid;
  }
  return hi;
}

// sqrt(mean |H_fit − H|² / σ²) of each FRF, σ the FRFs' own noise model
// (NaN for an FRF without one).
std::vector<double> MisfitInNoise(const std::vector<dynamics::Frf>& frfs, const std::vector<ModalFitResult>& fits) {
  std::vector<double> out;
  for (size_t i = 0; i < frfs.size(); ++i) {
    if (!frfs[i].noise_sigma()) {
      out.push_back(NAN);
      continue;
    }
    double sum = 0.0;
    const int n = frfs[i].size();
    for (int k = 0; k < n; ++k) {
      sum += std::norm((fits[i].Evaluate(frfs[i].freq_hz()(k)) - frfs[i].receptance()(k)) /
                       (*frfs[i].noise_sigma())(k));
    }
    out.push_back(std::sqrt(sum / std::max(1, n)));
  }
  return out;
}

// The model error τ of each FRF (GlobalModalFitOptions::model_error_power)
// about `fit`, 0 for an FRF `needs` says is within the noise.
std::vector<double> ModelErrors(const std::vector<dynamics::Frf>& frfs, const GlobalModalFitResult& fit, int p,
                                const std::vector<char>& needs) {
  std::vector<double> tau(frfs.size(), 0.0);
  for (size_t i = 0; i < frfs.size(); ++i) {
    if (!needs[i]) continue;
    const dynamics::Frf& f = frfs[i];
    const int n = f.size();
    Eigen::VectorXd r2(n), sigma2(n), w2(n);
    for (int k = 0; k < n; ++k) {
      r2(k) = std::norm(fit.per_frf[i].Evaluate(f.freq_hz()(k)) - f.receptance()(k));
      sigma2(k) = std::pow((*f.noise_sigma())(k), 2);
      w2(k) = std::pow(HzToRadPerSec(f.freq_hz()(k)), 2 * p);
    }
    // Degrees of freedom: each mode's complex residue, the residual terms
    // and this FRF's share of the common poles.
    const double modes = static_cast<double>(fit.modes.size());
    const double params = 2.0 * modes + 4.0 + 2.0 * modes / frfs.size() +
                          (fit.per_frf[i].lower_residual != cd(0.0) ? 2.0 : 0.0);
    const double nu = std::max(0.5 * n, n - 0.5 * params);
    const double t = std::sqrt(ModelErrorVariance(r2, sigma2, w2, nu));
    tau[i] = std::isfinite(t) ? t : 0.0;  // a non-finite residual gives no model error
  }
  return tau;
}

// The fit again with σ² + τ²/ω^2p, τ estimated about the previous fit until
// it settles: the noise's weights distort the first fit where τ dominates
// (the lines of small |H|), so the first τ overstates it (1.8-3.8 × a known τ
// that the second pass finds within 2.5 %:
// ModelErrorIsTheErrorTheNoiseModelDidNotKnow).
std::optional<GlobalModalFitResult> RefitWithModelError(const std::vector<dynamics::Frf>& frfs,
                                                        const GlobalModalFitResult& fit,
                                                        const GlobalModalFitOptions& o) {
  std::vector<char> needs(frfs.size(), 0);
  bool any = false;
  for (size_t i = 0; i < frfs.size(); ++i) {
    if (!frfs[i].noise_sigma() || i >= fit.misfit_in_noise.size()) return std::nullopt;
    needs[i] = fit.misfit_in_noise[i] > o.model_error_ratio;
    any = any || needs[i];
  }
  if (!any || fit.per_frf.size() != frfs.size()) return std::nullopt;
  const int p = o.model_error_power;
  GlobalModalFitOptions again = o;
  again.model_error_power = -1;
  std::vector<double> tau = ModelErrors(frfs, fit, p, needs);
  std::optional<GlobalModalFitResult> out;
  bool settled = false;
  for (int pass = 0; pass < 4 && !settled; ++pass) {
    std::vector<dynamics::Frf> weighted;
    for (size_t i = 0; i < frfs.size(); ++i) {
      const dynamics::Frf& f = frfs[i];
      Eigen::VectorXd sigma(f.size());
      for (int k = 0; k < f.size(); ++k) {
        sigma(k) = std::hypot((*f.noise_sigma())(k), tau[i] / std::pow(HzToRadPerSec(f.freq_hz()(k)), p));
      }
      weighted.push_back(f.WithNoise(sigma));
    }
    GlobalModalFitResult next = FitModesGlobal(weighted, again);
    if (next.status != SolverStatus::kConverged) break;
    next.model_error = tau;
    out = std::move(next);
    const std::vector<double> tau_next = ModelErrors(frfs, *out, p, needs);
    settled = true;
    for (size_t i = 0; i < frfs.size(); ++i) settled = settled && std::abs(tau_next[i] - tau[i]) <= 0.05 * tau[i];
    if (!settled) {
      for (size_t i = 0; i < frfs.size(); ++i) {
        // An FRF that needs a τ keeps one (a later pass that finds 0 would
        // return it to the weights that made the misfit).
        if (std::isfinite(tau_next[i]) && (tau_next[i] > 0.0 || !needs[i])) tau[i] = tau_next[i];
      }
    }
  }
  if (!out) return std::nullopt;
  // The misfit in units of the measurement's noise, as without τ.
  out->misfit_in_noise = MisfitInNoise(frfs, out->per_frf);
  out->misfit_in_noise_weights_alone = fit.misfit_in_noise;
  out->model_error_power = p;
  static const char* kQuantity[] = {"receptance", "mobility", "accelerance"};
  std::ostringstream s;
  s.precision(2);
  double worst = 0.0;
  for (double m : fit.misfit_in_noise) worst = std::max(worst, m);
  s << ", weighted with a model error white in the " << kQuantity[std::clamp(p, 0, 2)]
    << " (the noise model explains the misfit only to " << worst << " x the noise"
    << (settled ? "" : "; the model error had not settled to 5 % after 4 refits") << ")";
  out->message += s.str();
  return out;
}

}  // namespace

Eigen::MatrixXd ModalAssuranceCriterion(const Eigen::MatrixXcd& a, const Eigen::MatrixXcd& b) {
  if (a.rows() != b.rows()) {
    throw std::invalid_argument("ModalAssuranceCriterion: the shapes have " + std::to_string(a.rows()) + " and " +
                                std::to_string(b.rows()) + " points; they must have the same points");
  }
  Eigen::MatrixXd mac(a.cols(), b.cols());
  for (int i = 0; i < a.cols(); ++i) {
    for (int j = 0; j < b.cols(); ++j) {
      const double den = a.col(i).squaredNorm() * b.col(j).squaredNorm();
      mac(i, j) = den > 0.0 ? std::norm(a.col(i).dot(b.col(j))) / den : 0.0;
    }
  }
  return mac;
}

double RelativeMisfit(const ModalFitResult& fit, const dynamics::Frf& frf, int power) {
  double num = 0.0, den = 0.0;
  for (int k = 0; k < frf.size(); ++k) {
    const cd s(0.0, HzToRadPerSec(frf.freq_hz()(k)));
    const cd w = PowerOf(s, power);
    num += std::norm(w * (fit.Evaluate(frf.freq_hz()(k)) - frf.receptance()(k)));
    den += std::norm(w * frf.receptance()(k));
  }
  return den > 0.0 ? std::sqrt(num / den) : NAN;
}

Eigen::MatrixXcd GlobalModalFitResult::ModalConstants() const {
  Eigen::MatrixXcd a(per_frf.size(), modes.size());
  for (size_t o = 0; o < per_frf.size(); ++o)
    for (size_t r = 0; r < modes.size(); ++r) a(o, r) = per_frf[o].modes[r].modal_constant;
  return a;
}

Eigen::MatrixXcd GlobalModalFitResult::ModeShapes(int driving_point) const {
  Eigen::MatrixXcd phi = ModalConstants();
  for (int r = 0; r < phi.cols(); ++r) {
    if (driving_point >= 0 && driving_point < phi.rows()) {
      const cd root = std::sqrt(phi(driving_point, r));
      if (std::abs(root) > 0.0) phi.col(r) /= root;
      continue;
    }
    int imax = 0;
    phi.col(r).cwiseAbs().maxCoeff(&imax);
    const cd pivot = phi(imax, r);
    if (std::abs(pivot) > 0.0) phi.col(r) /= pivot;
  }
  return phi;
}

namespace {

// The FRFs cut to the band; throws unless they all have the same lines
// there (a global fit needs common lines).
std::vector<dynamics::Frf> CommonBand(const std::vector<dynamics::Frf>& all, const GlobalModalFitOptions& o) {
  std::vector<dynamics::Frf> frfs;
  // The 0 Hz line carries no pole information and a receptance that a
  // converted accelerance or mobility does not have.
  const double fmin = std::max(o.fmin_hz, 1e-12);
  for (const dynamics::Frf& f : all) frfs.push_back(f.Band(fmin, o.fmax_hz));
  const int N = frfs.front().size();
  for (size_t i = 1; i < frfs.size(); ++i) {
    if (frfs[i].size() != N || (N > 0 && (frfs[i].freq_hz() - frfs.front().freq_hz()).cwiseAbs().maxCoeff() >
                                             1e-9 * frfs.front().freq_hz()(N - 1))) {
      throw std::invalid_argument("FitModesGlobal: FRF " + std::to_string(i + 1) +
                                  " has other frequency lines in the band than FRF 1 (" + std::to_string(frfs[i].size()) +
                                  " vs " + std::to_string(N) + " lines); a global fit needs common lines");
    }
  }
  return frfs;
}

// The stabilisation diagram's outcome: the clusters of stable poles and the
// number of distinct orders a cluster had to span to count.
struct Diagram {
  std::vector<Cluster> clusters;
  int min_orders;
};

// The LSCF poles of orders min_order..nmax (recorded in `result` with the
// orders and the power of iω used) and their clusters of stable poles.
Diagram StabilisationDiagram(const std::vector<dynamics::Frf>& frfs, const GlobalModalFitOptions& o, int nmax,
                             GlobalModalFitResult* result) {
  result->orders_tried = nmax - o.min_order + 1;
  result->min_order = o.min_order;
  result->max_order = nmax;
  result->lscf_power = FlattestPower(frfs);
  const auto by_order = LscfPoles(frfs, result->lscf_power, o.min_order, nmax, result->fmin_hz, result->fmax_hz, o);
  for (const auto& poles : by_order)
    for (const OrderPole& p : poles) result->stabilisation.push_back({p.order, p.f_hz, p.zeta, p.stable});
  const int min_orders = std::max(o.min_stable_orders,
                                  static_cast<int>(std::ceil(o.min_cluster_fraction * result->orders_tried)));
  std::vector<Cluster> clusters = ClusterStablePoles(by_order, min_orders, o.cluster_freq_tol);
  return {clusters, min_orders};
}

// A set of common poles, each with its support (the number of orders its
// cluster spanned, 0 for a pole from a peak or the residual) and the fit of
// every FRF with them.
struct ModeSet {
  std::vector<cd> poles;
  std::vector<int> support;
  SetFit best;
};

// A dense FRF: band by band (GlobalModalFitOptions::max_modes_per_band),
// each band's fit keeping the modes in its core. The poles of all bands
// (empty when the FRF is not dense); result->bands is the number of bands.
ModeSet FitInBands(const std::vector<dynamics::Frf>& all, const GlobalModalFitOptions& o,
                   const std::vector<Cluster>& clusters, GlobalModalFitResult* result) {
  ModeSet out;
  std::vector<cd>& band_poles = out.poles;
  std::vector<int>& band_support = out.support;
  if (o.max_modes_per_band > 0 && static_cast<int>(clusters.size()) > std::max(o.dense_modes, o.max_modes_per_band)) {
    std::vector<double> fc;
    for (const Cluster& c : clusters) fc.push_back(c.f_hz);
    std::sort(fc.begin(), fc.end());
    const int n = static_cast<int>(fc.size());
    const int groups = (n + o.max_modes_per_band - 1) / o.max_modes_per_band;
    const int per = (n + groups - 1) / groups;
    std::vector<int> first;  // index of each group's first cluster
    for (int g = 0; g < groups; ++g) first.push_back(g * per);
    first.push_back(n);
    GlobalModalFitOptions sub = o;
    sub.max_modes_per_band = 0;
    sub.driving_point = -1;
    sub.model_error_power = -1;  // τ is estimated once, about the whole band's fit
    for (int g = 0; g < groups && first[g] < n; ++g) {
      const int a = first[g], b = std::min(n, first[g + 1]) - 1;  // this group's clusters
      // Core: from the gap below to the gap above (geometric means); band:
      // widened to take in the neighbour mode on each side with its flanks.
      const double core_lo = a == 0 ? result->fmin_hz : std::sqrt(fc[a - 1] * fc[a]);
      const double core_hi = b == n - 1 ? result->fmax_hz : std::sqrt(fc[b] * fc[b + 1]);
      sub.fmin_hz = a == 0 ? result->fmin_hz : std::max(result->fmin_hz, 0.97 * fc[a - 1]);
      sub.fmax_hz = b == n - 1 ? result->fmax_hz : std::min(result->fmax_hz, 1.03 * fc[b + 1]);
      const GlobalModalFitResult part = FitModesGlobal(all, sub);
      if (part.status != SolverStatus::kConverged) continue;
      for (const GlobalMode& m : part.modes) {
        const bool in_core = m.freq_hz >= core_lo && (m.freq_hz < core_hi || (g == groups - 1 && m.freq_hz <= core_hi));
        if (!in_core) continue;
        band_poles.push_back(m.pole);
        band_support.push_back(m.stable_orders);
      }
    }
    result->bands = groups;
  }
  return out;
}

// No stable cluster: the peaks of the summed |H| start the refinement,
// so that a clear resonance in noisy data is not lost.
void PolesFromPeaks(const std::vector<dynamics::Frf>& frfs, ModeSet* set) {
  const int N = frfs.front().size();
  Eigen::VectorXcd sum = Eigen::VectorXcd::Zero(N);
  for (size_t i = 0; i < frfs.size(); ++i) {
    const double level = frfs[i].receptance().cwiseAbs().maxCoeff();
    if (level > 0.0) sum += frfs[i].receptance().cwiseAbs().cast<cd>() / level;
  }
  const dynamics::Frf summed = dynamics::Frf::FromSamples(frfs.front().freq_hz(), sum);
  std::vector<PeakEstimate> peaks = PickPeaks(summed);
  std::sort(peaks.begin(), peaks.end(),
            [](const PeakEstimate& a, const PeakEstimate& b) { return a.peak_magnitude > b.peak_magnitude; });
  if (peaks.size() > 12) peaks.resize(12);
  for (const PeakEstimate& p : peaks) {
    const double z = std::isfinite(p.damping_ratio) ? std::clamp(p.damping_ratio, 1e-3, 0.2) : 0.02;
    set->poles.push_back(PoleFrom(p.peak_freq_hz, z));
    set->support.push_back(0);
  }
}

// What judges a set of poles for the given problem: whether a pole is
// physical, the settled set (fitted, refined, pruned) and its BIC.
struct SetSearch {
  const GlobalProblem& problem;
  const std::vector<dynamics::Frf>& frfs;
  const GlobalModalFitOptions& o;
  double fmin_hz, fmax_hz;  // the band's first and last line
  int total_lines;          // lines of all FRFs

  // A physical pole in the band: 0 < ζ < max_damping_ratio, fmin..fmax.
  bool Physical(const cd& q) const {
    const double wn = std::abs(q), f_hz = RadPerSecToHz(wn), zeta = -q.real() / wn;
    return zeta > 0.0 && zeta < o.max_damping_ratio && f_hz >= fmin_hz && f_hz <= fmax_hz;
  }

  // Fit, refine, prune (unphysical, out of band, negligible in every FRF,
  // duplicates) until the set no longer changes.
  std::pair<std::vector<cd>, std::vector<int>> Settle(std::vector<cd> p, std::vector<int> sup, SetFit* fit,
                                                       bool refine = true) const {
    for (int pass = 0; pass < 4 && !p.empty(); ++pass) {
      if (o.refine && refine) p = problem.Refine(p);
      *fit = problem.Fit(p);
      std::vector<size_t> order(p.size());
      std::iota(order.begin(), order.end(), size_t{0});
      std::vector<double> strength(p.size());
      for (size_t r = 0; r < p.size(); ++r) strength[r] = RelativeStrength(*fit, frfs, r);
      std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return strength[a] > strength[b]; });
      std::vector<cd> keep;
      std::vector<int> keep_sup;
      for (size_t r : order) {
        const double f_hz = RadPerSecToHz(std::abs(p[r])), zeta = -p[r].real() / std::abs(p[r]);
        if (!(Physical(p[r]) && strength[r] >= o.min_relative_contribution)) continue;
        bool duplicate = false;
        for (const cd& k : keep) {
          const double fk = RadPerSecToHz(std::abs(k)), zk = -k.real() / std::abs(k);
          if (std::abs(fk - f_hz) < 0.1 * (zk + zeta) * f_hz) duplicate = true;
        }
        if (duplicate) continue;
        keep.push_back(p[r]);
        keep_sup.push_back(sup[r]);
      }
      if (keep.size() == p.size()) break;
      p = keep;
      sup = keep_sup;
      if (p.empty()) break;
    }
    if (!p.empty()) *fit = problem.Fit(p);
    return std::pair{p, sup};
  }

  // The Bayesian information criterion of a set's fit: more modes (and the
  // lower residual's two parameters per FRF) must pay for themselves.
  double Bic(double cost, size_t modes, const std::vector<cd>& p, bool force_lower = false) const {
    const double n2 = 2.0 * total_lines;
    const bool lower = force_lower || problem.LowerResidual(p);
    const double params = 2.0 * modes + frfs.size() * (2.0 * modes + 4.0 + (lower ? 2.0 : 0.0));
    return n2 * std::log(std::max(cost, 1e-300)) + params * std::log(n2);
  }
};

// Residual-driven additions on the summed weighted residual of all FRFs.
// Returns the number of modes added.
int AddFromResidual(const SetSearch& search, ModeSet* set) {
  const GlobalProblem& problem = search.problem;
  const std::vector<dynamics::Frf>& frfs = search.frfs;
  const GlobalModalFitOptions& o = search.o;
  std::vector<cd>& poles = set->poles;
  std::vector<int>& support = set->support;
  SetFit& best = set->best;
  const int N = frfs.front().size();
  int added = 0;
  for (int attempt = 0; attempt < o.max_added_modes; ++attempt) {
    Eigen::VectorXd e2 = Eigen::VectorXd::Zero(N);
    for (size_t i = 0; i < frfs.size(); ++i) {
      for (int k = 0; k < N; ++k) {
        e2(k) += std::norm((best.per_frf[i].Evaluate(frfs[i].freq_hz()(k)) - frfs[i].receptance()(k)) *
                           problem.weights(i)(k));
      }
    }
    const int W = std::max(3, N / 200);
    Eigen::VectorXd csum(N + 1), local(N);
    csum(0) = 0.0;
    for (int k = 0; k < N; ++k) csum(k + 1) = csum(k) + e2(k);
    for (int k = 0; k < N; ++k) {
      const int a = std::max(0, k - W), b = std::min(N, k + W + 1);
      local(k) = (csum(b) - csum(a)) / (b - a);
    }
    std::vector<double> sorted(local.data(), local.data() + N);
    const double median = Median(sorted);
    int kmax = 0;
    local.maxCoeff(&kmax);
    if (!(local(kmax) > 4.0 * median)) break;
    const double f_peak = frfs.front().freq_hz()(kmax);
    double z0 = 0.02, nearest = 1e300;
    for (const cd& p : poles) {
      const double fp = RadPerSecToHz(std::abs(p));
      if (std::abs(fp - f_peak) < nearest) {
        nearest = std::abs(fp - f_peak);
        z0 = -p.real() / std::abs(p);
      }
    }
    SetFit trial_best;
    std::vector<cd> trial_poles;
    std::vector<int> trial_sup;
    // Each trial refines only the new pole (the others are refined
    // already); the best trial, if the BIC falls, is then refined with all.
    for (double shift : {0.0, -2.0, 2.0}) {
      std::vector<cd> p = poles;
      p.push_back(PoleFrom(f_peak * (1.0 + shift * z0), z0));
      // A trial only needs to be good enough to be judged: a few
      // iterations; the kept one is refined fully below.
      if (o.refine) p = problem.Refine(p, static_cast<int>(poles.size()), 8, 1e-4);
      const SetFit fit = problem.Fit(p);
      if (fit.cost < trial_best.cost) {
        trial_best = fit;
        trial_poles = p;
      }
    }
    if (!trial_poles.empty() && search.Bic(trial_best.cost, trial_poles.size(), trial_poles) <
                                    search.Bic(best.cost, poles.size(), poles)) {
      trial_sup = support;
      trial_sup.push_back(0);
      std::tie(trial_poles, trial_sup) = search.Settle(trial_poles, trial_sup, &trial_best);
    }
    if (trial_poles.size() > poles.size() &&
        search.Bic(trial_best.cost, trial_poles.size(), trial_poles) < search.Bic(best.cost, poles.size(), poles)) {
      best = trial_best;
      poles = trial_poles;
      support = trial_sup;
      ++added;
    } else {
      break;
    }
  }
  return added;
}

// Backward elimination: drop the weakest mode while that lowers the BIC.
void DropWeakModes(const SetSearch& search, ModeSet* set) {
  std::vector<cd>& poles = set->poles;
  std::vector<int>& support = set->support;
  SetFit& best = set->best;
  for (int attempt = 0; attempt < 8 && poles.size() > 1; ++attempt) {
    size_t weakest = 0;
    double weakest_s = 1e300;
    for (size_t r = 0; r < poles.size(); ++r) {
      const double s = RelativeStrength(best, search.frfs, r);
      if (s < weakest_s) {
        weakest_s = s;
        weakest = r;
      }
    }
    std::vector<cd> p;
    std::vector<int> sup;
    for (size_t r = 0; r < poles.size(); ++r) {
      if (r == weakest) continue;
      p.push_back(poles[r]);
      sup.push_back(support[r]);
    }
    // Judged without refinement first (the remaining poles are already
    // refined; a drop that does not pay without refitting is rarely worth
    // the refinement's cost), refined when it is kept.
    SetFit fit;
    std::tie(p, sup) = search.Settle(p, sup, &fit, /*refine=*/false);
    if (!p.empty() && search.Bic(fit.cost, p.size(), p) < search.Bic(best.cost, poles.size(), poles)) {
      std::tie(p, sup) = search.Settle(p, sup, &fit);
      best = fit;
      poles = p;
      support = sup;
    } else {
      break;
    }
  }
}

// The set refitted with a lower residual where the band has none by
// default; kept (returns true) if the BIC falls.
bool LowerResidualByBic(const SetSearch& search, bool banded, ModeSet* set) {
  const GlobalModalFitOptions& o = search.o;
  std::vector<cd>& poles = set->poles;
  SetFit& best = set->best;
  // A band that starts below a fifth of the lowest mode has no lower
  // residual by default (on a grounded structure the receptance tends to
  // its static value there, and 1/ω² would fit the noise); a free or
  // soft-mounted structure has a mass line there (1/ω² in the receptance:
  // pyuff's beam, 5-50 Hz under its 51.5 Hz mode, where the fit without it
  // stayed flat two decades below the data). It is kept if the BIC falls.
  bool lower_by_bic = false;
  if (o.lower_residual_by_bic && !search.problem.LowerResidual(poles)) {
    const GlobalProblem with_lower(search.frfs, search.fmin_hz, o.uniform_weights_power, /*force_lower=*/true);
    const std::vector<cd> p = o.refine && !banded ? with_lower.Refine(poles) : poles;
    const SetFit fit = with_lower.Fit(p);
    // Refined with the 1/ω² term a weak low pole could leave the band or
    // the physical damping range; then the set without it stands.
    const auto physical = [&](const cd& q) { return search.Physical(q); };
    if (std::all_of(p.begin(), p.end(), physical) && search.Bic(fit.cost, p.size(), p, /*force_lower=*/true) < search.Bic(best.cost, poles.size(), poles)) {
      best = fit;
      poles = p;
      lower_by_bic = true;
    }
  }
  return lower_by_bic;
}

// The modes of `set` into `result` (every FRF's table and the common
// modes) in ascending frequency, the same order in every FRF's table.
void Tabulate(const ModeSet& set, const std::vector<dynamics::Frf>& frfs, GlobalModalFitResult* result) {
  const std::vector<cd>& poles = set.poles;
  const std::vector<int>& support = set.support;
  const SetFit& best = set.best;
  // Ascending frequency, the same order in every FRF's table.
  std::vector<size_t> order(poles.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return std::abs(poles[a]) < std::abs(poles[b]); });
  result->per_frf = best.per_frf;
  for (size_t i = 0; i < frfs.size(); ++i) {
    ModalFitResult& r = result->per_frf[i];
    std::vector<FittedMode> sorted;
    for (size_t k : order) {
      sorted.push_back(best.per_frf[i].modes[k]);
      sorted.back().stable_orders = support[k];
    }
    r.modes = sorted;
    r.status = SolverStatus::kConverged;
    r.fmin_hz = result->fmin_hz;
    r.fmax_hz = result->fmax_hz;
    r.message = "global fit";
  }
  for (size_t k : order) {
    GlobalMode m;
    m.pole = poles[k];
    m.freq_hz = RadPerSecToHz(std::abs(poles[k]));
    m.damping_ratio = -poles[k].real() / std::abs(poles[k]);
    m.stable_orders = support[k];
    result->modes.push_back(m);
  }
}

// How the fit came about, for its message.
struct FitStory {
  size_t clusters{0};         // clusters of stable poles
  bool from_peaks{false};     // poles from the peaks of |H| (no cluster)
  bool banded{false};         // fitted band by band
  int added{0};               // modes added from the residual
  bool lower_by_bic{false};   // a lower residual kept by the BIC
};

// The converged fit's message: the modes, where the poles came from and
// what the fit did with them.
std::string SummaryMessage(const GlobalModalFitResult& result, size_t frfs, const GlobalModalFitOptions& o,
                           const FitStory& story) {
  const int nmax = result.max_order;
  return std::to_string(result.modes.size()) + " modes common to " + std::to_string(frfs) + " FRFs: " +
         (story.from_peaks ? std::string("no cluster of stable poles, poles from the peaks of |H|")
                           : std::to_string(story.clusters) + " clusters of stable poles over orders " +
                                 std::to_string(o.min_order) + ".." + std::to_string(nmax)) +
         (story.banded ? ", a dense FRF fitted in " + std::to_string(result.bands) + " bands" : "") +
         (o.refine ? ", refined" : "") +
         (story.added > 0 ? ", " + std::to_string(story.added) + " added from the residual" : "") +
         (story.lower_by_bic ? ", a lower residual (mass line) below the lowest mode" : "");
}

}  // namespace

void GlobalModalFitOptions::Validate() const {
  CheckOptionBand("fmin_hz", fmin_hz, "fmax_hz", fmax_hz);
  CheckOptionAtLeast("min_order", min_order, 2);
  if (max_order < min_order + 2) {
    throw OptionError("max_order", "max_order: expected a value >= min_order + 2 = " + std::to_string(min_order + 2) +
                                       ", got " + std::to_string(max_order));
  }
  CheckOptionAbove("stable_freq_tol", stable_freq_tol, 0.0);
  CheckOptionAbove("stable_damping_tol", stable_damping_tol, 0.0);
  CheckOptionAbove("cluster_freq_tol", cluster_freq_tol, 0.0);
  CheckOptionAtLeast("min_stable_orders", min_stable_orders, 1);
  CheckOptionRange("min_cluster_fraction", min_cluster_fraction, 0.0, 1.0);
  CheckOptionAbove("max_damping_ratio", max_damping_ratio, 0.0);
  CheckOptionRange("max_damping_ratio", max_damping_ratio, 0.0, 1.0);
  CheckOptionAtLeast("min_relative_contribution", min_relative_contribution, 0.0);
  CheckOptionAtLeast("max_added_modes", max_added_modes, 0);
  CheckOptionRange("uniform_weights_power", uniform_weights_power, -1, 2);
  CheckOptionAtLeast("dense_modes", dense_modes, 0);
  CheckOptionAtLeast("max_modes_per_band", max_modes_per_band, 0);
  CheckOptionAtLeast("driving_point", driving_point, -1);
  CheckOptionRange("model_error_power", model_error_power, -1, 2);
  CheckOptionAbove("model_error_ratio", model_error_ratio, 0.0);
}

GlobalModalFitResult FitModesGlobal(const std::vector<dynamics::Frf>& all, const GlobalModalFitOptions& o) {
  o.Validate();
  if (all.empty()) throw std::invalid_argument("FitModesGlobal: no FRFs given");
  GlobalModalFitResult result;
  const std::vector<dynamics::Frf> frfs = CommonBand(all, o);
  const int N = frfs.front().size();
  if (N == 0) {
    result.message = "no frequency lines in the band";
    return result;
  }
  result.fmin_hz = frfs.front().freq_hz()(0);
  result.fmax_hz = frfs.front().freq_hz()(N - 1);
  const int nmax = std::min(o.max_order, N / 3);
  if (o.min_order < 2 || nmax < o.min_order + 2) {
    result.message = "too few lines (" + std::to_string(N) + ") for model orders " + std::to_string(o.min_order) +
                     ".." + std::to_string(o.max_order);
    return result;
  }
  const Diagram diagram = StabilisationDiagram(frfs, o, nmax, &result);
  const std::vector<Cluster>& clusters = diagram.clusters;

  const GlobalProblem problem(frfs, result.fmin_hz, o.uniform_weights_power);
  ModeSet set;
  for (const Cluster& c : clusters) {
    set.poles.push_back(PoleFrom(c.f_hz, c.zeta));
    set.support.push_back(c.orders);
  }
  FitStory story;
  story.clusters = clusters.size();
  const ModeSet bands = FitInBands(all, o, clusters, &result);
  story.banded = !bands.poles.empty();
  const bool banded = story.banded;
  if (banded) {
    set.poles = bands.poles;
    set.support = bands.support;
  }
  if (set.poles.empty()) {
    PolesFromPeaks(frfs, &set);
    story.from_peaks = !set.poles.empty();
  }

  const SetSearch search{problem, frfs, o, result.fmin_hz, result.fmax_hz, N * static_cast<int>(frfs.size())};
  // Banded: the poles were refined, added and dropped in their bands; here
  // only the residues of every mode over the whole band (and the pruning of
  // a mode two bands both found).
  if (!set.poles.empty()) {
    std::tie(set.poles, set.support) = search.Settle(set.poles, set.support, &set.best, /*refine=*/!banded);
  }
  if (set.poles.empty()) {
    result.status = SolverStatus::kFailed;
    result.message = "no cluster of stable poles over " + std::to_string(diagram.min_orders) + " of the orders " +
                     std::to_string(o.min_order) + ".." + std::to_string(nmax) +
                     " and no peak of |H| fitted as a mode";
    return result;
  }
  if (!banded) {
    story.added = AddFromResidual(search, &set);
    DropWeakModes(search, &set);
  }
  story.lower_by_bic = LowerResidualByBic(search, banded, &set);
  Tabulate(set, frfs, &result);
  result.misfit_in_noise = MisfitInNoise(frfs, result.per_frf);
  result.status = SolverStatus::kConverged;
  result.model_error.assign(frfs.size(), 0.0);
  result.misfit_in_noise_weights_alone = result.misfit_in_noise;
  if (o.model_error_power >= 0 && o.uniform_weights_power < 0) {
    if (std::optional<GlobalModalFitResult> again = RefitWithModelError(frfs, result, o)) return *std::move(again);
  }
  result.message = SummaryMessage(result, frfs.size(), o, story);
  return result;
}

ModalFitResult FitOneFrf(const dynamics::Frf& frf, const ModalFitOptions& options) {
  GlobalModalFitOptions o;
  o.fmin_hz = options.fmin_hz;
  o.fmax_hz = options.fmax_hz;
  o.max_damping_ratio = options.max_damping_ratio;
  o.min_relative_contribution = options.min_relative_contribution;
  o.max_added_modes = options.max_added_modes;
  const GlobalModalFitResult g = FitModesGlobal({frf}, o);
  ModalFitResult r;
  if (g.status == SolverStatus::kConverged && !g.per_frf.empty()) r = g.per_frf[0];
  r.status = g.status;
  r.message = g.message;
  r.fmin_hz = g.fmin_hz;
  r.fmax_hz = g.fmax_hz;
  r.order_used = g.max_order;
  r.stabilisation = g.stabilisation;
  return r;
}

}  // namespace robomach::calibration
