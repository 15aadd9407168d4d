#include "robomach/dynamics/uncertainty.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {
namespace {

// Sample quantile with linear interpolation between order statistics
// (Hyndman & Fan 1996, definition 7: NumPy's default).
double Quantile(std::vector<double> sorted_values, double p) {
  const double h = p * static_cast<double>(sorted_values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(h));
  const size_t hi = std::min(lo + 1, sorted_values.size() - 1);
  return sorted_values[lo] + (h - static_cast<double>(lo)) * (sorted_values[hi] - sorted_values[lo]);
}

std::string Percent(double x) { return FormatNumber(100.0 * x, 3) + " %"; }

// A departure from linear relative to a half-width: in percent up to 10
// times it, beyond as a factor ("17 times", not "1.7e+03 %").
std::string OfHalfWidth(double x) {
  if (x < 10.0) return Percent(x) + " of its half-width";
  // Whole times up to a million (110, not 1.1e+02); beyond, a power of ten.
  return (x < 1e6 ? std::to_string(std::lround(x)) : FormatNumber(x, 2)) + " times its half-width";
}

}  // namespace

Eigen::VectorXd ToTheta(const ParameterUncertainty& u, const Eigen::VectorXd& values) {
  Eigen::VectorXd t = values;
  for (size_t i = 0; i < u.parameters.size(); ++i) {
    if (u.parameters[i].scale == UncertainScale::kLog) t(i) = std::log(values(i));
    if (u.parameters[i].scale == UncertainScale::kInverse) t(i) = 1.0 / values(i);
  }
  return t;
}

Eigen::VectorXd FromTheta(const ParameterUncertainty& u, const Eigen::VectorXd& theta) {
  Eigen::VectorXd v = theta;
  for (size_t i = 0; i < u.parameters.size(); ++i) {
    if (u.parameters[i].scale == UncertainScale::kLog) v(i) = std::exp(theta(i));
    // A sampled compliance <= 0 has no stiffness: NaN, a failed sample.
    if (u.parameters[i].scale == UncertainScale::kInverse) v(i) = theta(i) > 0.0 ? 1.0 / theta(i) : NAN;
  }
  return v;
}


const char* ToString(UncertainScale s) {
  switch (s) {
    case UncertainScale::kLog: return "log";
    case UncertainScale::kInverse: return "inverse";
    case UncertainScale::kLinear: return "linear";
  }
  return "?";
}

UncertainScale ParseUncertainScale(const std::string& name) {
  for (UncertainScale s : {UncertainScale::kLinear, UncertainScale::kLog, UncertainScale::kInverse}) {
    if (name == ToString(s)) return s;
  }
  throw std::invalid_argument("unknown scale '" + name + "'; expected linear, log or inverse");
}

void CheckValid(const ParameterUncertainty& u) {
  const int n = static_cast<int>(u.parameters.size());
  if (n == 0) throw std::invalid_argument("parameter uncertainty: no parameter");
  std::set<std::string> names;
  for (const UncertainParameter& p : u.parameters) {
    if (p.name.empty()) throw std::invalid_argument("parameter uncertainty: a parameter without a name");
    if (!names.insert(p.name).second) {
      throw std::invalid_argument("parameter uncertainty: parameter '" + p.name + "' given twice");
    }
    if (!std::isfinite(p.value)) {
      throw std::invalid_argument("parameter uncertainty: " + p.name + " has the non-finite value " +
                                  FormatNumber(p.value, 7));
    }
    if (p.scale != UncertainScale::kLinear && !(p.value > 0.0)) {
      throw std::invalid_argument("parameter uncertainty: " + p.name + " = " + FormatNumber(p.value, 7) +
                                  " on the " + ToString(p.scale) + " scale must be > 0");
    }
  }
  if (u.covariance.rows() != n || u.covariance.cols() != n) {
    throw std::invalid_argument("parameter uncertainty: the covariance is " + std::to_string(u.covariance.rows()) +
                                " x " + std::to_string(u.covariance.cols()) + ", expected " + std::to_string(n) +
                                " x " + std::to_string(n) + " (one row and column per parameter)");
  }
  if (!u.covariance.allFinite()) throw std::invalid_argument("parameter uncertainty: the covariance is not finite");
  const double scale = std::max(u.covariance.cwiseAbs().maxCoeff(), 1e-300);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < i; ++j) {
      if (std::abs(u.covariance(i, j) - u.covariance(j, i)) > 1e-8 * scale) {
        throw std::invalid_argument("parameter uncertainty: the covariance is not symmetric (row " +
                                    std::to_string(i + 1) + ", column " + std::to_string(j + 1) + ": " +
                                    FormatNumber(u.covariance(i, j), 7) + " vs " +
                                    FormatNumber(u.covariance(j, i), 7) + ")");
      }
    }
  }
  // A positive parameter's relative standard deviation above 100 % (inverse
  // scale: the compliance's interval reaches zero within 1 sigma) or a
  // factor of 10 (log scale) is no fit's result: the covariance of another
  // coordinate (of the value itself, in its unit squared) typed under this
  // scale is the likely mistake.
  for (int i = 0; i < n; ++i) {
    const UncertainParameter& p = u.parameters[static_cast<size_t>(i)];
    const double s = std::sqrt(std::max(u.covariance(i, i), 0.0));
    const double relative = p.scale == UncertainScale::kInverse ? s * p.value
                            : p.scale == UncertainScale::kLog   ? s
                                                                : 0.0;
    const double limit = p.scale == UncertainScale::kLog ? std::log(10.0) : 1.0;
    if (relative > limit) {
      throw std::invalid_argument(
          "parameter uncertainty: " + p.name + " on the " + ToString(p.scale) + " scale has a relative standard "
          "deviation of " + FormatNumber(100.0 * relative, 3) + " % (at most " +
          FormatNumber(100.0 * limit, 3) + " % is a fit's result): the covariance must be of " +
          (p.scale == UncertainScale::kInverse ? "1/value" : "log(value)") +
          " (the covariance of the value itself, in its unit squared, given under this scale?)");
    }
  }
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(u.covariance, Eigen::EigenvaluesOnly)
                                 .eigenvalues();
  if (ev.minCoeff() < -1e-9 * std::max(ev.maxCoeff(), 0.0) || ev.maxCoeff() < 0.0) {
    throw std::invalid_argument("parameter uncertainty: the covariance has the negative eigenvalue " +
                                FormatNumber(ev.minCoeff(), 4) + " (largest " + FormatNumber(ev.maxCoeff(), 4) +
                                "): not a covariance matrix");
  }
}

ParameterUncertainty CombineIndependent(const std::vector<ParameterUncertainty>& parts) {
  ParameterUncertainty out;
  int n = 0;
  for (const auto& p : parts) n += static_cast<int>(p.parameters.size());
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  int at = 0;
  std::vector<std::string> owners;
  for (const auto& part : parts) {
    for (const UncertainParameter& p : part.parameters) {
      for (size_t k = 0; k < out.parameters.size(); ++k) {
        if (out.parameters[k].name == p.name) {
          throw std::invalid_argument("parameter " + p.name + " is in two uncertainty files (" + owners[k] + " and " +
                                      part.source + "): a parameter fitted twice must be fitted once from both "
                                      "campaigns (kq-identify --merge), not taken as independent");
        }
      }
      out.parameters.push_back(p);
      owners.push_back(part.source);
    }
    const auto m = static_cast<Eigen::Index>(part.parameters.size());
    if (part.covariance.rows() != m || part.covariance.cols() != m) {
      throw std::invalid_argument("parameter uncertainty from " + part.source + ": covariance of the wrong size");
    }
    out.covariance.block(at, at, m, m) = part.covariance;
    at += static_cast<int>(m);
    out.source += (out.source.empty() ? "" : "; ") + part.source;
  }
  return out;
}

double NormalQuantile(double p) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("NormalQuantile: p outside (0, 1)");
  // Φ(z) = erfc(−z/√2)/2 is increasing; |z| < 40 covers every double p.
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

double ChiSquaredCdf(double x, int dof) {
  if (dof < 1) throw std::invalid_argument("ChiSquaredCdf: degrees of freedom below 1");
  if (!(x > 0.0)) return 0.0;
  // Closed forms for whole degrees of freedom (Abramowitz & Stegun 26.4.4,
  // 26.4.5): the upper tail Q(x|k).
  const double h = 0.5 * x;
  double q;
  if (dof % 2 == 0) {
    double term = 1.0, sum = 1.0;
    for (int j = 1; j < dof / 2; ++j) sum += (term *= h / j);
    q = std::exp(-h) * sum;
  } else {
    const double r = std::sqrt(x), phi = std::exp(-h) / std::sqrt(2.0 * M_PI);
    double term = r, sum = 0.0;
    for (int j = 1; j <= (dof - 1) / 2; ++j) {
      sum += term;
      term *= x / (2.0 * j + 1.0);
    }
    q = std::erfc(r / std::sqrt(2.0)) + 2.0 * phi * sum;
  }
  return std::clamp(1.0 - q, 0.0, 1.0);
}

double ChiSquaredQuantile(double p, int dof) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("ChiSquaredQuantile: p outside (0, 1)");
  if (dof < 1) throw std::invalid_argument("ChiSquaredQuantile: degrees of freedom below 1");
  double lo = 0.0, hi = std::max(10.0, 4.0 * dof);
  while (ChiSquaredCdf(hi, dof) < p && hi < 1e6) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, hi); ++i) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquaredCdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

const char* ToString(PropagationMethod m) {
  switch (m) {
    case PropagationMethod::kAuto: return "auto";
    case PropagationMethod::kFirstOrder: return "first-order";
    case PropagationMethod::kMonteCarlo: return "monte-carlo";
  }
  return "?";
}

PropagationMethod ParsePropagationMethod(const std::string& name) {
  for (PropagationMethod m : {PropagationMethod::kAuto, PropagationMethod::kFirstOrder, PropagationMethod::kMonteCarlo}) {
    if (name == ToString(m)) return m;
  }
  throw std::invalid_argument("unknown propagation method '" + name + "'; expected auto, first-order or monte-carlo");
}

void PropagationOptions::Validate() const {
  if (!(confidence > 0.0 && confidence < 1.0)) {
    const bool percent = confidence > 1.0 && confidence < 100.0;
    throw OptionError("confidence", "confidence: expected a level in (0, 1), got " + FormatNumber(confidence, 7) +
                                        (percent ? " (a percentage? 95 % is 0.95)" : ""));
  }
  if (samples < 100 || samples > 10000000) {
    throw OptionError("samples", "samples: expected 100 - 10 000 000 Monte Carlo samples, got " +
                                     std::to_string(samples));
  }
  if (!(nonlinearity_tolerance > 0.0 && nonlinearity_tolerance <= 1.0)) {
    throw OptionError("nonlinearity_tolerance",
                      "nonlinearity_tolerance: expected (0, 1], got " + FormatNumber(nonlinearity_tolerance, 7));
  }
}

namespace {

// What every stage of Propagate shares: the estimates, the outputs there,
// the covariance's principal axes and the interval's normal quantile
// (references to Propagate's locals, which outlive the stages).
struct PropagationBase {
  const ParameterUncertainty& u;
  const OutputFunction& f;
  const Eigen::VectorXd& values;  // the estimates
  const Eigen::VectorXd& theta0;  // the estimates on the sampling scales
  const Eigen::VectorXd& f0;      // f(values)
  const Eigen::VectorXd& lambda;  // the covariance's eigenvalues (clipped at 0)
  const Eigen::MatrixXd& V;       // its eigenvectors v_k, in columns
  double lambda_max;
  double z;  // the normal quantile of the confidence
  int n;     // parameters
  int m;     // outputs
};

// Σ_f = Σ_k λ_k (∂f/∂v_k)(∂f/∂v_k)ᵀ over the covariance's principal axes
// v_k: central differences along each axis with a step of 1e-3 √λ_k
// (2 evaluations per axis; axes without variance are skipped, so a
// rank-one covariance costs 3 evaluations), or forward differences (1).
// Returns D, which holds ∂f/∂v_k in column k (zero for a skipped axis) of
// g (b.f or the linearisation); counts the evaluations in res.
Eigen::MatrixXd Differences(const PropagationBase& b, const OutputFunction& g, bool central,
                            PropagationResult* res) {
  const int m = b.m, n = b.n;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(m, n);
  Eigen::VectorXd g0 = b.f0;
  if (&g != &b.f && !central) {
    g0 = g(b.values);
    ++res->evaluations;
  }
  auto at = [&](const Eigen::VectorXd& theta) {
    Eigen::VectorXd y = g(FromTheta(b.u, theta));
    if (y.size() != m) {
      throw std::invalid_argument("the local model gives " + std::to_string(y.size()) + " outputs, f " +
                                  std::to_string(m));
    }
    return y;
  };
  if (g0.size() != m) throw std::invalid_argument("the local model gives another number of outputs");
  for (int k = 0; k < n; ++k) {
    if (!(b.lambda(k) > 1e-14 * b.lambda_max)) continue;
    const double h = 1e-3 * std::sqrt(b.lambda(k));
    D.col(k) = central ? Eigen::VectorXd((at(b.theta0 + h * b.V.col(k)) - at(b.theta0 - h * b.V.col(k))) / (2.0 * h))
                       : Eigen::VectorXd((at(b.theta0 + h * b.V.col(k)) - g0) / h);
    res->evaluations += central ? 2 : 1;
  }
  return D;
}

// The first-order intervals into res->outputs (std_dev, lower, upper).
// Returns J = Σ_k (∂f/∂v_k) v_kᵀ, the Jacobian on the span of the
// covariance (the sigma-point check uses it); *lost tells the outputs whose
// derivatives the linearisation did not give.
Eigen::MatrixXd FirstOrderIntervals(const PropagationBase& b, const OutputFunction& linearisation,
                                    const PropagationOptions& o, PropagationResult* res, std::string* lost) {
  const int m = b.m;
  // With a linearisation, `central_differences` applies to it; an output
  // it does not reach at some step takes f's own central differences.
  Eigen::MatrixXd D = Differences(b, linearisation ? linearisation : b.f, o.central_differences, res);
  if (linearisation && !D.allFinite()) {
    const Eigen::MatrixXd Df = Differences(b, b.f, true, res);
    int outputs_lost = 0;
    for (int j = 0; j < m; ++j) {
      if (D.row(j).allFinite()) continue;
      D.row(j) = Df.row(j);
      ++outputs_lost;
    }
    *lost = "; the local model did not reach every step for " + std::to_string(outputs_lost) + " of " +
            std::to_string(m) + " outputs, whose derivatives are differences of the outputs themselves";
  }
  const Eigen::MatrixXd J = D * b.V.transpose();
  const Eigen::MatrixXd cov = D * b.lambda.asDiagonal() * D.transpose();
  for (int k = 0; k < m; ++k) {
    const double s = std::sqrt(std::max(cov(k, k), 0.0));
    res->outputs[k].std_dev = s;
    res->outputs[k].lower = b.f0(k) - b.z * s;
    res->outputs[k].upper = b.f0(k) + b.z * s;
  }
  return J;
}

// Sigma points along the covariance's principal axes, at the interval's
// half-width: where the outputs bend within the interval, the linear
// interval is wrong and Monte Carlo is used instead. Sets res's
// nonlinearities and reason; returns true if the first-order intervals
// stand (the departure within o.nonlinearity_tolerance).
bool SigmaPointsLinear(const PropagationBase& b, const Eigen::MatrixXd& J, const PropagationOptions& o,
                       const std::vector<std::string>& output_names, PropagationResult* res) {
  const int m = b.m, n = b.n;
  double worst = 0.0;
  int worst_output = -1;
  for (auto& out : res->outputs) out.nonlinearity = 0.0;
  for (int k = 0; k < n; ++k) {
    if (!(b.lambda(k) > 1e-14 * b.lambda_max)) continue;  // the axes the differences used
    for (double sign : {-1.0, 1.0}) {
      const Eigen::VectorXd step = sign * b.z * std::sqrt(b.lambda(k)) * b.V.col(k);
      Eigen::VectorXd fk;
      try {
        fk = b.f(FromTheta(b.u, b.theta0 + step));
      } catch (const std::exception&) {
        fk = Eigen::VectorXd::Constant(m, NAN);
      }
      ++res->evaluations;
      const Eigen::VectorXd linear = b.f0 + J * step;
      for (int j = 0; j < m; ++j) {
        const double half = b.z * res->outputs[j].std_dev;
        const double scale = std::max(half, 1e-12 * std::max(std::abs(b.f0(j)), 1e-300));
        const double d = std::isfinite(fk(j)) ? std::abs(fk(j) - linear(j)) / scale : INFINITY;
        res->outputs[j].nonlinearity = std::max(res->outputs[j].nonlinearity, d);
        if (d > worst) {
          worst = d;
          worst_output = j;
        }
      }
    }
  }
  res->nonlinearity = worst;
  if (worst <= o.nonlinearity_tolerance) {
    res->reason = "first order: at the sigma points the outputs depart from linear by at most " + Percent(worst) +
                  " of the half-width (under " + Percent(o.nonlinearity_tolerance) + ")";
    return true;
  }
  const std::string what = worst_output < static_cast<int>(output_names.size())
                               ? output_names[worst_output]
                               : "output " + std::to_string(worst_output + 1);
  res->reason = "Monte Carlo: " + what + " departs from linear by " +
                (std::isfinite(worst) ? OfHalfWidth(worst) : std::string("an undefined amount (not computable)")) +
                " at a sigma point (over " + Percent(o.nonlinearity_tolerance) +
                "): the first-order interval would be wrong";
  return false;
}

// The Monte Carlo intervals into res->outputs: o.samples draws of the
// normal distribution on the sampling scales, a sample whose outputs cannot
// be evaluated left out (and counted); appends the sample count to the reason.
void MonteCarloIntervals(const PropagationBase& b, const PropagationOptions& o, PropagationResult* res) {
  const int m = b.m, n = b.n;
  res->method_used = PropagationMethod::kMonteCarlo;
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::MatrixXd L = b.V * b.lambda.cwiseSqrt().asDiagonal();
  std::vector<std::vector<double>> samples(m);
  for (auto& s : samples) s.reserve(o.samples);
  Eigen::VectorXd xi(n);
  for (int s = 0; s < o.samples; ++s) {
    for (int i = 0; i < n; ++i) xi(i) = normal(rng);
    Eigen::VectorXd fs;
    try {
      fs = b.f(FromTheta(b.u, b.theta0 + L * xi));
    } catch (const std::exception&) {
      fs.resize(0);
    }
    ++res->evaluations;
    if (fs.size() != m || !fs.allFinite()) {
      ++res->failed_samples;
      continue;
    }
    for (int k = 0; k < m; ++k) samples[k].push_back(fs(k));
  }
  const int good = o.samples - res->failed_samples;
  if (good < 100) {
    throw std::invalid_argument("Monte Carlo: only " + std::to_string(good) + " of " + std::to_string(o.samples) +
                                " samples could be evaluated (sampled parameters outside their bounds?)");
  }
  for (int k = 0; k < m; ++k) {
    std::vector<double>& v = samples[k];
    std::sort(v.begin(), v.end());
    double mean = 0.0;
    for (double x : v) mean += x;
    mean /= static_cast<double>(v.size());
    double var = 0.0;
    for (double x : v) var += (x - mean) * (x - mean);
    res->outputs[k].std_dev = std::sqrt(var / static_cast<double>(v.size() - 1));
    res->outputs[k].lower = Quantile(v, 0.5 * (1.0 - o.confidence));
    res->outputs[k].upper = Quantile(v, 0.5 * (1.0 + o.confidence));
  }
  res->reason += "; " + std::to_string(good) + " samples, seed " + std::to_string(o.seed);
  if (res->failed_samples > 0) {
    res->reason += "; " + std::to_string(res->failed_samples) +
                   " samples could not be evaluated and were left out (sampled parameters outside their bounds)";
  }
}

}  // namespace

PropagationResult Propagate(const ParameterUncertainty& u, const OutputFunction& f, const PropagationOptions& o,
                            const std::vector<std::string>& output_names, const OutputFunction& linearisation) {
  CheckValid(u);
  o.Validate();
  const int n = static_cast<int>(u.parameters.size());
  Eigen::VectorXd values(n);
  for (int i = 0; i < n; ++i) values(i) = u.parameters[i].value;
  const Eigen::VectorXd theta0 = ToTheta(u, values);
  PropagationResult res;
  const Eigen::VectorXd f0 = f(values);
  ++res.evaluations;
  if (!f0.allFinite()) throw std::invalid_argument("the outputs at the estimates are not finite");
  const int m = static_cast<int>(f0.size());
  const double z = NormalQuantile(0.5 * (1.0 + o.confidence));
  res.outputs.assign(m, OutputInterval{});
  for (int k = 0; k < m; ++k) res.outputs[k].value = f0(k);

  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(u.covariance);
  const Eigen::VectorXd lambda = eig.eigenvalues().cwiseMax(0.0);
  const Eigen::MatrixXd& V = eig.eigenvectors();
  const PropagationBase b{u, f, values, theta0, f0, lambda, V, lambda.maxCoeff(), z, n, m};

  bool monte_carlo = o.method == PropagationMethod::kMonteCarlo;
  if (o.method != PropagationMethod::kMonteCarlo) {
    std::string lost;
    const Eigen::MatrixXd J = FirstOrderIntervals(b, linearisation, o, &res, &lost);
    res.method_used = PropagationMethod::kFirstOrder;
    if (o.method == PropagationMethod::kFirstOrder) {
      res.reason = "first order, as asked (--uncertainty-method first-order)";
    } else {
      monte_carlo = !SigmaPointsLinear(b, J, o, output_names, &res);
    }
    if (!monte_carlo) {
      res.reason += lost;
      res.linearised = linearisation && lost.empty();
    }
  } else {
    res.reason = "Monte Carlo, as asked (--uncertainty-method monte-carlo)";
  }

  if (monte_carlo) MonteCarloIntervals(b, o, &res);
  return res;
}

ParameterSet WithValues(const ParameterSet& base, const ParameterUncertainty& u, const Eigen::VectorXd& values) {
  ParameterSet out = base;
  for (size_t i = 0; i < u.parameters.size(); ++i) {
    if (!out.Has(u.parameters[i].name)) {
      throw std::invalid_argument("the uncertainty's parameter '" + u.parameters[i].name + "'" +
                                  (u.source.empty() ? "" : " (from " + u.source + ")") +
                                  " is not a parameter of this model (" + out.NameList() +
                                  "): an effect it belongs to is not switched on?");
    }
    out.Set(u.parameters[i].name, values(static_cast<Eigen::Index>(i)));
  }
  return out;
}

PostureModeIntervals ModalIntervals(const RobotDescription& description, const ParameterSet& base,
                                    const Eigen::VectorXd& q, const ParameterUncertainty& u,
                                    const PropagationOptions& options) {
  PostureOptions po;
  po.cartesian = false;
  po.jacobian_condition = false;
  auto outputs = [&](const Eigen::VectorXd& values) {
    const auto model = RobotModel::Build(description, WithValues(base, u, values));
    const PostureDynamics d = EvaluatePosture(model, q, po);
    Eigen::VectorXd out(3 * static_cast<Eigen::Index>(d.modes.size()));
    for (size_t k = 0; k < d.modes.size(); ++k) {
      const Mode& mode = d.modes[k];
      const double w = 2.0 * M_PI * mode.freq_hz;
      out(3 * k) = mode.freq_hz;
      out(3 * k + 1) = mode.damping_ratio;
      out(3 * k + 2) = std::isfinite(mode.modal_mass_kg) && mode.damping_ratio > 0.0
                           ? 1.0 / (mode.modal_mass_kg * w * w * 2.0 * mode.damping_ratio)
                           : 0.0;
    }
    return out;
  };
  PostureModeIntervals r;
  std::vector<std::string> names;
  for (int k = 1; k <= 100; ++k) {
    for (const char* what : {"frequency", "damping ratio", "peak receptance"}) {
      names.push_back("mode " + std::to_string(k) + "'s " + what);
    }
  }
  r.propagation = Propagate(u, outputs, options, names);
  const size_t modes = r.propagation.outputs.size() / 3;
  for (size_t k = 0; k < modes; ++k) {
    r.modes.push_back({r.propagation.outputs[3 * k], r.propagation.outputs[3 * k + 1],
                       r.propagation.outputs[3 * k + 2]});
  }
  return r;
}

ReceptanceBand DirectReceptanceBand(const RobotDescription& description, const ParameterSet& base,
                                    const Eigen::VectorXd& q, const ParameterUncertainty& u,
                                    const Eigen::VectorXd& all_lines, const PropagationOptions& options,
                                    int max_lines) {
  if (max_lines < 2) throw std::invalid_argument("DirectReceptanceBand: max_lines must be >= 2");
  PostureOptions po;
  po.cartesian = false;
  po.jacobian_condition = false;
  po.static_compliance = false;
  // The lines: every k-th, and the one nearest each mode at the estimates.
  std::set<Eigen::Index> chosen;
  {
    Eigen::VectorXd values(static_cast<Eigen::Index>(u.parameters.size()));
    for (size_t i = 0; i < u.parameters.size(); ++i) values(static_cast<Eigen::Index>(i)) = u.parameters[i].value;
    const PostureDynamics d = EvaluatePosture(RobotModel::Build(description, WithValues(base, u, values)), q, po);
    const Eigen::Index total = all_lines.size();
    std::vector<Eigen::Index> peaks;
    for (const Mode& m : d.modes) {
      if (total == 0 || m.freq_hz < all_lines(0) || m.freq_hz > all_lines(total - 1)) continue;
      Eigen::Index best = 0;
      (all_lines.array() - m.freq_hz).abs().minCoeff(&best);
      peaks.push_back(best);
    }
    const Eigen::Index room = std::max<Eigen::Index>(2, max_lines - static_cast<Eigen::Index>(peaks.size()));
    const Eigen::Index stride = std::max<Eigen::Index>(1, (total + room - 1) / room);
    for (Eigen::Index i = 0; i < total; i += stride) chosen.insert(i);
    if (total > 0) chosen.insert(total - 1);
    for (Eigen::Index i : peaks) chosen.insert(i);
    // Over the budget (many modes): drop strided lines, never a peak's.
    for (auto it = chosen.begin(); static_cast<int>(chosen.size()) > max_lines && it != chosen.end();) {
      const bool peak = std::find(peaks.begin(), peaks.end(), *it) != peaks.end();
      it = peak || *it == 0 ? std::next(it) : chosen.erase(it);
    }
  }
  Eigen::VectorXd freq_hz(static_cast<Eigen::Index>(chosen.size()));
  {
    Eigen::Index k = 0;
    for (Eigen::Index i : chosen) freq_hz(k++) = all_lines(i);
  }
  const Eigen::Index n = freq_hz.size();
  auto outputs = [&](const Eigen::VectorXd& values) {
    const auto model = RobotModel::Build(description, WithValues(base, u, values));
    const ReceptanceEvaluator h(EvaluatePosture(model, q, po));
    Eigen::VectorXd out(3 * n);
    for (int a = 0; a < 3; ++a) out.segment(a * n, n) = h.Entry(freq_hz, a, a).cwiseAbs().array().log().matrix();
    return out;
  };
  std::vector<std::string> names;
  for (int a = 0; a < 3; ++a) {
    for (Eigen::Index i = 0; i < n; ++i) {
      names.push_back(std::string("|H") + "xyz"[a] + "xyz"[a] + "| at " + FormatNumber(freq_hz(i), 4) + " Hz");
    }
  }
  ReceptanceBand b;
  b.freq_hz = freq_hz;
  b.propagation = Propagate(u, outputs, options, names);
  for (int a = 0; a < 3; ++a) {
    b.magnitude[a].resize(n);
    b.lower[a].resize(n);
    b.upper[a].resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const OutputInterval& o = b.propagation.outputs[static_cast<size_t>(a * n + i)];
      b.magnitude[a](i) = std::exp(o.value);
      b.lower[a](i) = std::exp(o.lower);
      b.upper[a](i) = std::exp(o.upper);
    }
  }
  return b;
}

std::string UseEstimates(const ParameterUncertainty& u, ParameterSet* parameters) {
  Eigen::VectorXd values(static_cast<Eigen::Index>(u.parameters.size()));
  std::string changed;
  for (size_t i = 0; i < u.parameters.size(); ++i) {
    values(static_cast<Eigen::Index>(i)) = u.parameters[i].value;
  }
  const ParameterSet updated = WithValues(*parameters, u, values);
  for (const UncertainParameter& p : u.parameters) {
    const double before = parameters->Get(p.name);
    if (std::abs(before - p.value) > 1e-9 * std::max(std::abs(before), std::abs(p.value))) {
      changed += (changed.empty() ? "" : ", ") + p.name + " " + FormatNumber(before, 4) + " -> " +
                 FormatNumber(p.value, 4);
    }
  }
  *parameters = updated;
  return changed.empty() ? changed : "the uncertainty's estimates replace the config's values: " + changed;
}

std::string IntervalLine(const std::string& pose_id, const PostureModeIntervals& intervals, double confidence) {
  std::string line = pose_id + ": " + FormatNumber(100.0 * confidence, 3) + " % intervals (" +
                     ToString(intervals.propagation.method_used) + ")";
  for (size_t k = 0; k < std::min<size_t>(3, intervals.modes.size()); ++k) {
    const OutputInterval& f = intervals.modes[k].freq_hz;
    line += std::string(k ? "," : ":") + " mode " + std::to_string(k + 1) + " " + FormatNumber(f.value, 4) +
            " Hz [" + FormatNumber(f.lower, 4) + ", " + FormatNumber(f.upper, 4) + "]";
  }
  return line;
}

}  // namespace robomach::dynamics
