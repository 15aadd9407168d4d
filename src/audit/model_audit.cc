#include "robomach/audit/model_audit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <mutex>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::audit {

void CheckValid(const AuditOptions& o) {
  if (o.calibration_parameters.empty()) throw std::invalid_argument("AuditOptions::calibration_parameters is empty");
  if (!(o.fmin_hz >= 0.0) || !(o.fmax_hz > o.fmin_hz)) {
    throw std::invalid_argument("AuditOptions: need 0 <= fmin_hz < fmax_hz, got fmin_hz = " +
                                std::to_string(o.fmin_hz) + ", fmax_hz = " + std::to_string(o.fmax_hz));
  }
  if (o.num_bands < 1) throw std::invalid_argument("AuditOptions::num_bands must be >= 1, got " +
                                                   std::to_string(o.num_bands));
  if (!(o.significance_factor > 1.0) || !(o.explained_factor > 1.0)) {
    throw std::invalid_argument("AuditOptions: significance_factor and explained_factor must be > 1");
  }
  if (o.max_iterations < 1) throw std::invalid_argument("AuditOptions::max_iterations must be >= 1");
  if (o.fit_line_stride < 1) throw std::invalid_argument("AuditOptions::fit_line_stride must be >= 1");
  if (o.threads < 1) throw std::invalid_argument("AuditOptions::threads must be >= 1");
}

double Bic(double rss, int n, int k) {
  return n * std::log(rss / n) + k * std::log(static_cast<double>(n));
}

ModelErrors ComputeErrors(const std::shared_ptr<const dynamics::RobotModel>& model,
                          const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                          double fmin_hz, double fmax_hz, int num_bands) {
  ModelErrors out;
  dynamics::PostureEvaluator eval(model);
  for (const std::string& pose : measured.pose_ids()) {
    const auto q = postures.find(pose);
    if (q == postures.end()) throw std::invalid_argument("measured posture " + pose + " is not in the posture set");
    const dynamics::ReceptanceEvaluator H(eval.Evaluate(q->second));
    for (const auto& [key, full] : measured.ForPose(pose)) {
      const dynamics::Frf frf = full.Band(fmin_hz, fmax_hz);
      CurveError c;
      c.key = key;
      if (frf.size() == 0) {
        out.curves.push_back(c);
        continue;
      }
      const Eigen::VectorXcd hm =
          H.Entry(frf.freq_hz(), static_cast<int>(key.response), static_cast<int>(key.excitation));
      Eigen::VectorXd r(frf.size());
      for (int i = 0; i < frf.size(); ++i) r(i) = std::log(std::abs(hm(i))) - std::log(std::abs(frf.receptance()(i)));
      c.lines = frf.size();
      c.rms_log_mag = std::sqrt(r.squaredNorm() / c.lines);
      out.rss += r.squaredNorm();
      out.lines += c.lines;
      // Bands equal on a log-frequency axis (the modes spread over decades).
      const double f0 = std::max(frf.freq_hz()(0), 1e-3), f1 = frf.freq_hz()(frf.size() - 1);
      for (int b = 0; b < num_bands; ++b) {
        BandError be;
        be.fmin_hz = f0 * std::pow(f1 / f0, static_cast<double>(b) / num_bands);
        be.fmax_hz = f0 * std::pow(f1 / f0, static_cast<double>(b + 1) / num_bands);
        double s = 0.0;
        for (int i = 0; i < frf.size(); ++i) {
          const double f = frf.freq_hz()(i);
          if (f >= be.fmin_hz && (f < be.fmax_hz || (b == num_bands - 1 && f <= be.fmax_hz))) {
            s += r(i) * r(i);
            ++be.lines;
          }
        }
        if (be.lines == 0) continue;
        be.rms_log_mag = std::sqrt(s / be.lines);
        c.bands.push_back(be);
      }
      std::sort(c.bands.begin(), c.bands.end(),
                [](const BandError& a, const BandError& b) { return a.rms_log_mag > b.rms_log_mag; });
      out.curves.push_back(c);
    }
  }
  out.total_rms_log_mag = out.lines > 0 ? std::sqrt(out.rss / out.lines) : NAN;
  return out;
}

double EstimateNoiseFloor(const dynamics::FrfSet& measured, double fmin_hz, double fmax_hz) {
  std::vector<double> d;
  for (const auto& [key, full] : measured) {
    const dynamics::Frf frf = full.Band(fmin_hz, fmax_hz);
    for (int i = 1; i + 1 < frf.size(); ++i) {
      const auto L = [&](int j) { return std::log(std::abs(frf.receptance()(j))); };
      d.push_back(std::abs(L(i - 1) - 2.0 * L(i) + L(i + 1)));
    }
  }
  if (d.empty()) return NAN;
  auto mid = d.begin() + d.size() / 2;
  std::nth_element(d.begin(), mid, d.end());
  // median |N(0, σ_d)| = 0.6745 σ_d, σ_d = √6 s.
  return *mid / (0.6745 * std::sqrt(6.0));
}

std::string CandidateResult::name() const {
  std::string s;
  for (const auto& e : effects) s += (s.empty() ? "" : "+") + e;
  return s;
}

std::pair<dynamics::RobotDescription, dynamics::ParameterSet> WithEffect(
    const dynamics::RobotDescription& description, const dynamics::ParameterSet& base, const std::string& effect) {
  dynamics::RobotDescription d = description;
  d.effects.push_back({effect, {}});
  dynamics::ParameterSet p = dynamics::DefaultParameters(d);
  for (const auto& s : base.specs()) p.Set(s.name, base.Get(s.name));
  return {d, p};
}

std::string EffectYaml(const CandidateResult& c) {
  std::ostringstream out;
  out.precision(6);
  out << "effects:\n";
  for (const std::string& e : c.effects) {
    out << "  - name: " << e << "\n";
    const std::string prefix = e + ".";
    for (const auto& est : c.fit.estimates) {
      if (est.name.rfind(prefix, 0) == 0) out << "    " << est.name.substr(prefix.size()) << ": " << est.value << "\n";
    }
  }
  return out.str();
}

namespace {

// Fittable parameters that `effect` adds, prefixed.
std::vector<std::string> FittableOf(const std::string& effect) {
  std::vector<std::string> names;
  for (const auto& s : dynamics::EffectRegistry::Instance().Create(effect)->parameters()) {
    if (s.fittable) names.push_back(effect + "." + s.name);
  }
  return names;
}

calibration::CalibrationOptions FitOptions(const AuditOptions& o, std::vector<std::string> free) {
  calibration::CalibrationOptions c;
  c.objective = calibration::Objective::kWholeCurve;
  c.free_parameters = std::move(free);
  c.fmin_hz = o.fmin_hz;
  c.fmax_hz = o.fmax_hz;
  c.modal_fit.fmin_hz = o.fmin_hz;
  c.modal_fit.fmax_hz = o.fmax_hz;
  c.max_iterations = o.max_iterations;
  return c;
}

// Sum of squared whole-curve residuals |ln(H_model / H_measured)|² (log
// magnitude and phase, as the calibration's whole-curve objective) over all
// lines of `data`; +inf if the model cannot be built or evaluated there.
double WholeCurveCost(const dynamics::RobotDescription& desc, const dynamics::ParameterSet& params,
                      const calibration::PostureMap& postures, const dynamics::FrfSet& data, double fmin_hz,
                      double fmax_hz) {
  try {
    const auto model = dynamics::RobotModel::Build(desc, params);
    dynamics::PostureEvaluator eval(model);
    double cost = 0.0;
    for (const std::string& pose : data.pose_ids()) {
      const dynamics::PostureDynamics d = eval.Evaluate(postures.at(pose));
      for (const auto& [key, frf] : data.ForPose(pose)) {
        const int n = frf.Band(fmin_hz, fmax_hz).size();
        if (n > 0) cost += n * std::pow(calibration::WholeCurveError(d, key, frf, fmin_hz, fmax_hz), 2);
      }
    }
    return std::isfinite(cost) ? cost : std::numeric_limits<double>::infinity();
  } catch (const std::exception&) {
    return std::numeric_limits<double>::infinity();
  }
}

// Trial values of one effect parameter for the start-value scan: a
// log-spaced grid over its bounds (factor ≈ 2 between points, at most
// kScanPoints), or for a parameter that may be zero, zero and a log grid
// over 1e-3..1e3 times its default.
std::vector<double> ScanGrid(const dynamics::ParameterSpec& s, double current) {
  constexpr int kScanPoints = 25;
  double lo = s.lower, hi = s.upper;
  std::vector<double> grid;
  if (!(lo > 0.0)) {
    grid.push_back(std::max(lo, 0.0));
    const double ref = current > 0.0 ? current : s.default_value;
    if (!(ref > 0.0)) return grid;
    lo = std::max(ref * 1e-3, lo);
    hi = std::min(ref * 1e3, hi);
  }
  if (!(hi > lo) || !std::isfinite(hi)) return grid;
  const int n = std::clamp(static_cast<int>(std::ceil(std::log2(hi / lo))) + 1, 3, kScanPoints);
  for (int i = 0; i < n; ++i) grid.push_back(lo * std::pow(hi / lo, static_cast<double>(i) / (n - 1)));
  return grid;
}

// Start values for an added effect's parameters. Fitting an FRF is
// multimodal: from the library defaults a local fit can explain a peak with
// the wrong mode (a flange's torsion or lateral spring instead of its
// bending) and stop there; so can a coordinate-wise scan that takes the
// parameters in a fixed order. Best-first instead: scan every added
// parameter over its grid from the current point, apply only the single
// move that lowers the whole-curve cost most, and repeat (a few rounds);
// the joint fit then refines from the right basin.
dynamics::ParameterSet ScanStart(const dynamics::RobotDescription& desc, dynamics::ParameterSet params,
                                 const std::vector<std::string>& added, const calibration::PostureMap& postures,
                                 const dynamics::FrfSet& data, const AuditOptions& o) {
  constexpr int kRounds = 3;
  double best = WholeCurveCost(desc, params, postures, data, o.fmin_hz, o.fmax_hz);
  for (int round = 0; round < kRounds; ++round) {
    std::string best_name;
    double best_value = 0.0;
    for (const std::string& name : added) {
      const double start = params.Get(name);
      for (double v : ScanGrid(params.spec(name), start)) {
        if (v == start) continue;
        dynamics::ParameterSet trial = params;
        trial.Set(name, v);
        const double c = WholeCurveCost(desc, trial, postures, data, o.fmin_hz, o.fmax_hz);
        if (c < best) {
          best = c;
          best_name = name;
          best_value = v;
        }
      }
    }
    if (best_name.empty()) break;
    // Refine the move between its grid neighbours (golden section in the
    // logarithm, or linearly for a grid that starts at zero).
    {
      const std::vector<double> grid = ScanGrid(params.spec(best_name), params.Get(best_name));
      const auto it = std::find(grid.begin(), grid.end(), best_value);
      const size_t k = static_cast<size_t>(it - grid.begin());
      const double lo = k > 0 ? grid[k - 1] : best_value, hi = k + 1 < grid.size() ? grid[k + 1] : best_value;
      const bool log_axis = lo > 0.0;
      const auto cost_at = [&](double u) {
        dynamics::ParameterSet trial = params;
        trial.Set(best_name, log_axis ? std::exp(u) : u);
        return WholeCurveCost(desc, trial, postures, data, o.fmin_hz, o.fmax_hz);
      };
      double a = log_axis ? std::log(lo) : lo, b = log_axis ? std::log(hi) : hi;
      const double g = 0.5 * (std::sqrt(5.0) - 1.0);
      double c = b - g * (b - a), d = a + g * (b - a), fc = cost_at(c), fd = cost_at(d);
      for (int it2 = 0; it2 < 12; ++it2) {
        if (fc < fd) {
          b = d; d = c; fd = fc; c = b - g * (b - a); fc = cost_at(c);
        } else {
          a = c; c = d; fc = fd; d = a + g * (b - a); fd = cost_at(d);
        }
      }
      const double u = fc < fd ? c : d, fu = std::min(fc, fd);
      if (fu < best) {
        best = fu;
        best_value = std::clamp(log_axis ? std::exp(u) : u, params.spec(best_name).lower, params.spec(best_name).upper);
      }
    }
    params.Set(best_name, best_value);
  }
  return params;
}

CandidateResult FitCandidate(const dynamics::RobotDescription& base_desc, const dynamics::ParameterSet& start,
                             const std::vector<std::string>& base_effects_added, const std::string& effect,
                             const std::vector<std::string>& base_free, const calibration::PostureMap& postures,
                             const dynamics::FrfSet& fit_data, const dynamics::FrfSet& measured,
                             const calibration::MeasuredFeatures& features,
                             const AuditOptions& o, double baseline_bic) {
  CandidateResult c;
  c.effects = base_effects_added;
  c.effects.push_back(effect);
  auto [desc, params] = WithEffect(base_desc, start, effect);
  std::vector<std::string> free = base_free;
  const std::vector<std::string> added = FittableOf(effect);
  free.insert(free.end(), added.begin(), added.end());
  c.added_parameters = static_cast<int>(free.size() - o.calibration_parameters.size());
  try {
    params = ScanStart(desc, params, added, postures, fit_data, o);
    c.fit = calibration::Calibrate(desc, params, postures, fit_data, features, FitOptions(o, free));
    c.errors = ComputeErrors(dynamics::RobotModel::Build(desc, c.fit.parameters), postures, measured, o.fmin_hz,
                             o.fmax_hz, o.num_bands);
  } catch (const std::runtime_error& e) {
    // Numerical trouble in one candidate (e.g. an eigensolver failing at an
    // extreme parameter value) is that candidate's status, not the audit's end.
    c.fit.status = calibration::FitStatus::kFailed;
    c.fit.message = e.what();
    c.note = std::string("fit failed: ") + e.what();
    c.bic = c.bic_change = std::numeric_limits<double>::infinity();
    c.errors.total_rms_log_mag = NAN;
    return c;
  }
  c.bic = Bic(c.errors.rss, c.errors.lines, static_cast<int>(free.size()));
  c.bic_change = c.bic - baseline_bic;
  c.plausible = c.fit.status == calibration::FitStatus::kConverged;
  if (!c.plausible) c.note = "fit " + calibration::FitStatusName(c.fit.status) + ": " + c.fit.message;
  for (const auto& e : c.fit.estimates) {
    bool is_effect = false;
    for (const auto& eff : c.effects) is_effect |= e.name.rfind(eff + ".", 0) == 0;
    if (is_effect && e.at_bound) {
      c.plausible = false;
      c.note += (c.note.empty() ? "" : "; ") + e.name + " pinned at a bound";
    }
  }
  return c;
}

// Every stride-th line of each FRF (coherence dropped: the fits do not use it).
dynamics::FrfSet Decimate(const dynamics::FrfSet& in, int stride) {
  if (stride == 1) return in;
  dynamics::FrfSet out;
  for (const auto& [key, frf] : in) {
    const int n = (frf.size() + stride - 1) / stride;
    Eigen::VectorXd f(n);
    Eigen::VectorXcd h(n);
    for (int i = 0; i < n; ++i) {
      f(i) = frf.freq_hz()(i * stride);
      h(i) = frf.receptance()(i * stride);
    }
    out.Insert(key, dynamics::Frf::FromSamples(f, h));
  }
  return out;
}

// Runs fit(i) for i in [0, n) on up to `threads` threads; results in order.
std::vector<CandidateResult> RunAll(int n, int threads, const std::function<CandidateResult(int)>& fit) {
  std::vector<CandidateResult> out(n);
  for (int start = 0; start < n; start += threads) {
    std::vector<std::future<CandidateResult>> batch;
    for (int i = start; i < std::min(n, start + threads); ++i) batch.push_back(std::async(std::launch::async, fit, i));
    for (int i = 0; i < static_cast<int>(batch.size()); ++i) out[start + i] = batch[i].get();
  }
  return out;
}

}  // namespace

AuditResult RunAudit(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                     const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                     const AuditOptions& o) {
  CheckValid(o);
  const auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  std::vector<std::string> candidates = o.candidates;
  if (candidates.empty()) {
    for (const std::string& n : dynamics::EffectRegistry::Instance().Names()) {
      bool present = false;
      for (const auto& e : description.effects) present |= e.name == n;
      if (!present) candidates.push_back(n);
    }
  }
  for (const std::string& n : candidates) {
    for (const auto& e : description.effects) {
      if (e.name == n) throw std::invalid_argument("candidate effect '" + n + "' is already in the model");
    }
    dynamics::EffectRegistry::Instance().Create(n);  // throws for an unknown name
  }

  AuditResult r;
  r.noise_floor = EstimateNoiseFloor(measured, o.fmin_hz, o.fmax_hz);
  const calibration::CalibrationOptions base_opt = FitOptions(o, o.calibration_parameters);
  say("modal fit of " + std::to_string(measured.size()) + " measured FRFs");
  const calibration::MeasuredFeatures features = calibration::ExtractFeatures(measured, base_opt.modal_fit);
  say("calibrating the current model (whole curve)");
  // Effect parameters among the calibration parameters (an effect switched
  // on with defaults) are fitted in a second step from the calibrated core,
  // as the candidates are: in one step from the defaults the whole-curve fit
  // was seen to stop at twice the noise floor (iteration limit), which a
  // candidate effect then "explained".
  std::vector<std::string> core;
  for (const auto& n : o.calibration_parameters) {
    if (n.find('.') == std::string::npos) core.push_back(n);
  }
  if (!core.empty() && core.size() < o.calibration_parameters.size()) {
    const calibration::CalibrationResult first =
        calibration::Calibrate(description, parameters, postures, measured, features, FitOptions(o, core));
    r.baseline_fit = calibration::Calibrate(description, first.parameters, postures, measured, features, base_opt);
  } else {
    r.baseline_fit = calibration::Calibrate(description, parameters, postures, measured, features, base_opt);
  }
  const auto base_model = dynamics::RobotModel::Build(description, r.baseline_fit.parameters);
  r.errors_before = ComputeErrors(base_model, postures, measured, o.fmin_hz, o.fmax_hz, o.num_bands);
  r.modes_before = calibration::CompareWithMeasurement(base_model, postures, measured, features, base_opt.matching,
                                                       o.fmin_hz, o.fmax_hz);
  r.baseline_bic = Bic(r.errors_before.rss, r.errors_before.lines, static_cast<int>(o.calibration_parameters.size()));
  r.significant_failure = !(r.errors_before.total_rms_log_mag <= o.significance_factor * r.noise_floor);
  {
    std::ostringstream m;
    m.precision(3);
    m << "error before " << r.errors_before.total_rms_log_mag << ", noise floor " << r.noise_floor
      << (r.significant_failure ? ": significant failure" : ": consistent with the noise");
    say(m.str());
  }
  if (!r.significant_failure && o.rank_only_if_failing) {
    r.explained = true;
    r.verdict = "the model agrees with the measurement within the noise floor; no effect is missing";
    return r;
  }
  const auto explains = [&](const CandidateResult& c) {
    return c.errors.total_rms_log_mag <= o.explained_factor * r.noise_floor;
  };
  const auto by_bic = [](const CandidateResult& a, const CandidateResult& b) { return a.bic < b.bic; };

  const dynamics::FrfSet fit_data = Decimate(measured, o.fit_line_stride);
  std::mutex say_mutex;
  const auto timed = [&](const std::function<CandidateResult()>& f) {
    const auto t0 = std::chrono::steady_clock::now();
    CandidateResult c = f();
    std::ostringstream m;
    m.precision(3);
    m << "candidate " << c.name() << ": error " << c.errors.total_rms_log_mag << ", BIC change " << c.bic_change
      << " (" << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s)";
    std::lock_guard<std::mutex> lock(say_mutex);
    say(m.str());
    return c;
  };
  say("fitting " + std::to_string(candidates.size()) + " candidate effects");
  std::vector<CandidateResult> singles =
      RunAll(static_cast<int>(candidates.size()), o.threads, [&](int i) {
        return timed([&] {
          return FitCandidate(description, r.baseline_fit.parameters, {}, candidates[i], o.calibration_parameters,
                              postures, fit_data, measured, features, o, r.baseline_bic);
        });
      });
  std::sort(singles.begin(), singles.end(), by_bic);
  r.candidates = singles;
  if (singles.empty()) {
    r.verdict = "no candidate effects to try";
    return r;
  }
  // The best single candidate is accepted if it lowers the BIC and is plausible.
  const CandidateResult& top = singles.front();
  if (top.bic_change < 0.0 && top.plausible) {
    r.best = 0;
    if (!explains(top) && o.greedy_second_round && singles.size() > 1) {
      auto [desc1, params1] = WithEffect(description, top.fit.parameters, top.effects[0]);
      std::vector<std::string> free1 = o.calibration_parameters;
      for (const auto& n : FittableOf(top.effects[0])) free1.push_back(n);
      std::vector<std::string> others;
      for (const std::string& n : candidates) {
        if (n != top.effects[0]) others.push_back(n);
      }
      say("greedy round: " + std::to_string(others.size()) + " effects on top of " + top.effects[0]);
      std::vector<CandidateResult> pairs = RunAll(static_cast<int>(others.size()), o.threads, [&](int i) {
        return timed([&] {
          return FitCandidate(desc1, top.fit.parameters, top.effects, others[i], free1, postures, fit_data, measured,
                              features, o, r.baseline_bic);
        });
      });
      std::sort(pairs.begin(), pairs.end(), by_bic);
      for (auto& p : pairs) r.candidates.push_back(p);
      if (!pairs.empty() && pairs.front().bic < top.bic && pairs.front().plausible) {
        r.best = static_cast<int>(singles.size());
      }
    }
  }
  if (r.best >= 0) {
    const CandidateResult& b = r.candidates[r.best];
    r.explained = explains(b);
    if (r.explained) {
      r.missing_effects = b.effects;
      r.verdict = "missing effect found: " + b.name();
    } else {
      std::ostringstream m;
      m.precision(3);
      m << "unexplained: the best candidate (" << b.name() << ") lowers the error to " << b.errors.total_rms_log_mag
        << " but not near the noise floor " << r.noise_floor << "; the failure is not attributed to it";
      r.verdict = m.str();
    }
  } else {
    r.verdict = "unexplained: no candidate effect lowers the BIC with plausible parameters";
  }
  return r;
}

}  // namespace robomach::audit
