#include "robomach/calibration/frf_noise.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "robomach/calibration/modal_fit.h"

namespace robomach::calibration {
namespace {

// Smallest relative noise the model admits: data rounded to 13 digits (a
// noise-free synthesis) would otherwise get weights of 1e13 and make every
// round-off of a model "significant".
constexpr double kMinRelative = 1e-6;
// Weight of the smoothness penalty on the second difference of the knots of
// ln floor: one line's worth of information, enough to carry the shape
// through octaves with one or two lines, negligible where there are many.
constexpr double kSmoothness = 1.0;
// |d|²/v above this is not noise (probability e⁻¹² for an exponential
// variate): a sharp peak where the signal is not smooth on the grid.
constexpr double kTrimRatio = 12.0;
constexpr int kDriftSpacings[] = {8, 16};

// The floor's shape: hat functions on knots evenly spaced in log₂ f.
struct FloorBasis {
  std::vector<double> knots;  // log₂ f
  // Per line: the two knots it lies between and the weight of the upper one.
  std::vector<int> lo;
  std::vector<double> t;

  FloorBasis(const Eigen::VectorXd& f, double knots_per_octave) {
    const int n = static_cast<int>(f.size());
    double fpos = 0.0;
    for (int i = 0; i < n && fpos == 0.0; ++i) fpos = f(i) > 0.0 ? f(i) : 0.0;
    std::vector<double> x(n);
    for (int i = 0; i < n; ++i) x[i] = std::log2(std::max(f(i), fpos));
    const double x0 = x.front(), x1 = x.back();
    const int k = std::max(2, static_cast<int>(std::ceil((x1 - x0) * knots_per_octave - 1e-9)) + 1);
    for (int j = 0; j < k; ++j) knots.push_back(x0 + (x1 - x0) * j / (k - 1));
    lo.resize(n);
    t.resize(n);
    for (int i = 0; i < n; ++i) {
      const double u = x1 > x0 ? (x[i] - x0) / (x1 - x0) * (k - 1) : 0.0;
      const int j = std::clamp(static_cast<int>(std::floor(u)), 0, k - 2);
      lo[i] = j;
      t[i] = std::clamp(u - j, 0.0, 1.0);
    }
  }
  int size() const { return static_cast<int>(knots.size()); }
};

// The model σ_i² = rel² a_i + floor_i² and its derivatives with respect to
// θ = (ln rel, ln floor at each knot).
struct NoiseModelEval {
  const FloorBasis& basis;
  const Eigen::VectorXd& a;  // |H|²
  Eigen::VectorXd floor2, rel2a, sigma2;

  void Evaluate(const Eigen::VectorXd& theta) {
    const int n = static_cast<int>(a.size());
    floor2.resize(n);
    rel2a.resize(n);
    const double rel2 = std::exp(2.0 * theta(0));
    for (int i = 0; i < n; ++i) {
      const int j = basis.lo[i];
      const double lf = (1.0 - basis.t[i]) * theta(1 + j) + basis.t[i] * theta(2 + j);
      floor2(i) = std::exp(2.0 * lf);
      rel2a(i) = rel2 * a(i);
    }
    sigma2 = floor2 + rel2a;
  }
  // ∂σ_i²/∂θ, added with weight w into `g` (size 1 + knots).
  void AddGradient(int i, double w, Eigen::VectorXd* g) const {
    (*g)(0) += w * 2.0 * rel2a(i);
    const int j = basis.lo[i];
    (*g)(1 + j) += w * 2.0 * floor2(i) * (1.0 - basis.t[i]);
    (*g)(2 + j) += w * 2.0 * floor2(i) * basis.t[i];
  }
};

// Penalty λ Σ (θ_{k−1} − 2θ_k + θ_{k+1})² on the knots: its gradient and
// Hessian added to (g, A), and its value.
double AddSmoothness(const Eigen::VectorXd& theta, Eigen::VectorXd* g, Eigen::MatrixXd* A) {
  const int k = static_cast<int>(theta.size()) - 1;
  double value = 0.0;
  for (int j = 1; j + 1 < k; ++j) {
    const double d = theta(j) - 2.0 * theta(j + 1) + theta(j + 2);
    value += kSmoothness * d * d;
    if (g) {
      const int idx[3] = {j, j + 1, j + 2};
      const double c[3] = {1.0, -2.0, 1.0};
      for (int p = 0; p < 3; ++p) {
        (*g)(idx[p]) += 2.0 * kSmoothness * c[p] * d;
        for (int q = 0; q < 3; ++q) (*A)(idx[p], idx[q]) += 2.0 * kSmoothness * c[p] * c[q];
      }
    }
  }
  return value;
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

double Quantile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  const size_t m = std::min(v.size() - 1, static_cast<size_t>(p * v.size()));
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

// Lower bound of each θ: rel ≥ kMinRelative; the floor ≥ 1e-12 of the
// largest |H| (a floor of exactly zero has no logarithm).
void ClampTheta(Eigen::VectorXd* theta, double max_abs_h) {
  (*theta)(0) = std::clamp((*theta)(0), std::log(kMinRelative), 0.0);
  const double lo = std::log(1e-12 * max_abs_h), hi = std::log(1e3 * max_abs_h);
  for (int j = 1; j < theta->size(); ++j) (*theta)(j) = std::clamp((*theta)(j), lo, hi);
}

// One Newton step `step` from θ, halved until the cost does not rise (at
// most 30 times), θ clamped to its bounds. Returns false if no step was
// accepted; sets *small when the gain or the step is at round-off level.
template <typename Cost>
bool DampedStep(const Cost& cost_of, const Eigen::VectorXd& step, double max_abs_h, Eigen::VectorXd* theta,
                double* cost, bool* small) {
  double lambda = 1.0;
  for (int tries = 0; tries < 30; ++tries, lambda *= 0.5) {
    Eigen::VectorXd t2 = *theta + lambda * step;
    ClampTheta(&t2, max_abs_h);
    const double c2 = cost_of(t2);
    if (c2 <= *cost) {
      const double gain = *cost - c2;
      *theta = t2;
      *cost = c2;
      *small = gain < 1e-9 * std::max(1.0, std::abs(c2)) || (lambda * step).cwiseAbs().maxCoeff() < 1e-7;
      return true;
    }
  }
  return false;
}

struct ScatterFit {
  Eigen::VectorXd theta;
  int iterations{0};
  bool converged{false};
};

// One observation of the noise: q = |Σ_j c_j e_j|² for the noise e_j of up
// to three lines j, exponentially distributed with mean v = Σ c_j² σ_j².
struct Term {
  int line[3];
  double c2[3];
  int count;
  double q;
  double V(const Eigen::VectorXd& sigma2) const {
    double v = 0.0;
    for (int j = 0; j < count; ++j) v += c2[j] * sigma2(line[j]);
    return v;
  }
};

// Second differences of the lines i, i+1, i+2, exact for a straight line and
// scaled so that an even grid gives (1, −2, 1).
Term SecondDifference(const dynamics::Frf& frf, int i, int s_lines = 1) {
  const Eigen::VectorXd& f = frf.freq_hz();
  const Eigen::VectorXcd& h = frf.receptance();
  const int j = i + s_lines, k = i + 2 * s_lines;
  const double x0 = f(i), x1 = f(j), x2 = f(k);
  const double s = 0.5 * (x2 - x0);
  const double c0 = (x2 - x1) / s, c1 = -(x2 - x0) / s, c2 = (x1 - x0) / s;
  return {{i, j, k}, {c0 * c0, c1 * c1, c2 * c2}, 3, std::norm(c0 * h(i) + c1 * h(j) + c2 * h(k))};
}

// Maximum likelihood of the terms (see the header): Fisher scoring with the
// smoothness penalty, terms with q/v above kTrimRatio dropped and the fit
// repeated.
// `a`: the signal power |H|² of each line for the relative term.
ScatterFit FitTerms(const dynamics::Frf& frf, const Eigen::VectorXd& a, const FloorBasis& basis,
                    const std::vector<Term>& terms) {
  const Eigen::VectorXd& f = frf.freq_hz();
  const double max_abs_h = std::sqrt(a.maxCoeff());
  const int m = static_cast<int>(terms.size());
  NoiseModelEval model{basis, a, {}, {}, {}};
  const int np = 1 + basis.size();
  Eigen::VectorXd theta(np);
  // Start: rel 1 %, the floor at each knot from the lower quartile of q/Σc²
  // near it (an Exp(1) variate's lower quartile is 0.288).
  theta(0) = std::log(0.01);
  const double spacing = basis.size() > 1 ? basis.knots[1] - basis.knots[0] : 1.0;
  std::vector<double> all;
  for (const Term& t : terms) all.push_back(t.q / (t.c2[0] + (t.count > 1 ? t.c2[1] + t.c2[2] : 0.0)));
  for (int k = 0; k < basis.size(); ++k) {
    std::vector<double> near;
    for (int i = 0; i < m; ++i) {
      const double x = std::log2(std::max(f(terms[i].line[terms[i].count / 2]), 1e-300));
      if (std::abs(x - basis.knots[k]) <= spacing) near.push_back(all[i]);
    }
    const double q25 = near.empty() ? Quantile(all, 0.25) : Quantile(near, 0.25);
    theta(1 + k) = 0.5 * std::log(std::max(q25 / 0.288, 1e-300));
  }
  ClampTheta(&theta, max_abs_h);
  std::vector<char> keep(m, 1);
  auto nll = [&](const Eigen::VectorXd& th) {
    model.Evaluate(th);
    double s = 0.0;
    for (int i = 0; i < m; ++i) {
      if (!keep[i]) continue;
      const double v = terms[i].V(model.sigma2);
      s += std::log(v) + terms[i].q / v;
    }
    return s + AddSmoothness(th, nullptr, nullptr);
  };
  ScatterFit out;
  for (int trim_round = 0; trim_round < 6; ++trim_round) {
    double cost = nll(theta);
    bool converged = false;
    for (int it = 0; it < 200; ++it) {
      ++out.iterations;
      model.Evaluate(theta);
      Eigen::VectorXd score = Eigen::VectorXd::Zero(np);
      Eigen::MatrixXd info = Eigen::MatrixXd::Zero(np, np);
      for (int i = 0; i < m; ++i) {
        if (!keep[i]) continue;
        const Term& t = terms[i];
        const double v = t.V(model.sigma2);
        Eigen::VectorXd g = Eigen::VectorXd::Zero(np);  // ∂ ln v / ∂θ
        for (int j = 0; j < t.count; ++j) model.AddGradient(t.line[j], t.c2[j] / v, &g);
        score += (1.0 - t.q / v) * g;
        info.selfadjointView<Eigen::Lower>().rankUpdate(g);
      }
      info = info.selfadjointView<Eigen::Lower>();
      AddSmoothness(theta, &score, &info);
      info.diagonal().array() += 1e-9;
      const Eigen::VectorXd step = info.ldlt().solve(-score);
      if (!step.allFinite()) break;
      // No descent left at round-off level counts as converged too.
      if (!DampedStep(nll, step, max_abs_h, &theta, &cost, &converged) || converged) {
        converged = true;
        break;
      }
    }
    out.converged = converged;
    // Drop the terms where the signal is not smooth on the grid, refit.
    model.Evaluate(theta);
    bool changed = false;
    for (int i = 0; i < m; ++i) {
      const char k = terms[i].q / terms[i].V(model.sigma2) <= kTrimRatio;
      if (k != keep[i]) changed = true;
      keep[i] = k;
    }
    if (!changed) break;
  }
  out.theta = theta;
  return out;
}

// The additive floor seen by second differences over 8 and 16 lines (the
// larger of the two fits' floors; the `rel` of these fits is not used),
// applied to the residual about the modal fit so that the signal's own
// curvature is not counted: a drift that is smooth over a few lines, such
// as the leakage of the slow trend of an integrated accelerometer signal
// below ~100 Hz (issue #18), is nearly cancelled by the one-line second
// difference (to 4 % of its variance when it is a moving average over 15
// lines; 38 % over 8 lines, 100 % over 16) but not by these; for
// independent lines all spacings see the same floor. On the tap
// test with drifts averaged over 1 to 30 lines (30 cases), spacing 8 alone
// left 4 with a mode fitted in the drift, 8 and 16 none. Empty if the FRF
// is too short.
std::optional<Eigen::VectorXd> WideFloor2(const dynamics::Frf& frf, const Eigen::VectorXd& a,
                                          const FloorBasis& basis);

ScatterFit FitScatter(const dynamics::Frf& frf, const Eigen::VectorXd& a, const FloorBasis& basis) {
  std::vector<Term> terms;
  for (int i = 0; i + 2 < frf.size(); ++i) terms.push_back(SecondDifference(frf, i));
  return FitTerms(frf, a, basis, terms);
}

std::optional<Eigen::VectorXd> WideFloor2(const dynamics::Frf& frf, const Eigen::VectorXd& a,
                                          const FloorBasis& basis) {
  std::optional<Eigen::VectorXd> out;
  for (int spacing : kDriftSpacings) {
    std::vector<Term> terms;
    for (int i = 0; i + 2 * spacing < frf.size(); ++i) terms.push_back(SecondDifference(frf, i, spacing));
    if (terms.size() < 8) continue;
    const ScatterFit fit = FitTerms(frf, a, basis, terms);
    NoiseModelEval model{basis, a, {}, {}, {}};
    model.Evaluate(fit.theta);
    out = out ? Eigen::VectorXd(out->cwiseMax(model.floor2)) : model.floor2;
  }
  return out;
}

// Least squares of ln σ² (from the coherence) on the model, Gauss–Newton.
ScatterFit FitToSigma(const dynamics::Frf& frf, const Eigen::VectorXd& a, const FloorBasis& basis,
                      const Eigen::VectorXd& sigma2) {
  const int n = frf.size();
  const double max_abs_h = std::sqrt(a.maxCoeff());
  NoiseModelEval model{basis, a, {}, {}, {}};
  const int np = 1 + basis.size();
  Eigen::VectorXd theta(np);
  theta(0) = std::log(0.01);
  for (int k = 0; k < basis.size(); ++k) {
    theta(1 + k) = 0.5 * std::log(std::max(Median(std::vector<double>(sigma2.data(), sigma2.data() + n)), 1e-300));
  }
  ClampTheta(&theta, max_abs_h);
  auto cost_of = [&](const Eigen::VectorXd& th) {
    model.Evaluate(th);
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += std::pow(std::log(model.sigma2(i) / sigma2(i)), 2);
    return s + AddSmoothness(th, nullptr, nullptr);
  };
  ScatterFit out;
  double cost = cost_of(theta);
  for (int it = 0; it < 200; ++it) {
    ++out.iterations;
    model.Evaluate(theta);
    Eigen::VectorXd grad = Eigen::VectorXd::Zero(np);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(np, np);
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd g = Eigen::VectorXd::Zero(np);
      model.AddGradient(i, 1.0 / model.sigma2(i), &g);
      const double r = std::log(model.sigma2(i) / sigma2(i));
      grad += 2.0 * r * g;
      A += 2.0 * g * g.transpose();
    }
    AddSmoothness(theta, &grad, &A);
    A.diagonal().array() += 1e-9;
    const Eigen::VectorXd step = A.ldlt().solve(-grad);
    if (!step.allFinite()) break;
    bool small = false;
    if (!DampedStep(cost_of, step, max_abs_h, &theta, &cost, &small) || small) {
      out.converged = true;
      break;
    }
  }
  out.theta = theta;
  return out;
}

std::string Sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

}  // namespace

void CheckValid(const NoiseOptions& o) {
  auto fail = [](const std::string& m) { throw std::invalid_argument("NoiseOptions: " + m); };
  if (!(o.min_snr > 0.0 && std::isfinite(o.min_snr))) fail("min_snr must be finite and > 0");
  if (o.averages < 0) fail("averages must be >= 0 (0: unknown)");
  if (!(o.knots_per_octave > 0.0 && o.knots_per_octave <= 8.0)) fail("knots_per_octave must be in (0, 8]");
  if (o.max_gap_lines < 0) fail("max_gap_lines must be >= 0");
  if (o.min_run_lines < 1) fail("min_run_lines must be >= 1");
}

std::string NoiseSourceName(NoiseSource s) { return s == NoiseSource::kCoherence ? "coherence" : "scatter"; }

FrfNoise EstimateFrfNoise(const dynamics::Frf& frf, const NoiseOptions& o) {
  CheckValid(o);
  const int n = frf.size();
  if (n < 8) {
    throw std::invalid_argument("noise model: an FRF needs at least 8 lines, this one has " + std::to_string(n));
  }
  const Eigen::VectorXd a = frf.receptance().cwiseAbs2();
  // The signal power in the relative term σ² = rel² |H|² + floor²: not the
  // line's own |H|², which carries that line's noise (where the floor
  // dominates, rel |H_i| then tracks each line's noise and the likelihood
  // is gamed: rel came out 0.8 on such data), but the running median over
  // 7 lines; in the second pass the modal fit's |H|² on the usable lines.
  Eigen::VectorXd signal(n);
  for (int i = 0; i < n; ++i) {
    std::vector<double> w;
    for (int j = std::max(0, i - 3); j <= std::min(n - 1, i + 3); ++j) w.push_back(a(j));
    signal(i) = Median(w);
  }
  const FloorBasis basis(frf.freq_hz(), o.knots_per_octave);
  FrfNoise out;
  ScatterFit fit;
  Eigen::VectorXd sigma2(n);
  const bool coherence = o.use_coherence && frf.coherence() && o.averages >= 2;
  std::optional<Eigen::VectorXd> wide_floor2;
  if (coherence) {
    out.source = NoiseSource::kCoherence;
    out.averages = o.averages;
    for (int i = 0; i < n; ++i) {
      const double g2 = std::clamp((*frf.coherence())(i), 1e-6, 1.0);
      sigma2(i) = std::max(a(i) * (1.0 - g2) / ((o.averages - 1) * g2), kMinRelative * kMinRelative * a(i));
    }
    const double smallest = sigma2.maxCoeff() * 1e-24;
    for (int i = 0; i < n; ++i) sigma2(i) = std::max(sigma2(i), smallest);
    fit = FitToSigma(frf, signal, basis, sigma2);
  } else {
    out.source = NoiseSource::kScatter;
    fit = FitScatter(frf, signal, basis);
  }
  // rel, floor, σ, SNR and the usable lines of a fitted θ.
  const auto finish = [&](const ScatterFit& fit) {
    out.usable_bands.clear();
    NoiseModelEval model{basis, signal, {}, {}, {}};
    model.Evaluate(fit.theta);
    if (wide_floor2) {
      // The larger of the two floors: where a drift is smooth over a few
      // lines the wide one sees it; elsewhere they agree.
      model.floor2 = model.floor2.cwiseMax(*wide_floor2);
      model.sigma2 = model.floor2 + model.rel2a;
    }
    out.relative = std::exp(fit.theta(0));
    out.floor_m_per_N = model.floor2.cwiseSqrt();
    out.sigma_m_per_N = coherence ? sigma2.cwiseSqrt() : model.sigma2.cwiseSqrt();
    out.iterations += fit.iterations;
    out.converged = fit.converged;
    // SNR against the additive floor, |H| as the running median over 5 lines
    // (one noisy line does not flip the mask).
    out.snr.resize(n);
    for (int i = 0; i < n; ++i) {
      std::vector<double> w;
      for (int j = std::max(0, i - 2); j <= std::min(n - 1, i + 2); ++j) w.push_back(std::sqrt(a(j)));
      out.snr(i) = Median(w) / out.floor_m_per_N(i);
    }
    std::vector<char> u(n);
    for (int i = 0; i < n; ++i) u[i] = out.snr(i) >= o.min_snr;
    // Close short gaps between usable stretches, then drop short stretches.
    for (int i = 0; i < n;) {
      if (u[i]) {
        ++i;
        continue;
      }
      int j = i;
      while (j < n && !u[j]) ++j;
      if (i > 0 && j < n && j - i <= o.max_gap_lines) std::fill(u.begin() + i, u.begin() + j, 1);
      i = j;
    }
    for (int i = 0; i < n;) {
      if (!u[i]) {
        ++i;
        continue;
      }
      int j = i;
      while (j < n && u[j]) ++j;
      if (j - i < o.min_run_lines) {
        std::fill(u.begin() + i, u.begin() + j, 0);
      } else {
        out.usable_bands.emplace_back(frf.freq_hz()(i), frf.freq_hz()(j - 1));
      }
      i = j;
    }
    out.usable = u;
    out.usable_lines = static_cast<int>(std::count(u.begin(), u.end(), 1));
  };
  finish(fit);
  if (!coherence && o.refine_with_modal_fit && out.usable_lines >= 16) {
    // Second pass: about the modal fit of the usable lines the signal's own
    // curvature (sharp peaks on a coarse grid) no longer counts as scatter,
    // which biased rel upwards by 30-50 % on lightly damped modes. Lines
    // outside the usable band keep their second differences (there the
    // floor dominates and the signal is smooth on its scale).
    std::vector<int> lines;
    for (int i = 0; i < n; ++i) {
      if (out.usable[i]) lines.push_back(i);
    }
    const dynamics::Frf band = frf.WithNoise(out.sigma_m_per_N).Select(lines);
    const ModalFitResult mf = FitModes(band);
    if (mf.status == ModalFitStatus::kOk) {
      const double params = 4.0 * mf.modes.size() + 2.0 + (mf.lower_residual != std::complex<double>(0.0) ? 2.0 : 0.0);
      const double dof = std::max(0.5, 1.0 - params / (2.0 * lines.size()));
      // A line the modal fit misses by more than kTrimRatio first-pass
      // variances is a misfit of the fit (a mode it did not find), not noise.
      std::vector<Term> terms;
      const Eigen::VectorXd sigma1 = out.sigma_m_per_N;
      for (int i : lines) {
        const double q = std::norm(frf.receptance()(i) - mf.Evaluate(frf.freq_hz()(i)));
        if (q <= kTrimRatio * sigma1(i) * sigma1(i)) terms.push_back({{i, i, i}, {dof, 0.0, 0.0}, 1, q});
      }
      for (int i = 0; i + 2 < n; ++i) {
        if (!out.usable[i] && !out.usable[i + 1] && !out.usable[i + 2]) terms.push_back(SecondDifference(frf, i));
      }
      const Eigen::VectorXd signal1 = signal;
      for (int i : lines) signal(i) = std::norm(mf.Evaluate(frf.freq_hz()(i)));
      // The residual about the fit on every line, for the wide floor.
      Eigen::VectorXcd resid(n);
      for (int i = 0; i < n; ++i) resid(i) = frf.receptance()(i) - mf.Evaluate(frf.freq_hz()(i));
      if (o.wide_floor) wide_floor2 = WideFloor2(dynamics::Frf::FromSamples(frf.freq_hz(), resid), signal, basis);
      const ScatterFit refined = FitTerms(frf, signal, basis, terms);
      // The first pass can only overstate rel (the signal's curvature adds
      // to the scatter); a second pass that raises it is describing the
      // fit's misfit instead, and is not used.
      if (!(std::exp(refined.theta(0)) <= 1.05 * out.relative)) {
        signal = signal1;
        wide_floor2.reset();
      } else {
        const FrfNoise first = out;
        finish(refined);
        if (out.usable_lines == 0) {
          out = first;
          signal = signal1;
          wide_floor2.reset();
        } else {
          out.modal_refined = true;
        }
      }
    }
  }
  std::ostringstream d;
  if (coherence) {
    d << "coherence (" << o.averages << " averages)";
  } else {
    d << (out.modal_refined ? "scatter about the modal fit" : "scatter");
  }
  d << ": rel " << Sci(100.0 * out.relative) << " %, floor " << Sci(out.floor_m_per_N.minCoeff()) << ".."
    << Sci(out.floor_m_per_N.maxCoeff()) << " m/N; " << DescribeUsable(out);
  if (!out.converged) d << "; the noise fit did not converge";
  out.description = d.str();
  return out;
}

std::string DescribeUsable(const FrfNoise& n) {
  std::ostringstream d;
  d << "usable ";
  if (n.usable_bands.empty()) {
    d << "none";
  } else {
    d << Sci(n.usable_bands.front().first) << "-" << Sci(n.usable_bands.back().second) << " Hz";
    if (n.usable_bands.size() > 1) d << " in " << n.usable_bands.size() << " stretches";
  }
  d << " (" << n.usable_lines << " of " << n.usable.size() << " lines)";
  return d.str();
}

NoiseModels EstimateNoise(const dynamics::FrfSet& measured, const NoiseOptions& options) {
  NoiseModels out;
  for (const auto& [key, frf] : measured) {
    try {
      out.emplace(key, EstimateFrfNoise(frf, options));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(key.ToString() + ": " + e.what());
    }
  }
  return out;
}

dynamics::FrfSet UsableData(const dynamics::FrfSet& measured, const NoiseModels& noise) {
  dynamics::FrfSet out;
  for (const auto& [key, frf] : measured) {
    auto it = noise.find(key);
    if (it == noise.end()) throw std::invalid_argument("no noise model for " + key.ToString());
    const FrfNoise& nm = it->second;
    if (static_cast<int>(nm.usable.size()) != frf.size()) {
      throw std::invalid_argument("the noise model of " + key.ToString() + " has " +
                                  std::to_string(nm.usable.size()) + " lines, the FRF " +
                                  std::to_string(frf.size()));
    }
    std::vector<int> lines;
    for (int i = 0; i < frf.size(); ++i) {
      if (nm.usable[i]) lines.push_back(i);
    }
    if (lines.empty()) continue;
    out.Insert(key, frf.WithNoise(nm.sigma_m_per_N).Select(lines));
  }
  return out;
}

Eigen::VectorXd LogResidualWeights(const dynamics::Frf& frf) {
  Eigen::VectorXd w = Eigen::VectorXd::Ones(frf.size());
  if (!frf.noise_sigma()) return w;
  for (int i = 0; i < frf.size(); ++i) {
    w(i) = std::sqrt(2.0) * std::abs(frf.receptance()(i)) / (*frf.noise_sigma())(i);
  }
  return w;
}

UsableBandPeak PeakReceptanceInUsableBand(const dynamics::Frf& frf, int averages) {
  UsableBandPeak out;
  // The usable lines are a subset of all lines, so their peak is at most the
  // peak of all lines: when that is plausible the noise model (seconds on a
  // few thousand lines) can change no verdict on the upper limit.
  const double all_lines = dynamics::PeakReceptance(frf);
  if (all_lines <= dynamics::kMaxPlausibleReceptance) {
    out.peak_m_per_N = all_lines;
    return out;
  }
  FrfNoise noise;
  try {
    NoiseOptions o;
    o.wide_floor = true;
    o.averages = averages;
    noise = EstimateFrfNoise(frf, o);
  } catch (const std::invalid_argument&) {
    noise.usable_lines = 0;  // fewer than 8 lines: no noise model
  }
  if (noise.usable_lines == 0) {
    out.peak_m_per_N = all_lines;
    return out;
  }
  // A line counts when it is usable, above 0 Hz and coherent (as
  // dynamics::PeakReceptance); the peak is the largest median of three
  // neighbouring counted lines (a resonance spans several lines).
  const int n = frf.size();
  std::vector<char> counted(n, 0);
  for (int k = 0; k < n; ++k) {
    counted[k] = noise.usable[k] && frf.freq_hz()(k) > 0.0 && !(frf.coherence() && (*frf.coherence())(k) < 0.5);
  }
  double peak = 0.0;
  bool any = false;
  for (int k = 1; k + 1 < n; ++k) {
    if (!(counted[k - 1] && counted[k] && counted[k + 1])) continue;
    const double a = std::abs(frf.receptance()(k - 1)), b = std::abs(frf.receptance()(k)),
                 c = std::abs(frf.receptance()(k + 1));
    peak = std::max(peak, std::max(std::min(a, b), std::min(std::max(a, b), c)));  // median of three
    any = true;
  }
  if (!any) {
    out.peak_m_per_N = all_lines;
    return out;
  }
  out.peak_m_per_N = peak;
  out.fmin_hz = noise.usable_bands.front().first;
  out.fmax_hz = noise.usable_bands.back().second;
  out.on_usable_band = true;
  return out;
}

std::string UsableBandUnitFinding(const std::string& what, const UsableBandPeak& p) {
  std::string f = dynamics::ReceptancePeakFinding(what, p.peak_m_per_N);
  if (f.empty()) return f;
  return f + (p.on_usable_band ? " (the largest on the usable band " + Sci(p.fmin_hz) + "-" + Sci(p.fmax_hz) +
                                     " Hz of the noise model)"
                               : std::string(" (the largest of all lines)"));
}

std::vector<std::string> ReceptanceUnitFindings(const dynamics::FrfSet& frfs, const std::string& source,
                                                int averages) {
  std::vector<std::string> out;
  for (const auto& [key, frf] : frfs) {
    std::string f = UsableBandUnitFinding(source + ": " + key.ToString(), PeakReceptanceInUsableBand(frf, averages));
    if (!f.empty()) out.push_back(std::move(f));
  }
  return out;
}

}  // namespace robomach::calibration
