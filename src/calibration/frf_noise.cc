#include "robomach/calibration/frf_noise.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "robomach/calibration/global_modal_fit.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/common/enum_names.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"

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
// Relative error allowed to the local rational fit of FindOutlierLines, of
// the median |H| of its window, added in quadrature to the noise: on the
// analytic two-mode curve of frf_outlier_lines_test without noise the fit
// is within 7e-6 of |H| (one line between the modes, near the
// antiresonance, came out at 7 x the 1e-6 smallest relative noise and was
// flagged without it); 1e-4 leaves a margin of 14. Real data have relative
// noise of 1e-3 or more, to which it adds less than 0.5 %.
constexpr double kLocalModelTolerance = 1e-4;

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

// The largest reduced χ² of a local fit's neighbours for which its line is
// judged (PredictFromNeighbours).
constexpr double kMaxLocalChi2 = 4.0;

// The local fit of FindOutlierLines at line i: Ĥ_i and its variance, from
// the lines `use` (at most 2W+1 around i, i itself not among them).
struct LocalPrediction {
  std::complex<double> h;
  double var{0.0};  // its variance, and the fit's model tolerance
  bool ok{false};
};

LocalPrediction PredictFromNeighbours(const dynamics::Frf& frf, const Eigen::VectorXd& sigma, int i,
                                      const std::vector<int>& use) {
  using cd = std::complex<double>;
  LocalPrediction out;
  const int m = static_cast<int>(use.size());
  // Four complex unknowns (n₀, n₁, n₂, d₁): at least 6 lines leave 4 real
  // degrees of freedom over.
  if (m < 6) return out;
  const Eigen::VectorXd& f = frf.freq_hz();
  const Eigen::VectorXcd& h = frf.receptance();
  // x in units of the half-width of the window (|x| <= 1), H in units of
  // its typical size: the normal equations stay well scaled.
  double half = 0.0;
  for (int k : use) half = std::max(half, std::abs(f(k) - f(i)));
  if (!(half > 0.0)) return out;
  std::vector<double> mags;
  for (int k : use) mags.push_back(std::abs(h(k)));
  const double scale = std::max(Median(mags), 1e-300);
  Eigen::VectorXd x(m), s(m);
  Eigen::VectorXcd y(m);
  for (int j = 0; j < m; ++j) {
    x(j) = (f(use[j]) - f(i)) / half;
    y(j) = h(use[j]) / scale;
    s(j) = std::max(sigma(use[j]) / scale, 1e-300);
  }
  Eigen::Vector4cd p = Eigen::Vector4cd::Zero();  // n₀, n₁, n₂, d₁
  Eigen::Matrix4cd normal;
  for (int iteration = 0; iteration < 4; ++iteration) {
    normal.setZero();
    Eigen::Vector4cd rhs = Eigen::Vector4cd::Zero();
    for (int j = 0; j < m; ++j) {
      // Sanathanan–Koerner: the Levy residual H D − N carries the noise
      // times D, so each row is weighted by 1/(σ |D|) of the last iterate.
      const double d = std::max(std::abs(1.0 + p(3) * x(j)), 1e-6);
      const double w = 1.0 / (s(j) * d);
      const Eigen::Vector4cd row(cd(w), cd(w * x(j)), cd(w * x(j) * x(j)), -w * x(j) * y(j));
      normal += row.conjugate() * row.transpose();
      rhs += row.conjugate() * (w * y(j));
    }
    // A tiny ridge: where the data are a straight line the pole (d₁) and
    // the slope (n₁) trade off and the normal equations are singular; the
    // prediction n₀ is determined all the same.
    for (int k = 0; k < 4; ++k) normal(k, k) += 1e-10 * std::abs(normal(k, k)) + 1e-300;
    const Eigen::Vector4cd next = normal.ldlt().solve(rhs);
    if (!next.allFinite()) return out;
    p = next;
  }
  // How well the local model describes the neighbours themselves: a robust
  // reduced χ² of their residuals, median |r/σ|² / ln 2 (|r/σ|² is Exp(1)
  // for noise alone, whose median is ln 2; the median ignores a neighbour
  // the rational fit misses on its own, a pole placed next to it). Where
  // the model does not describe the neighbours (two modes within the
  // window, a mode narrower than a line next to another: seen on a
  // 6-posture robot campaign at 9-10 Hz and 33-37 Hz, lines flagged at
  // 7-13 × the noise in clean data), the line in the middle cannot be
  // judged: no prediction. kMaxLocalChi2 = 4: for 14 neighbours the median
  // of Exp(1) exceeds 4 ln 2 with probability below 1e-6. Below it, the
  // covariance is scaled by that χ² where it exceeds 1 (the usual
  // residual-variance scaling).
  std::vector<double> r2(static_cast<size_t>(m));
  for (int j = 0; j < m; ++j) {
    const cd model = (p(0) + p(1) * x(j) + p(2) * x(j) * x(j)) / (1.0 + p(3) * x(j));
    r2[static_cast<size_t>(j)] = std::norm((y(j) - model) / s(j));
  }
  const double chi2_red = Median(r2) / std::log(2.0);
  if (!(chi2_red <= kMaxLocalChi2)) return out;
  // Ĥ(0) = n₀; ∂Ĥ(0)/∂(n₀, n₁, n₂, d₁) = (1, 0, 0, 0), so its variance is
  // the (0, 0) element of the least-squares covariance (normal)⁻¹.
  const Eigen::Matrix4cd cov = normal.inverse();
  out.h = p(0) * scale;
  out.var = std::max(cov(0, 0).real(), 0.0) * scale * scale * std::max(1.0, chi2_red) +
            std::pow(kLocalModelTolerance * scale, 2);
  out.ok = std::isfinite(out.var) && std::isfinite(std::abs(out.h));
  return out;
}

double MainsMultiple(double f_hz, double spacing_hz) {
  for (double mains : {50.0, 60.0}) {
    const double k = std::round(f_hz / mains);
    if (k >= 1.0 && std::abs(f_hz - k * mains) <= 0.5 * spacing_hz + 1e-9 * f_hz) return k * mains;
  }
  return 0.0;
}

}  // namespace

std::vector<ExcludedLine> FindOutlierLines(const dynamics::Frf& frf, const Eigen::VectorXd& sigma,
                                           const std::vector<char>& candidate, const NoiseOptions& o) {
  o.Validate();
  const int n = frf.size();
  if (sigma.size() != n || static_cast<int>(candidate.size()) != n) {
    throw std::invalid_argument("FindOutlierLines: sigma and candidate need one entry per line (" +
                                std::to_string(n) + ")");
  }
  const int w = o.outlier_window_lines;
  std::vector<char> flagged(n, 0);
  std::vector<double> z(n, 0.0);
  auto fit_at = [&](int i) {
    std::vector<int> use;
    for (int k = std::max(0, i - w); k <= std::min(n - 1, i + w); ++k) {
      if (std::abs(k - i) >= 2 && !flagged[k]) use.push_back(k);
    }
    return PredictFromNeighbours(frf, sigma, i, use);
  };
  // The threshold of line i: outlier_threshold at a mains multiple (hum),
  // outlier_threshold_off_mains elsewhere.
  const auto spacing_at = [&](int i) {
    return i + 1 < n ? frf.freq_hz()(i + 1) - frf.freq_hz()(i) : frf.freq_hz()(i) - frf.freq_hz()(i - 1);
  };
  std::vector<double> threshold(n);
  for (int i = 0; i < n; ++i) {
    threshold[i] = n > 1 && MainsMultiple(frf.freq_hz()(i), spacing_at(i)) > 0.0 ? o.outlier_threshold
                                                                               : o.outlier_threshold_off_mains;
  }
  // z over the line's own threshold: a line is flagged where it exceeds 1.
  auto score = [&](int i) {
    if (!candidate[i] || flagged[i]) return 0.0;
    const LocalPrediction p = fit_at(i);
    if (!p.ok) return 0.0;
    return std::abs(frf.receptance()(i) - p.h) / std::sqrt(sigma(i) * sigma(i) + p.var) / threshold[i];
  };
  for (int i = 0; i < n; ++i) z[i] = score(i);
  // Greedy, largest first; at most a tenth of the lines (beyond that the
  // noise model, not the data, is wrong, and it is no longer "isolated").
  for (int count = 0; count < std::max(1, n / 10); ++count) {
    const int best = static_cast<int>(std::max_element(z.begin(), z.end()) - z.begin());
    if (!(z[best] > 1.0)) break;
    flagged[best] = 1;
    z[best] = 0.0;
    for (int k = std::max(0, best - w); k <= std::min(n - 1, best + w); ++k) z[k] = score(k);
  }
  // Runs longer than max_outlier_run_lines are structure, not spikes.
  for (int i = 0; i < n;) {
    if (!flagged[i]) {
      ++i;
      continue;
    }
    int j = i;
    while (j < n && flagged[j]) ++j;
    // A run of two or three lines is the leakage of a hum between grid
    // lines only at a mains multiple; elsewhere it is structure the local
    // model does not follow (a weak mode narrower than a line on the flank
    // of a strong one: two lines flagged at 8 × the noise at 32.5 and
    // 33.1 Hz of a robot on a compliant base), and only single lines are
    // spikes.
    bool at_mains = false;
    for (int k = i; k < j; ++k) {
      const double spacing = k + 1 < n ? frf.freq_hz()(k + 1) - frf.freq_hz()(k) : frf.freq_hz()(k) - frf.freq_hz()(k - 1);
      at_mains |= MainsMultiple(frf.freq_hz()(k), spacing) > 0.0;
    }
    if (j - i > o.max_outlier_run_lines || (j - i > 1 && !at_mains)) {
      std::fill(flagged.begin() + i, flagged.begin() + j, 0);
    }
    i = j;
  }
  // Sizes against the final fits (every flagged line out of every fit); a
  // line that only stood out through a flagged neighbour is kept.
  std::vector<ExcludedLine> out;
  for (int i = 0; i < n; ++i) {
    if (!flagged[i]) continue;
    const LocalPrediction p = fit_at(i);
    if (!p.ok) continue;
    const double excess = std::abs(frf.receptance()(i) - p.h);
    if (!(excess / std::sqrt(sigma(i) * sigma(i) + p.var) > threshold[i])) continue;
    const Eigen::VectorXd& f = frf.freq_hz();
    const double spacing = i + 1 < n ? f(i + 1) - f(i) : f(i) - f(i - 1);
    out.push_back({i, f(i), excess / sigma(i), excess, MainsMultiple(f(i), spacing)});
  }
  return out;
}

std::string DescribeExcludedLine(const ExcludedLine& e) {
  std::ostringstream d;
  char f[32], r[32];
  std::snprintf(f, sizeof(f), "%.5g", e.freq_hz);
  std::snprintf(r, sizeof(r), "%.2g", e.ratio);
  d << f << " Hz: " << (e.ratio >= 100.0 ? std::to_string(static_cast<long long>(std::lround(e.ratio))) : r)
    << " x the noise";
  if (e.mains_hz > 0.0) {
    d << " (mains hum: ";
    bool first = true;
    for (double mains : {50.0, 60.0}) {
      const double k = e.mains_hz / mains;
      if (std::abs(k - std::round(k)) > 1e-9) continue;
      d << (first ? "" : " or ") << std::lround(k) << " x " << mains << " Hz";
      first = false;
    }
    d << ")";
  }
  return d.str();
}

void NoiseOptions::Validate() const {
  // "NoiseOptions: FIELD must be BOUND, got VALUE": the field is the first
  // word, as a tool's ValidateOptions puts its option in its place.
  auto fail = [](const std::string& field, const std::string& bound, double value) {
    throw OptionError(field, "NoiseOptions: " + field + " must be " + bound + ", got " + FormatNumber(value, 7));
  };
  if (!(min_snr > 0.0 && std::isfinite(min_snr))) fail("min_snr", "finite and > 0", min_snr);
  if (averages < 0) fail("averages", ">= 0 (0: unknown)", averages);
  if (!(knots_per_octave > 0.0 && knots_per_octave <= 8.0)) fail("knots_per_octave", "in (0, 8]", knots_per_octave);
  if (max_gap_lines < 0) fail("max_gap_lines", ">= 0", max_gap_lines);
  if (min_run_lines < 1) fail("min_run_lines", ">= 1", min_run_lines);
  if (!(outlier_threshold_off_mains >= outlier_threshold && std::isfinite(outlier_threshold_off_mains))) {
    fail("outlier_threshold_off_mains",
         "finite and >= outlier_threshold " + FormatNumber(outlier_threshold, 7) + " (15 by default)",
         outlier_threshold_off_mains);
  }
  if (!(outlier_threshold >= 3.0 && std::isfinite(outlier_threshold))) {
    fail("outlier_threshold", "finite and >= 3 (standard deviations of the noise; 6 by default)", outlier_threshold);
  }
  if (outlier_window_lines < 4 || outlier_window_lines > 64) {
    fail("outlier_window_lines", "in [4, 64]", outlier_window_lines);
  }
  if (max_outlier_run_lines < 1) fail("max_outlier_run_lines", ">= 1", max_outlier_run_lines);
}

std::string ToString(NoiseSource s) { return s == NoiseSource::kCoherence ? "coherence" : "scatter"; }

NoiseSource ParseNoiseSource(const std::string& name) {
  constexpr NoiseSource kAll[] = {NoiseSource::kCoherence, NoiseSource::kScatter};
  return ParseByName("noise source", name, kAll);
}

namespace {

// What the passes of the noise model share: the data and options, |H|² of
// each line, the signal power of the relative term, the floor's basis, the
// coherence's σ² (coherence only) and the wide floor of the second pass.
struct NoiseState {
  const dynamics::Frf& frf;
  const NoiseOptions& o;
  int n;
  Eigen::VectorXd a;       // |H|²
  Eigen::VectorXd signal;  // signal power of the relative term
  FloorBasis basis;
  bool coherence;
  Eigen::VectorXd sigma2;  // from the coherence
  std::optional<Eigen::VectorXd> wide_floor2;
};

// The running median of `a` over 7 lines (the first pass's signal power).
Eigen::VectorXd RunningMedian7(const Eigen::VectorXd& a, int n) {
  Eigen::VectorXd signal(n);
  for (int i = 0; i < n; ++i) {
    std::vector<double> w;
    for (int j = std::max(0, i - 3); j <= std::min(n - 1, i + 3); ++j) w.push_back(a(j));
    signal(i) = Median(w);
  }
  return signal;
}

// The first pass: θ fitted to the σ² the coherence gives (with at least two
// averages, when asked for), else to the scatter of the lines.
ScatterFit FirstPass(NoiseState* s, FrfNoise* out) {
  const NoiseOptions& o = s->o;
  const int n = s->n;
  if (s->coherence) {
    out->source = NoiseSource::kCoherence;
    out->averages = o.averages;
    for (int i = 0; i < n; ++i) {
      const double g2 = std::clamp((*s->frf.coherence())(i), 1e-6, 1.0);
      s->sigma2(i) = std::max(s->a(i) * (1.0 - g2) / ((o.averages - 1) * g2), kMinRelative * kMinRelative * s->a(i));
    }
    const double smallest = s->sigma2.maxCoeff() * 1e-24;
    for (int i = 0; i < n; ++i) s->sigma2(i) = std::max(s->sigma2(i), smallest);
    return FitToSigma(s->frf, s->signal, s->basis, s->sigma2);
  }
  out->source = NoiseSource::kScatter;
  return FitScatter(s->frf, s->signal, s->basis);
}

// The usable lines from the SNR: SNR >= min_snr, short gaps between usable
// stretches closed, then short stretches dropped; each stretch kept is
// added to out->usable_bands.
std::vector<char> UsableFromSnr(const NoiseState& s, FrfNoise* out) {
  const NoiseOptions& o = s.o;
  const int n = s.n;
  std::vector<char> u(n);
  for (int i = 0; i < n; ++i) u[i] = out->snr(i) >= o.min_snr;
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
      out->usable_bands.emplace_back(s.frf.freq_hz()(i), s.frf.freq_hz()(j - 1));
    }
    i = j;
  }
  return u;
}

// rel, floor, σ, SNR and the usable lines of a fitted θ.
void FinishPass(const NoiseState& s, const ScatterFit& fit, FrfNoise* out) {
  const NoiseOptions& o = s.o;
  const int n = s.n;
  out->usable_bands.clear();
  NoiseModelEval model{s.basis, s.signal, {}, {}, {}};
  model.Evaluate(fit.theta);
  if (s.wide_floor2) {
    // The larger of the two floors: where a drift is smooth over a few
    // lines the wide one sees it; elsewhere they agree.
    model.floor2 = model.floor2.cwiseMax(*s.wide_floor2);
    model.sigma2 = model.floor2 + model.rel2a;
  }
  out->relative = std::exp(fit.theta(0));
  out->floor_m_per_N = model.floor2.cwiseSqrt();
  out->sigma_m_per_N = s.coherence ? s.sigma2.cwiseSqrt() : model.sigma2.cwiseSqrt();
  out->iterations += fit.iterations;
  out->status = fit.converged ? SolverStatus::kConverged : SolverStatus::kNotConverged;
  // SNR against the additive floor, |H| as the running median over 5 lines
  // (one noisy line does not flip the mask).
  out->snr.resize(n);
  for (int i = 0; i < n; ++i) {
    std::vector<double> w;
    for (int j = std::max(0, i - 2); j <= std::min(n - 1, i + 2); ++j) w.push_back(std::sqrt(s.a(j)));
    out->snr(i) = Median(w) / out->floor_m_per_N(i);
  }
  std::vector<char> u = UsableFromSnr(s, out);
  // Isolated outlier lines (hum, spikes) inside the usable band are named
  // and left out; the usable bands stay as they were drawn.
  out->excluded_lines.clear();
  if (o.exclude_outlier_lines) {
    out->excluded_lines = FindOutlierLines(s.frf, out->sigma_m_per_N, u, o);
    for (const ExcludedLine& e : out->excluded_lines) u[e.line] = 0;
  }
  out->usable = u;
  out->usable_lines = static_cast<int>(std::count(u.begin(), u.end(), 1));
}

// The modal fit of the usable lines for the second pass.
ModalFitResult ModalFitOfUsable(const dynamics::Frf& band, const NoiseOptions& o) {
  // With global_modal_fit the fit frf-modes makes (one FRF: poles from
  // the clustered stabilisation diagram to order 100, refined by variable
  // projection): the single-FRF fitter took 20 s on dataset58's 1600
  // lines, where no pole was stable to its order 32 and it refined
  // peak-picked poles.
  ModalFitResult mf;
  {
    if (o.global_modal_fit) {
      const GlobalModalFitResult g = FitModesGlobal({band});
      if (g.status == SolverStatus::kConverged) mf = g.per_frf[0];
      else mf.status = g.status;
    } else {
      mf = FitModes(band);
    }
  }
  return mf;
}

// The second pass's observations: each usable line's misfit about the modal
// fit `mf` (trimmed), the second differences of the lines outside the
// usable band.
std::vector<Term> ModalFitTerms(const NoiseState& s, const ModalFitResult& mf, const std::vector<int>& lines,
                                const FrfNoise& out) {
  const dynamics::Frf& frf = s.frf;
  const NoiseOptions& o = s.o;
  const int n = s.n;
  const double params = 4.0 * mf.modes.size() + (o.global_modal_fit ? 4.0 : 2.0) +
                        (mf.lower_residual != std::complex<double>(0.0) ? 2.0 : 0.0);
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
  return terms;
}

// The second pass (scatter only, enough usable lines): θ refitted about the
// modal fit of the usable lines, kept only when it is plausible.
void SecondPass(NoiseState* s, FrfNoise* out) {
  const dynamics::Frf& frf = s->frf;
  const NoiseOptions& o = s->o;
  const int n = s->n;
  // Second pass: about the modal fit of the usable lines the signal's own
  // curvature (sharp peaks on a coarse grid) no longer counts as scatter,
  // which biased rel upwards by 30-50 % on lightly damped modes. Lines
  // outside the usable band keep their second differences (there the
  // floor dominates and the signal is smooth on its scale).
  std::vector<int> lines;
  for (int i = 0; i < n; ++i) {
    if (out->usable[i]) lines.push_back(i);
  }
  const dynamics::Frf band = frf.WithNoise(out->sigma_m_per_N).Select(lines);
  const ModalFitResult mf = ModalFitOfUsable(band, o);
  if (mf.status != SolverStatus::kConverged) return;
  const std::vector<Term> terms = ModalFitTerms(*s, mf, lines, *out);
  const Eigen::VectorXd signal1 = s->signal;
  for (int i : lines) s->signal(i) = std::norm(mf.Evaluate(frf.freq_hz()(i)));
  // The residual about the fit on every line, for the wide floor.
  Eigen::VectorXcd resid(n);
  for (int i = 0; i < n; ++i) resid(i) = frf.receptance()(i) - mf.Evaluate(frf.freq_hz()(i));
  if (o.wide_floor) s->wide_floor2 = WideFloor2(dynamics::Frf::FromSamples(frf.freq_hz(), resid), s->signal, s->basis);
  const ScatterFit refined = FitTerms(frf, s->signal, s->basis, terms);
  // The first pass can only overstate rel (the signal's curvature adds
  // to the scatter); a second pass that raises it is describing the
  // fit's misfit instead, and is not used. Nor is one that all but
  // removes it (below a quarter of the first pass, where the curvature
  // accounted for 30-50 %): on dataset58 (30 modes, a fit that leaves
  // 14 x the noise) rel fell from 0.16 % to 1e-4 % and the floor rose
  // over the whole band below 24 Hz, the trimmed misfit moved into the
  // floor.
  const double rel2 = std::exp(refined.theta(0));
  if (!(rel2 <= 1.05 * out->relative) || (o.global_modal_fit && !(rel2 >= 0.25 * out->relative))) {
    s->signal = signal1;
    s->wide_floor2.reset();
  } else {
    const FrfNoise first = *out;
    FinishPass(*s, refined, out);
    if (out->usable_lines == 0) {
      *out = first;
      s->signal = signal1;
      s->wide_floor2.reset();
    } else {
      out->modal_refined = true;
    }
  }
}

// The one-line description: the source, rel, the floor's range, the usable
// band, the isolated lines left out and whether the fit converged.
std::string DescribeNoise(const FrfNoise& out, const NoiseState& s) {
  const NoiseOptions& o = s.o;
  std::ostringstream d;
  if (s.coherence) {
    d << "coherence (" << o.averages << " averages)";
  } else {
    d << (out.modal_refined ? "scatter about the modal fit" : "scatter");
  }
  d << ": rel " << Sci(100.0 * out.relative) << " %, floor " << Sci(out.floor_m_per_N.minCoeff()) << ".."
    << Sci(out.floor_m_per_N.maxCoeff()) << " m/N; " << DescribeUsable(out);
  if (!out.excluded_lines.empty()) {
    // The largest first; a long list is cut (every line is in the summary).
    std::vector<ExcludedLine> by_size = out.excluded_lines;
    std::stable_sort(by_size.begin(), by_size.end(),
                     [](const ExcludedLine& a, const ExcludedLine& b) { return a.ratio > b.ratio; });
    const size_t shown = std::min<size_t>(by_size.size(), 6);
    d << "; " << by_size.size() << (by_size.size() == 1 ? " isolated line" : " isolated lines") << " left out: ";
    for (size_t k = 0; k < shown; ++k) d << (k ? ", " : "") << DescribeExcludedLine(by_size[k]);
    if (shown < by_size.size()) d << " and " << by_size.size() - shown << " more";
  }
  if (out.status != SolverStatus::kConverged) d << "; the noise fit did not converge";
  return d.str();
}

}  // namespace

FrfNoise EstimateFrfNoise(const dynamics::Frf& frf, const NoiseOptions& o) {
  o.Validate();
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
  const bool coherence = o.use_coherence && frf.coherence() && o.averages >= 2;
  NoiseState s{frf, o, n, a, RunningMedian7(a, n), FloorBasis(frf.freq_hz(), o.knots_per_octave), coherence,
               Eigen::VectorXd(n), std::nullopt};
  FrfNoise out;
  const ScatterFit fit = FirstPass(&s, &out);
  FinishPass(s, fit, &out);
  if (!coherence && o.refine_with_modal_fit && out.usable_lines >= 16) SecondPass(&s, &out);
  out.description = DescribeNoise(out, s);
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
    // Only the usable band is needed: the fast fitter (20 s -> 0.6 s on
    // dataset58, which comes here as a mobility with 4.5 m/N at 0.5 Hz).
    o.global_modal_fit = true;
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

std::string UsableBandUnitFinding(const std::string& what, const UsableBandPeak& p, dynamics::FrfFileFormat format) {
  std::string f = dynamics::ReceptancePeakFinding(what, p.peak_m_per_N, format);
  if (f.empty()) return f;
  return f + (p.on_usable_band ? " (the largest on the usable band " + Sci(p.fmin_hz) + "-" + Sci(p.fmax_hz) +
                                     " Hz of the noise model)"
                               : std::string(" (the largest of all lines)"));
}

std::vector<std::string> ReceptanceUnitFindings(const dynamics::FrfSet& frfs, const std::string& source,
                                                int averages, dynamics::FrfFileFormat format) {
  std::vector<std::string> out;
  for (const auto& [key, frf] : frfs) {
    std::string f =
        UsableBandUnitFinding(source + ": " + key.ToString(), PeakReceptanceInUsableBand(frf, averages), format);
    if (!f.empty()) out.push_back(std::move(f));
  }
  return out;
}

}  // namespace robomach::calibration
