// The audit's hypotheses beyond the effect library (issue #33): the model's
// own parameters freed (a joint stiffness that is off), and compliance
// anywhere along the chain (virtual joints), screened cheaply and the best
// fitted as candidates.
#include "audit/internal/hypotheses.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <iomanip>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "robomach/common/errors.h"
#include "robomach/common/parallel.h"
#include "robomach/dynamics/effect.h"

namespace robomach::audit::internal {

std::vector<std::string> DefaultParameterCandidates(const dynamics::ParameterSet& p) {
  std::vector<std::string> out;
  for (const auto& s : p.specs()) {
    if (s.name.rfind("kq", 0) == 0 && s.name.find('.') == std::string::npos) out.push_back(s.name);
  }
  return out;
}

CandidateResult FitParameterHypothesis(const dynamics::RobotDescription& desc, const dynamics::ParameterSet& start,
                                       const std::vector<std::string>& freed,
                                       const std::vector<std::string>& calibration, const FitContext& x) {
  const AuditOptions& o = x.options;
  CandidateResult c;
  c.parameters = freed;
  std::sort(c.parameters.begin(), c.parameters.end());  // kq2 before kq3 in every message
  std::vector<std::string> free = calibration;
  for (const std::string& n : freed) {
    if (!Contains(free, n)) free.push_back(n);
  }
  c.added_parameters = static_cast<int>(freed.size());
  try {
    // Start: the best-first scan of the freed parameters from the
    // calibrated model (it moves only where the whole-curve cost falls, so
    // the fit starts no worse than the calibrated model it contains).
    const dynamics::ParameterSet from = ScanStart(desc, start, freed, x.banded);
    c.start = "scan";
    c.fit = CalibrateWithRetry(desc, from, free, x);
  } catch (const NumericalError& e) {
    MarkFitFailed(e, &c);  // this hypothesis's row, not the audit's end
    return c;
  }
  c.errors = ComputeErrors(dynamics::RobotModel::Build(desc, c.fit.parameters), x.postures, x.measured, o.fmin_hz,
                           o.fmax_hz, o.num_bands);
  c.bic = Bic(c.errors.rss, c.errors.lines, static_cast<int>(free.size()));
  c.bic_change = c.bic - x.baseline_bic;
  c.plausible = c.fit.status == calibration::FitStatus::kConverged;
  if (!c.plausible) c.note = std::string("fit ") + ToString(c.fit.status) + ": " + c.fit.message;
  // A freed parameter on its bound (three decades from the configured
  // joint stiffness) has found no stiffness: the hypothesis stands in for
  // something else.
  for (const auto& e : c.fit.estimates) {
    if (!e.at_bound || !Contains(freed, e.name)) continue;
    c.plausible = false;
    c.pinned.push_back(e.name);
    std::ostringstream m;
    m.precision(3);
    m << e.name << " on its bound " << e.value;
    c.note += (c.note.empty() ? "" : "; ") + m.str();
  }
  return c;
}

std::vector<std::string> VirtualJointNames(const dynamics::RobotDescription& desc) {
  std::vector<std::string> out;
  const int n = desc.arm.num_joints();
  static const char* kAxes[] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  for (int place = 0; place <= n; ++place) {
    for (const char* axis : kAxes) {
      const std::string name =
          "virtual_joint_" + (place == 0 ? std::string("base") : "link" + std::to_string(place)) + "_" + axis;
      try {
        dynamics::EffectRegistry::Instance().Create(name)->CheckApplicable(desc);
      } catch (const std::invalid_argument&) {
        continue;  // a rotation about a joint's own axis: the joint-stiffness hypothesis covers it
      }
      bool present = false;
      for (const auto& e : desc.effects) present |= e.name == name;
      if (!present) out.push_back(name);
    }
  }
  return out;
}

namespace {

// An orthonormal basis Q of the whole-curve residuals' sensitivity to the
// calibration parameters at `calibrated` (central differences in the
// logarithm; additive for a parameter at zero; residuals r0 there): the
// best linearised re-adjustment of them leaves r − Q Qᵀ r.
Eigen::MatrixXd CalibrationBasis(const dynamics::RobotDescription& desc, const dynamics::ParameterSet& calibrated,
                                 const std::vector<std::string>& calibration, const BandedFitData& banded,
                                 const Eigen::VectorXd& r0) {
  Eigen::MatrixXd J(r0.size(), static_cast<Eigen::Index>(calibration.size()));
  for (size_t j = 0; j < calibration.size(); ++j) {
    const std::string& name = calibration[j];
    const dynamics::ParameterSpec& spec = calibrated.spec(name);
    const double v = calibrated.Get(name);
    dynamics::ParameterSet lo = calibrated, hi = calibrated;
    double span;
    if (v > 0.0) {
      lo.SetClamped(name, v * std::exp(-1e-4));
      hi.SetClamped(name, v * std::exp(1e-4));
      span = std::log(hi.Get(name) / lo.Get(name));
    } else {
      hi.SetClamped(name, v + 1e-4 * std::max(std::abs(spec.default_value), 1e-12));
      span = hi.Get(name) - v;
    }
    const Eigen::VectorXd a = WholeCurveResidualVector(desc, lo, banded);
    const Eigen::VectorXd b = WholeCurveResidualVector(desc, hi, banded);
    J.col(static_cast<Eigen::Index>(j)) =
        a.size() == r0.size() && b.size() == r0.size() && span > 0.0 ? Eigen::VectorXd((b - a) / span)
                                                                     : Eigen::VectorXd::Zero(r0.size());
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(J);
  return qr.householderQ() * Eigen::MatrixXd::Identity(J.rows(), J.cols());
}

}  // namespace

std::vector<ScreenedVirtualJoint> ScreenVirtualJoints(const dynamics::RobotDescription& desc,
                                                      const dynamics::ParameterSet& calibrated,
                                                      const std::vector<std::string>& calibration,
                                                      const FitContext& x, double* baseline) {
  std::vector<ScreenedVirtualJoint> out;
  *baseline = NAN;
  const Eigen::VectorXd r0 = WholeCurveResidualVector(desc, calibrated, x.banded);
  if (r0.size() == 0 || !(x.noise_floor > 0.0)) return out;
  // The linearised re-adjustment of the calibration parameters every
  // screened value gets.
  const Eigen::MatrixXd Q = CalibrationBasis(desc, calibrated, calibration, x.banded, r0);
  // The cost after the best linearised step of the calibration parameters:
  // |r − Q Qᵀ r|², r the residuals with the virtual joint at one stiffness.
  const auto projected = [&](const Eigen::VectorXd& r) { return (r - Q * (Q.transpose() * r)).squaredNorm(); };
  *baseline = std::sqrt(projected(r0) / static_cast<double>(r0.size())) / x.noise_floor;
  const std::vector<std::string> names = VirtualJointNames(desc);
  out.resize(names.size());
  ParallelForOptions po;
  po.threads = x.options.threads;
  po.chunk_size = 1;
  ParallelFor(
      0, static_cast<long>(names.size()),
      [&](long i, int) {
        ScreenedVirtualJoint& s = out[static_cast<size_t>(i)];
        s.effect = names[static_cast<size_t>(i)];
        const auto [d, p] = dynamics::WithEffect(desc, calibrated, s.effect);
        const std::string param = FittableOf(s.effect).at(0);
        const dynamics::ParameterSpec& spec = p.spec(param);
        // A factor of 4 between trial stiffnesses over the whole range: a
        // virtual joint's mode moves by a factor of 2 in frequency between
        // neighbours, so one of them lands within a factor of √2 of any
        // stiffness that matters.
        double best = std::numeric_limits<double>::infinity(), best_k = NAN;
        for (double k = spec.lower; k <= spec.upper * 1.0001; k *= 4.0) {
          dynamics::ParameterSet trial = p;
          trial.SetClamped(param, k);
          const Eigen::VectorXd r = WholeCurveResidualVector(d, trial, x.banded);
          if (r.size() != r0.size()) continue;
          const double c = projected(r);
          if (c < best) best = c, best_k = k;
        }
        s.stiffness = best_k;
        // rms whole-curve residual (log magnitude and phase chord) in units
        // of the noise floor.
        s.predicted_error = std::sqrt(best / static_cast<double>(r0.size())) / x.noise_floor;
      },
      po);
  std::stable_sort(out.begin(), out.end(), [](const ScreenedVirtualJoint& a, const ScreenedVirtualJoint& b) {
    return a.predicted_error < b.predicted_error;
  });
  return out;
}

namespace {

// min |b + A w|² subject to |w| <= c: the trust-region subproblem, through
// the SVD of A (w(λ) = −V diag(s / (s² + λ)) Uᵀ b, |w(λ)| decreasing in λ).
Eigen::VectorXd ConstrainedStep(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, double c) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  const Eigen::VectorXd g = svd.matrixU().transpose() * b;
  const double tol = s.size() > 0 ? 1e-12 * s(0) : 0.0;
  const auto step = [&](double lambda) {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(s.size());
    for (Eigen::Index k = 0; k < s.size(); ++k) {
      if (s(k) > tol || lambda > 0.0) y(k) = -s(k) * g(k) / (s(k) * s(k) + lambda);
    }
    return Eigen::VectorXd(svd.matrixV() * y);
  };
  Eigen::VectorXd w = step(0.0);
  if (w.norm() <= c) return w;
  double lo = 0.0, hi = s.size() > 0 ? std::max(s(0) * s(0), 1e-300) : 1.0;
  while (step(hi).norm() > c && hi < 1e300) hi *= 10.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (step(mid).norm() > c ? lo : hi) = mid;
  }
  return step(hi);
}

// The parameters of the uncertainty the audit can move (indices into
// u.parameters), their names in a->parameters; the others, with the reason,
// in a->left_out.
std::vector<int> MovableParameters(const dynamics::ParameterSet& calibrated, const dynamics::ParameterUncertainty& u,
                                   const AuditOptions& o, UncertaintyAllowance* a) {
  std::vector<int> kept;
  for (size_t i = 0; i < u.parameters.size(); ++i) {
    const std::string& n = u.parameters[i].name;
    if (!calibrated.Has(n)) {
      a->left_out.push_back(n + ": not a parameter of this model");
    } else if (Contains(o.calibration_parameters, n)) {
      a->left_out.push_back(n + ": calibrated by the audit against these data");
    } else {
      kept.push_back(static_cast<int>(i));
      a->parameters.push_back(n);
    }
  }
  return kept;
}

// The confidence region of the parameters moved, in whitened coordinates
// θ = θ̂ + B w, |w| <= radius, and the model's parameters at a point w: the
// search and the refit both map through it.
struct WhitenedRegion {
  const dynamics::RobotDescription& desc;
  const dynamics::ParameterSet& calibrated;
  const std::vector<std::string>& names;  // the parameters moved, as in moved_u
  const BandedFitData& banded;
  dynamics::ParameterUncertainty moved_u;
  Eigen::VectorXd theta0;
  Eigen::MatrixXd B;
  int rank = 0;
  double radius = NAN;

  dynamics::ParameterSet Point(const Eigen::VectorXd& w) const {
    dynamics::ParameterSet p = calibrated;
    const Eigen::VectorXd v = dynamics::FromTheta(moved_u, theta0 + B * w);
    for (int i = 0; i < static_cast<int>(names.size()); ++i) {
      // A compliance <= 0 is an infinite stiffness: the parameter's upper bound.
      p.SetClamped(names[i], std::isfinite(v(i)) ? v(i) : std::numeric_limits<double>::infinity());
    }
    return p;
  }
  Eigen::VectorXd Residuals(const Eigen::VectorXd& w) const {
    return WholeCurveResidualVector(desc, Point(w), banded);
  }
};

// The marginal of the parameters moved (a Gaussian's marginal: the
// sub-covariance), and their estimates.
dynamics::ParameterUncertainty Marginal(const dynamics::ParameterUncertainty& u, const std::vector<int>& kept,
                                        Eigen::VectorXd* estimates) {
  const int n = static_cast<int>(kept.size());
  dynamics::ParameterUncertainty moved_u;
  moved_u.covariance.resize(n, n);
  estimates->resize(n);
  for (int i = 0; i < n; ++i) {
    moved_u.parameters.push_back(u.parameters[kept[i]]);
    (*estimates)(i) = u.parameters[kept[i]].value;
    for (int j = 0; j < n; ++j) moved_u.covariance(i, j) = u.covariance(kept[i], kept[j]);
  }
  return moved_u;
}

// Whitened coordinates: θ = θ̂ + B w, B = V √Λ over the covariance's rank,
// the region |w| <= √χ²(P, rank). Sets r->B, r->rank, r->radius and a's
// rank, chi2 and radius; false (nothing set) if the covariance is zero.
bool Whiten(double confidence, WhitenedRegion* r, UncertaintyAllowance* a) {
  const Eigen::MatrixXd& cov = r->moved_u.covariance;
  const int n = static_cast<int>(cov.rows());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(cov);
  const double lmax = es.eigenvalues().maxCoeff();
  std::vector<int> axes;
  for (int k = 0; k < n; ++k) {
    if (es.eigenvalues()(k) > 1e-14 * lmax && es.eigenvalues()(k) > 0.0) axes.push_back(k);
  }
  if (axes.empty()) return false;
  a->rank = static_cast<int>(axes.size());
  Eigen::MatrixXd B(n, a->rank);
  for (int k = 0; k < a->rank; ++k) B.col(k) = es.eigenvectors().col(axes[k]) * std::sqrt(es.eigenvalues()(axes[k]));
  a->chi2 = dynamics::ChiSquaredQuantile(confidence, a->rank);
  a->radius = std::sqrt(a->chi2);
  r->B = std::move(B);
  r->rank = a->rank;
  r->radius = a->radius;
  return true;
}

// The most favourable point of the region: a few Gauss-Newton steps in w,
// each constrained to the region, on the residuals after the calibration
// parameters' linear re-adjustment (basis Q; r0 the residuals at w = 0).
Eigen::VectorXd MostFavourablePoint(const WhitenedRegion& region, const Eigen::MatrixXd& Q, const Eigen::VectorXd& r0) {
  const int rank = region.rank;
  const auto residuals = [&](const Eigen::VectorXd& w) { return region.Residuals(w); };
  const auto project = [&](const Eigen::MatrixXd& m) -> Eigen::MatrixXd { return m - Q * (Q.transpose() * m); };
  Eigen::VectorXd w = Eigen::VectorXd::Zero(rank);
  double best = project(r0).squaredNorm();
  for (int iteration = 0; iteration < 4; ++iteration) {
    const Eigen::VectorXd rw = residuals(w);
    if (rw.size() != r0.size()) break;
    Eigen::MatrixXd A(r0.size(), rank);
    constexpr double h = 0.05;  // in standard deviations along each axis
    bool ok = true;
    for (int k = 0; k < rank && ok; ++k) {
      Eigen::VectorXd wp = w, wm = w;
      wp(k) += h;
      wm(k) -= h;
      const Eigen::VectorXd rp = residuals(wp), rm = residuals(wm);
      ok = rp.size() == r0.size() && rm.size() == r0.size();
      if (ok) A.col(k) = (rp - rm) / (2.0 * h);
    }
    if (!ok) break;
    const Eigen::MatrixXd PA = project(A);
    const Eigen::VectorXd step = ConstrainedStep(PA, Eigen::VectorXd(project(rw) - PA * w), region.radius) - w;
    // A step the true cost does not accept is halved (the region is convex:
    // every point between w and the step's end lies in it).
    bool accepted = false;
    for (double f = 1.0; f > 0.05 && !accepted; f *= 0.5) {
      const Eigen::VectorXd next = w + f * step;
      const Eigen::VectorXd rn = residuals(next);
      if (rn.size() != r0.size()) continue;
      const double cost = project(rn).squaredNorm();
      if (cost < best * (1.0 - 1e-6)) {
        best = cost;
        w = next;
        accepted = true;
      }
    }
    if (!accepted) break;
  }
  return w;
}

// Words: whether the region covers the failure (or how much of it), the
// parameters that moved the most relative to their estimates, and how far
// into the region the point lies.
std::string AllowanceSentence(const UncertaintyAllowance& a, const Eigen::VectorXd& estimates, double error_before,
                              double noise_floor) {
  const int n = static_cast<int>(a.parameters.size());
  std::vector<std::pair<double, std::string>> moved;
  for (int i = 0; i < n; ++i) {
    const double v0 = estimates(i), v1 = a.at.Get(a.parameters[i]);
    const double rel = v0 != 0.0 ? v1 / v0 - 1.0 : v1 - v0;
    std::ostringstream m;
    m.precision(1);
    m << a.parameters[i] << ' ' << (rel >= 0 ? "+" : "") << std::fixed << 100.0 * rel << " %";
    moved.push_back({-std::abs(rel), m.str()});
  }
  std::sort(moved.begin(), moved.end());
  std::string names;
  for (size_t i = 0; i < a.parameters.size(); ++i) names += (i ? ", " : "") + a.parameters[i];
  std::ostringstream m;
  m.precision(3);
  const double pct = std::round(100.0 * a.confidence * 10.0) / 10.0;
  const double before_units = error_before / noise_floor;
  if (a.covers_failure) {
    m << "within the parameter uncertainty: with " << names << " inside " << (n == 1 ? "its " : "their ") << pct
      << " % confidence region the error falls from " << before_units << " to " << a.error_noise_units
      << " x the noise floor";
  } else {
    const double f = std::isfinite(a.fraction_removed) ? std::max(0.0, a.fraction_removed) : 0.0;
    m << "the uncertainty of " << names << " (" << pct << " % confidence region) explains " << std::fixed
      << std::setprecision(0) << 100.0 * f << " % of the excess misfit" << std::defaultfloat << std::setprecision(3)
      << " (error " << before_units << " -> " << a.error_noise_units
      << " x the noise floor at its most favourable point); the rest is a model error";
  }
  m << " (most moved: ";
  for (size_t i = 0; i < moved.size() && i < 3; ++i) m << (i ? ", " : "") << moved[i].second;
  m << "; Mahalanobis distance " << a.distance << " of " << a.radius << ")";
  return m.str();
}

}  // namespace

std::optional<UncertaintyAllowance> AllowanceOfUncertainty(const dynamics::RobotDescription& desc,
                                                           const dynamics::ParameterSet& calibrated,
                                                           const dynamics::ParameterUncertainty& u,
                                                           double confidence, const FitContext& x,
                                                           double error_before) {
  const AuditOptions& o = x.options;
  UncertaintyAllowance a;
  a.confidence = confidence;
  const std::vector<int> kept = MovableParameters(calibrated, u, o, &a);
  const int n = static_cast<int>(kept.size());
  auto nothing = [&](const std::string& why) {
    a.sentence = "the parameter uncertainty was not used: " + why;
    return a;
  };
  if (n == 0) {
    std::string l;
    for (const auto& s : a.left_out) l += (l.empty() ? "" : "; ") + s;
    return nothing("it has no parameter the audit can move (" + l + ")");
  }
  Eigen::VectorXd estimates;
  WhitenedRegion region{desc, calibrated, a.parameters, x.banded, Marginal(u, kept, &estimates), {}, {}};
  region.theta0 = dynamics::ToTheta(region.moved_u, estimates);
  if (!Whiten(confidence, &region, &a)) {
    a.parameters.clear();
    return nothing("its covariance is zero");
  }
  const Eigen::VectorXd r0 = region.Residuals(Eigen::VectorXd::Zero(a.rank));
  if (r0.size() == 0) {
    a.parameters.clear();
    return nothing("the model cannot be evaluated at its estimates");
  }
  // The calibration parameters' linear re-adjustment (as the screen's).
  const Eigen::MatrixXd Q = CalibrationBasis(desc, calibrated, o.calibration_parameters, x.banded, r0);
  const Eigen::VectorXd w = MostFavourablePoint(region, Q, r0);
  a.distance = w.norm();
  // The calibration refitted at the point: the error in the audit's own
  // measure (rms log magnitude over every line), comparable with error_before.
  const dynamics::ParameterSet start = region.Point(w);
  const calibration::CalibrationResult fit = CalibrateWithRetry(desc, start, o.calibration_parameters, x);
  a.at = fit.status == calibration::FitStatus::kFailed ? start : fit.parameters;
  a.errors = ComputeErrors(dynamics::RobotModel::Build(desc, a.at), x.postures, x.measured, o.fmin_hz, o.fmax_hz,
                           o.num_bands);
  a.error_noise_units = a.errors.total_rms_log_mag / x.noise_floor;
  a.fraction_removed = FractionRemoved(error_before, a.errors.total_rms_log_mag, x.noise_floor);
  const bool significant = !(error_before <= o.significance_factor * x.noise_floor);
  a.covers_failure = significant && a.errors.total_rms_log_mag <= o.significance_factor * x.noise_floor;

  a.sentence = AllowanceSentence(a, estimates, error_before, x.noise_floor);
  return a;
}


}  // namespace robomach::audit::internal
