#include "robomach/audit/model_audit.h"

#include "audit/internal/candidate_fit.h"
#include "audit/internal/hypotheses.h"
#include "audit/internal/verdict.h"

#include <algorithm>

#include <Eigen/SVD>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <mutex>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "robomach/audit/error_patterns.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/common/errors.h"
#include "robomach/common/golden_section.h"
#include "robomach/common/number_format.h"
#include "robomach/common/parallel.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/gravity_torque.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::audit {

void AuditOptions::Validate() const {
  // "AuditOptions::FIELD must be BOUND, got VALUE": a tool's ValidateOptions
  // puts its option in the field's place.
  const auto fail = [](const std::string& field, const std::string& bound, const std::string& value) {
    throw OptionError(field, "AuditOptions::" + field + " must be " + bound + ", got " + value);
  };
  const auto num = [](double v) { return std::to_string(v); };
  if (calibration_parameters.empty()) {
    throw OptionError("calibration_parameters",
                      "AuditOptions::calibration_parameters is empty: expected at least one parameter");
  }
  if (!(fmin_hz >= 0.0) || !(fmax_hz > fmin_hz)) {
    throw OptionError(fmin_hz >= 0.0 ? "fmax_hz" : "fmin_hz",
                      "AuditOptions: need 0 <= fmin_hz < fmax_hz, got fmin_hz = " + std::to_string(fmin_hz) +
                          ", fmax_hz = " + std::to_string(fmax_hz));
  }
  if (num_bands < 1) fail("num_bands", ">= 1", std::to_string(num_bands));
  if (!(significance_factor > 1.0)) fail("significance_factor", "> 1", num(significance_factor));
  if (!(explained_factor > 1.0)) fail("explained_factor", "> 1", num(explained_factor));
  if (!(mostly_explained_fraction > 0.0) || !(mostly_explained_fraction <= 1.0)) {
    fail("mostly_explained_fraction", "in (0, 1]", num(mostly_explained_fraction));
  }
  if (!(clear_bic_gap >= 0.0)) fail("clear_bic_gap", ">= 0", num(clear_bic_gap));
  if (max_iterations < 1) fail("max_iterations", ">= 1", std::to_string(max_iterations));
  if (fit_line_stride < 0) fail("fit_line_stride", ">= 0 (0: automatic)", std::to_string(fit_line_stride));
  if (!(identifiable_chi2 >= 0.0) || !std::isfinite(identifiable_chi2)) {
    fail("identifiable_chi2", "finite and >= 0", num(identifiable_chi2));
  }
  if (parameter_pairs_from < 0) fail("parameter_pairs_from", ">= 0", std::to_string(parameter_pairs_from));
  if (virtual_joints_fitted < 0) {
    fail("virtual_joints_fitted", ">= 0 (0: no virtual joints)", std::to_string(virtual_joints_fitted));
  }
  if (threads < 1) fail("threads", ">= 1", std::to_string(threads));
  if (!(robust_scale >= 0.0) || !std::isfinite(robust_scale)) {
    fail("robust_scale", ">= 0 (0: none)", num(robust_scale));
  }
  if (!(uncertainty_confidence > 0.0 && uncertainty_confidence < 1.0)) {
    fail("uncertainty_confidence", "in (0, 1)", num(uncertainty_confidence));
  }
  if (!parameter_uncertainty.parameters.empty()) {
    try {
      dynamics::CheckValid(parameter_uncertainty);
    } catch (const OptionError&) {
      throw;
    } catch (const std::invalid_argument& e) {
      throw OptionError("parameter_uncertainty", e.what());  // its text as it was
    }
  }
}

double Bic(double rss, int n, int k) {
  return n * std::log(rss / n) + k * std::log(static_cast<double>(n));
}

ModelErrors ComputeErrors(const std::shared_ptr<const dynamics::RobotModel>& model,
                          const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                          double fmin_hz, double fmax_hz, int num_bands) {
  ModelErrors out;
  dynamics::PostureEvaluator eval(model);
  // Bands equal on a log-frequency axis (the modes spread over decades),
  // the same for every FRF: over the lowest and highest line of all of them
  // in the band. (Per-FRF edges, from each FRF's own usable lines, made
  // every FRF's bands different, and the pattern's "the same band fails at
  // every posture" could never be seen on data with a noise model.)
  double f0 = std::numeric_limits<double>::infinity(), f1 = 0.0;
  for (const auto& [key, full] : measured) {
    const dynamics::Frf frf = full.Band(fmin_hz, fmax_hz);
    if (frf.size() == 0) continue;
    f0 = std::min(f0, std::max(frf.freq_hz()(0), 1e-3));
    f1 = std::max(f1, frf.freq_hz()(frf.size() - 1));
  }
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
      // Log-magnitude residuals, in units of their noise when the data carry
      // a noise model (LogResidualWeights; all ones otherwise).
      const Eigen::VectorXd w = calibration::LogResidualWeights(frf);
      Eigen::VectorXd r(frf.size());
      for (int i = 0; i < frf.size(); ++i) {
        r(i) = w(i) * (std::log(std::abs(hm(i))) - std::log(std::abs(frf.receptance()(i))));
      }
      c.lines = frf.size();
      c.rms_log_mag = std::sqrt(r.squaredNorm() / c.lines);
      out.rss += r.squaredNorm();
      out.lines += c.lines;
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
  // With a noise model the errors are in units of the noise already.
  bool all_noise = !measured.empty();
  for (const auto& [key, frf] : measured) all_noise = all_noise && frf.noise_sigma().has_value();
  if (all_noise) return 1.0;
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

using namespace internal;  // the audit's private stages

namespace {

// The baseline the user can trust (issue #33 §5): the model as configured,
// the calibration parameters the calibration left on a bound, and the model
// the where-it-fails pictures are drawn from.
void JudgeBaseline(const dynamics::RobotDescription& description, const dynamics::ParameterSet& configured,
                   const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                   const calibration::CalibrationOptions& base_opt, const AuditOptions& o, AuditResult* r) {
  const auto configured_model = dynamics::RobotModel::Build(description, configured);
  r->errors_configured = ComputeErrors(configured_model, postures, measured, o.fmin_hz, o.fmax_hz, o.num_bands);
  r->pictures_from = "calibrated";
  r->pictures_parameters = r->baseline_fit.parameters;
  for (const auto& e : r->baseline_fit.estimates) {
    if (!e.at_bound) continue;
    const dynamics::ParameterSpec& spec = r->baseline_fit.parameters.spec(e.name);
    BoundFlag f;
    f.name = e.name;
    f.value = e.value;
    f.lower = std::abs(e.value - spec.lower) <= std::abs(e.value - spec.upper);
    std::ostringstream m;
    m.precision(3);
    m << e.name << " on its " << (f.lower ? "lower" : "upper") << " bound " << e.value << " " << spec.unit
      << " (configured " << configured.Get(e.name) << "): the calibration is standing in for something missing";
    f.message = m.str();
    r->baseline_on_bound.push_back(f);
  }
  if (!r->baseline_on_bound.empty()) {
    // A calibration that ends on a bound has bent the model to mimic what
    // is missing (the demo's m6 at its lower bound 2.9 kg, d6 = 1.18 m,
    // 13-42 % frequency errors against 1.5 % as configured): the pictures
    // of where the model fails show the model as configured.
    r->pictures_from = "configured";
    r->pictures_parameters = configured;
    r->modes_before = calibration::CompareWithMeasurement(configured_model, postures, measured, r->features,
                                                          base_opt.matching, o.fmin_hz, o.fmax_hz);
  }
}


// The estimates of parameter_uncertainty must be the values audited: the
// allowance is computed around them. A parameter not in the model or
// calibrated here is left out (and said so).
void CheckUncertaintyEstimates(const dynamics::ParameterSet& parameters, const AuditOptions& options) {
  for (const auto& p : options.parameter_uncertainty.parameters) {
    if (!parameters.Has(p.name) || std::find(options.calibration_parameters.begin(),
                                             options.calibration_parameters.end(),
                                             p.name) != options.calibration_parameters.end()) {
      continue;  // left out, and said so (AuditResult::uncertainty)
    }
    const double v = parameters.Get(p.name);
    if (!(std::abs(v - p.value) <= 1e-9 * std::max(std::abs(p.value), 1e-300))) {
      throw std::invalid_argument("AuditOptions::parameter_uncertainty: the estimate of " + p.name + " (" +
                                  FormatNumber(p.value) + ") is not the audited value (" + FormatNumber(v) +
                                  "); put the estimates into the parameters first (dynamics::UseEstimates)");
    }
  }
}

// The effects to try as candidates, grown by the virtual-joint screen and
// the load-dependent stiffnesses.
struct CandidateLists {
  std::vector<std::string> effects;
  // The library's effects (the greedy round's second effects); the virtual
  // joints the screen picks join `effects` as single candidates only.
  std::vector<std::string> library;
  bool explicit_list{false};
};

// The candidate effects, and the parameter hypotheses in *o, from the
// options; every name checked.
CandidateLists ResolveCandidates(const dynamics::RobotDescription& description,
                                 const dynamics::ParameterSet& parameters, AuditOptions* opt) {
  AuditOptions& o = *opt;
  CandidateLists out;
  // An explicit candidate list is the whole list: its effects (virtual
  // joints included) and its model parameters (parameter hypotheses); the
  // virtual-joint screen and the default parameter hypotheses run only
  // when no list is given.
  std::vector<std::string>& candidates = out.effects;
  out.explicit_list = !o.candidates.empty();
  if (out.explicit_list) {
    std::vector<std::string> named_parameters;
    for (const std::string& n : o.candidates) {
      if (parameters.Has(n) && n.find('.') == std::string::npos) {
        named_parameters.push_back(n);
      } else {
        candidates.push_back(n);
      }
    }
    o.parameter_candidates = named_parameters;
    o.try_parameters = o.try_parameters && !named_parameters.empty();
    o.virtual_joints_fitted = 0;
  } else {
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
    dynamics::EffectRegistry::Instance().Create(n)->CheckApplicable(description);  // throws for an unknown name
  }
  for (const std::string& n : o.parameter_candidates) {
    if (!parameters.Has(n)) {
      throw std::invalid_argument("parameter hypothesis '" + n + "' is not a parameter of the model; its parameters: " +
                                  parameters.NameList());
    }
  }
  out.library = candidates;
  return out;
}

// The audit's inputs and its options (RunAudit's copy, as resolved),
// handed to every stage together.
struct AuditInputs {
  const dynamics::RobotDescription& description;
  const dynamics::ParameterSet& parameters;
  const calibration::PostureMap& postures;
  const dynamics::FrfSet& measured;
  const AuditOptions& o;  // CalibrateBaseline resolves its fit_line_stride

  void Say(const std::string& s) const {
    if (o.progress) o.progress(s);
  }
  // The free parameters besides an effect's own: the calibration
  // parameters, and kq_j for a load-dependent stiffness of joint j.
  std::vector<std::string> FreeFor(const std::string& effect) const {
    std::vector<std::string> free = o.calibration_parameters;
    if (effect.rfind("load_stiffness_j", 0) == 0) {
      const std::string kq = "kq" + effect.substr(16) + "_Nm_per_rad";
      if (parameters.Has(kq) && !Contains(free, kq)) free.push_back(kq);
    }
    return free;
  }
};

// Whether a candidate's error is within explained_factor of the noise floor.
bool Explains(const CandidateResult& c, const AuditOptions& o, double noise_floor) {
  return c.errors.total_rms_log_mag <= o.explained_factor * noise_floor;
}

// The ranking's order: lowest BIC first.
bool ByBic(const CandidateResult& a, const CandidateResult& b) { return a.bic < b.bic; }

// The baseline calibration when effects were switched on with --add (their
// parameters among the calibration parameters); sets r->baseline_fit.
void CalibrateWithAddedEffects(const AuditInputs& in, const std::vector<std::string>& core, AuditResult* r) {
  const dynamics::RobotDescription& description = in.description;
  const dynamics::ParameterSet& parameters = in.parameters;
  const calibration::PostureMap& postures = in.postures;
  const dynamics::FrfSet& measured = in.measured;
  const AuditOptions& o = in.o;
  const calibration::MeasuredFeatures& features = r->features;
  // Effects whose parameters are free (switched on with --add) are fitted
  // exactly as candidates are: the core calibrated without them, then
  // each added in turn by FitCandidate (scan, identifiability screen,
  // second start), then one polishing fit of everything. A plain fit from
  // the defaults stopped in wrong basins (a flange at 14 × the noise
  // floor, torsion on its bound; a spindle interface at 5 ×), and the
  // audit then blamed another effect for the rest.
  std::vector<std::string> added_effects;
  for (const auto& e : description.effects) {
    for (const auto& n : o.calibration_parameters) {
      if (n.rfind(e.name + ".", 0) == 0 &&
          std::find(added_effects.begin(), added_effects.end(), e.name) == added_effects.end()) {
        added_effects.push_back(e.name);
      }
    }
  }
  dynamics::RobotDescription core_desc = description;
  std::erase_if(core_desc.effects, [&](const dynamics::EffectConfig& e) {
    return std::find(added_effects.begin(), added_effects.end(), e.name) != added_effects.end();
  });
  dynamics::ParameterSet core_params = dynamics::DefaultParameters(core_desc);
  for (const auto& spec : core_params.specs()) core_params.Set(spec.name, parameters.Get(spec.name));
  const calibration::CalibrationResult core_fit =
      calibration::Calibrate(core_desc, core_params, postures, measured, features, FitOptions(o, core));
  const ModelErrors core_errors = ComputeErrors(dynamics::RobotModel::Build(core_desc, core_fit.parameters),
                                                postures, measured, o.fmin_hz, o.fmax_hz, o.num_bands);
  const dynamics::FrfSet fit_data = Decimate(measured, o.fit_line_stride);
  const BandedFitData banded = BandFitData(postures, fit_data, o.fmin_hz, o.fmax_hz);
  const FitContext added_context{postures,
                                 fit_data,
                                 measured,
                                 features,
                                 o,
                                 Bic(core_errors.rss, core_errors.lines, static_cast<int>(core.size())),
                                 r->noise_floor,
                                 core_errors.total_rms_log_mag,
                                 core_params,
                                 banded};
  dynamics::RobotDescription so_far = core_desc;
  dynamics::ParameterSet start = core_fit.parameters;
  std::vector<std::string> effects_so_far, free = core;
  for (const std::string& e : added_effects) {
    in.Say("fitting the added effect " + e + " (as a candidate)");
    const CandidateResult c = FitCandidate(so_far, start, effects_so_far, e, free, added_context);
    if (c.fit.status == calibration::FitStatus::kFailed && !std::isfinite(c.bic)) {
      // Reported, not fatal: the effect stays at its start values and the
      // audit goes on with the rest.
      r->warnings.push_back("the fit of the added effect " + e + " failed (" + c.fit.message +
                            "); it is kept at its start values");
      in.Say(r->warnings.back());
      auto [with_desc, with_params] = WithEffect(so_far, start, e);
      so_far = std::move(with_desc);
      start = std::move(with_params);
      effects_so_far.push_back(e);
      continue;
    }
    if (!c.note.empty()) in.Say(e + ": " + c.note);
    so_far = WithEffect(so_far, start, e).first;
    start = c.fit.parameters;
    effects_so_far.push_back(e);
    free = FreeAfter(free, e, c);
  }
  dynamics::ParameterSet polished_start = parameters;
  for (const auto& spec : start.specs()) {
    if (polished_start.Has(spec.name)) polished_start.Set(spec.name, start.Get(spec.name));
  }
  // The polish frees what the candidate fits left free: a calibration
  // parameter held for an exact trade-off and an effect parameter the data
  // cannot determine stay held (each candidate's note says which).
  std::vector<std::string> polish_free;
  for (const auto& n : o.calibration_parameters) {
    if (Contains(free, n)) polish_free.push_back(n);
  }
  calibration::CalibrationOptions polish_opt = FitOptions(o, polish_free);
  polish_opt.extra_starts = true;
  r->baseline_fit = calibration::Calibrate(description, polished_start, postures, measured, features, polish_opt);
}

// The first stage: the noise floor, the measured features (and from them
// the line stride, in *opt, the same options as in.o), the calibrated
// current model, its errors, the baseline judged, and whether it fails.
void CalibrateBaseline(const AuditInputs& in, AuditOptions* opt, AuditResult* r_out) {
  AuditOptions& o = *opt;
  AuditResult& r = *r_out;
  const dynamics::RobotDescription& description = in.description;
  const dynamics::ParameterSet& parameters = in.parameters;
  const calibration::PostureMap& postures = in.postures;
  const dynamics::FrfSet& measured = in.measured;
  r.noise_floor = EstimateNoiseFloor(measured, o.fmin_hz, o.fmax_hz);
  calibration::CalibrationOptions base_opt = FitOptions(o, o.calibration_parameters);
  // The baseline sets the error every candidate is judged against: it gets
  // the calibration's further starts (a poor baseline fit is a false alarm).
  base_opt.extra_starts = true;
  in.Say("modal fit of " + std::to_string(measured.size()) + " measured FRFs");
  r.features = calibration::ExtractFeatures(measured, base_opt.modal_fit);
  const calibration::MeasuredFeatures& features = r.features;
  if (o.fit_line_stride == 0) {
    o.fit_line_stride = AutoLineStride(measured, features);
    in.Say("fits use every " + (o.fit_line_stride == 1 ? std::string() : Ordinal(o.fit_line_stride) + " ") +
           "line (half-power bands of the measured modes)");
  }
  in.Say("calibrating the current model (whole curve)");
  std::vector<std::string> core;
  for (const auto& n : o.calibration_parameters) {
    if (n.find('.') == std::string::npos) core.push_back(n);
  }
  if (!core.empty() && core.size() < o.calibration_parameters.size()) {
    CalibrateWithAddedEffects(in, core, &r);
  } else {
    r.baseline_fit = calibration::Calibrate(description, parameters, postures, measured, features, base_opt);
  }
  const auto base_model = dynamics::RobotModel::Build(description, r.baseline_fit.parameters);
  r.errors_before = ComputeErrors(base_model, postures, measured, o.fmin_hz, o.fmax_hz, o.num_bands);
  r.modes_before = calibration::CompareWithMeasurement(base_model, postures, measured, features, base_opt.matching,
                                                       o.fmin_hz, o.fmax_hz);
  r.baseline_bic = Bic(r.errors_before.rss, r.errors_before.lines, static_cast<int>(o.calibration_parameters.size()));
  r.configured = parameters;
  JudgeBaseline(description, parameters, postures, measured, base_opt, o, &r);
  for (const BoundFlag& f : r.baseline_on_bound) in.Say(f.message);
  r.significant_failure = !(r.errors_before.total_rms_log_mag <= o.significance_factor * r.noise_floor);
  {
    std::ostringstream m;
    m.precision(3);
    m << "error before " << r.errors_before.total_rms_log_mag << ", noise floor " << r.noise_floor
      << (r.significant_failure ? ": significant failure" : ": consistent with the noise");
    in.Say(m.str());
  }
}

// Issue #37 §4: how much of the misfit the parameters' own uncertainty
// allows (only for a significant failure, and when asked).
void AllowUncertainty(const AuditInputs& in, const FitContext& context, AuditResult* r) {
  const AuditOptions& o = in.o;
  if (r->significant_failure && !o.parameter_uncertainty.parameters.empty()) {
    in.Say("the parameter uncertainty: the calibrated model at its most favourable point within the " +
           FormatNumber(100.0 * o.uncertainty_confidence) + " % region");
    r->uncertainty = AllowanceOfUncertainty(in.description, r->baseline_fit.parameters, o.parameter_uncertainty,
                                            o.uncertainty_confidence, context, r->errors_before.total_rms_log_mag);
    if (r->uncertainty && r->uncertainty->parameters.empty()) {
      r->warnings.push_back(r->uncertainty->sentence);  // asked for and not done: said, and the run flagged
    } else if (r->uncertainty) {
      in.Say(r->uncertainty->sentence);
    }
  }
}

// What the candidate fits share: the inputs, the fit context, and the
// progress message of each fit with its time (the fits run in parallel, so
// the messages are said one at a time).
struct CandidateFitter {
  CandidateFitter(const AuditInputs& in, const FitContext& context) : in(in), context(context) {}

  CandidateResult Timed(const std::function<CandidateResult()>& f) {
    const auto t0 = std::chrono::steady_clock::now();
    CandidateResult c = f();
    std::ostringstream m;
    m.precision(3);
    m << "candidate " << c.name() << ": error " << c.errors.total_rms_log_mag << ", BIC change " << c.bic_change
      << " (" << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s)";
    std::lock_guard<std::mutex> lock(say_mutex);
    in.Say(m.str());
    return c;
  }

  const AuditInputs& in;
  const FitContext& context;
  std::mutex say_mutex;
};

// The parameter hypotheses fitted: each parameter alone (by BIC), and the
// pairs of the best few.
struct HypothesisFits {
  std::vector<CandidateResult> singles, pairs;
};

// Parameter hypotheses first (issue #33 §1): each of the model's own
// parameters freed alone, then every pair of the best few.
HypothesisFits FitParameterHypotheses(CandidateFitter& fitter, const AuditResult& r) {
  const AuditInputs& in = fitter.in;
  const AuditOptions& o = in.o;
  const FitContext& context = fitter.context;
  HypothesisFits out;
  std::vector<CandidateResult>& hypotheses = out.singles;
  if (!o.try_parameters) return out;
  std::vector<std::string> names =
      o.parameter_candidates.empty() ? DefaultParameterCandidates(in.parameters) : o.parameter_candidates;
  std::erase_if(names, [&](const std::string& n) { return Contains(o.calibration_parameters, n); });
  in.Say("fitting " + std::to_string(names.size()) + " parameter hypotheses (each parameter freed alone)");
  hypotheses = RunAll(
      static_cast<int>(names.size()), o.threads,
      [&](int i) {
        return fitter.Timed([&] {
          return FitParameterHypothesis(in.description, r.baseline_fit.parameters, {names[i]},
                                        o.calibration_parameters, context);
        });
      },
      [&](int i) { return ScanCost(r.baseline_fit.parameters, {names[i]}); });
  std::sort(hypotheses.begin(), hypotheses.end(), ByBic);
  std::vector<int> top_h;
  for (int i = 0; i < static_cast<int>(hypotheses.size()) && static_cast<int>(top_h.size()) < o.parameter_pairs_from;
       ++i) {
    if (hypotheses[i].fit.status != calibration::FitStatus::kFailed && hypotheses[i].bic_change < 0.0) {
      top_h.push_back(i);
    }
  }
  std::vector<std::pair<int, int>> pair_of;
  for (size_t a = 0; a < top_h.size(); ++a) {
    for (size_t b = a + 1; b < top_h.size(); ++b) pair_of.push_back({top_h[a], top_h[b]});
  }
  if (!pair_of.empty()) {
    in.Say("fitting " + std::to_string(pair_of.size()) + " pairs of parameter hypotheses");
    out.pairs = RunAll(
        static_cast<int>(pair_of.size()), o.threads,
        [&](int k) {
          const CandidateResult& first = hypotheses[pair_of[k].first];  // the better one: its fit is the start
          const CandidateResult& second = hypotheses[pair_of[k].second];
          return fitter.Timed([&] {
            return FitParameterHypothesis(in.description, first.fit.parameters,
                                          {first.parameters[0], second.parameters[0]}, o.calibration_parameters,
                                          context);
          });
        },
        [&](int k) {
          return ScanCost(r.baseline_fit.parameters, {hypotheses[pair_of[k].first].parameters[0],
                                                      hypotheses[pair_of[k].second].parameters[0]});
        });
  }
  return out;
}

// Compliance anywhere along the chain (issue #33 §2): every virtual joint
// screened, the best few that promise a real improvement fitted fully as
// candidates next to the library's effects.
void ScreenVirtualJointCandidates(const AuditInputs& in, const FitContext& context,
                                  std::vector<std::string>* candidates, AuditResult* r) {
  const AuditOptions& o = in.o;
  if (o.virtual_joints_fitted <= 0) return;
  in.Say("screening virtual joints (compliance along the chain)");
  r->virtual_joint_screen = ScreenVirtualJoints(in.description, r->baseline_fit.parameters, o.calibration_parameters,
                                                context, &r->virtual_joint_screen_baseline);
  int taken = 0;
  for (ScreenedVirtualJoint& s : r->virtual_joint_screen) {
    // A virtual joint that the screen expects to remove less than a
    // tenth of the excess is not worth a fit.
    const double base = r->virtual_joint_screen_baseline;
    if (taken >= o.virtual_joints_fitted || !(s.predicted_error < base - 0.1 * std::max(base - 1.0, 0.0))) break;
    s.fitted = true;
    candidates->push_back(s.effect);
    ++taken;
  }
  std::ostringstream m;
  m.precision(3);
  m << "virtual joints: " << taken << " of " << r->virtual_joint_screen.size() << " fitted";
  if (!r->virtual_joint_screen.empty()) {
    m << " (best " << r->virtual_joint_screen.front().effect << ": " << r->virtual_joint_screen.front().predicted_error
      << " against " << r->virtual_joint_screen_baseline << " by the screen)";
  }
  in.Say(m.str());
}

// Posture-dependent joint stiffness (issue #33 §3): a joint whose gravity
// torque varies over the measured postures (at least a fifth of the
// largest variation of any joint) is a candidate for load_stiffness_j<j>,
// fitted with its kq_j free.
void AddLoadStiffnessCandidates(const AuditInputs& in, const AuditResult& r, std::vector<std::string>* candidates) {
  const dynamics::RobotDescription& description = in.description;
  const auto base_model = dynamics::RobotModel::Build(description, r.baseline_fit.parameters);
  const int n = description.arm.num_joints();
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(n, INFINITY), hi = Eigen::VectorXd::Zero(n);
  for (const std::string& pose : in.measured.pose_ids()) {
    const Eigen::VectorXd g = dynamics::GravityTorque(*base_model, in.postures.at(pose)).cwiseAbs();
    lo = lo.cwiseMin(g);
    hi = hi.cwiseMax(g);
  }
  const Eigen::VectorXd range = hi - lo;
  const double largest = range.maxCoeff();
  for (int j = 0; j < n && largest > 0.0; ++j) {
    const std::string name = "load_stiffness_j" + std::to_string(j + 1);
    bool present = false;
    for (const auto& e : description.effects) present |= e.name == name;
    if (!present && range(j) >= 0.2 * largest && in.parameters.Has("kq" + std::to_string(j + 1) + "_Nm_per_rad")) {
      candidates->push_back(name);
    }
  }
}

// The schedule's cost estimate of `effect` added to (base_desc, base),
// whose added effects `base_effects` are scanned again.
double EffectCost(const dynamics::RobotDescription& base_desc, const dynamics::ParameterSet& base,
                  const std::vector<std::string>& base_effects, const std::string& effect) {
  const auto [desc_e, params_e] = WithEffect(base_desc, base, effect);
  std::vector<std::string> scanned = FittableOf(effect);
  for (const std::string& e : base_effects) {
    for (const std::string& n : FittableOf(e)) scanned.push_back(n);
  }
  return ScanCost(params_e, scanned);
}

// Every candidate effect fitted alone, sorted by BIC.
// Every candidate from its scan first; the further starts (FitCandidate)
// only where they could change the verdict: best BIC first, until a
// plausible candidate explains the data. (All candidates with all starts
// took 110 s of CPU instead of 78 s on 6 x 2 x 4096-line data with a
// hidden long-reach tool, for fits that could not change the ranking's
// top.)
std::vector<CandidateResult> FitSingleCandidates(CandidateFitter& fitter, const std::vector<std::string>& candidates,
                                                 const AuditResult& r) {
  const AuditInputs& in = fitter.in;
  const AuditOptions& o = in.o;
  const FitContext& context = fitter.context;
  const dynamics::RobotDescription& description = in.description;
  in.Say("fitting " + std::to_string(candidates.size()) + " candidate effects");
  std::vector<CandidateResult> singles = RunAll(
      static_cast<int>(candidates.size()), o.threads,
      [&](int i) {
        return fitter.Timed([&] {
          return FitCandidate(description, r.baseline_fit.parameters, {}, candidates[i], in.FreeFor(candidates[i]),
                              context, false);
        });
      },
      [&](int i) { return EffectCost(description, r.baseline_fit.parameters, {}, candidates[i]); });
  std::set<std::string> refined;
  for (;;) {
    std::sort(singles.begin(), singles.end(), ByBic);
    bool done = false;
    for (const CandidateResult& c : singles) {
      if (c.bic_change < 0.0 && c.plausible) {
        done = Explains(c, o, r.noise_floor) && !Doubtful(c);
        break;
      }
    }
    std::vector<int> pick;
    for (int i = 0; i < static_cast<int>(singles.size()) && static_cast<int>(pick.size()) < std::max(1, o.threads);
         ++i) {
      if (!refined.count(singles[i].name()) && NeedsMoreStarts(singles[i], context)) pick.push_back(i);
    }
    if (done || pick.empty()) break;
    std::vector<CandidateResult> more = RunAll(
        static_cast<int>(pick.size()), o.threads,
        [&](int k) {
          const CandidateResult& first = singles[pick[k]];
          in.Say("more starts for " + first.name());
          return fitter.Timed([&] {
            return FitCandidate(description, r.baseline_fit.parameters, {}, first.effects.back(),
                                in.FreeFor(first.effects.back()), context, true, &first.fit.parameters);
          });
        },
        [&](int k) {
          return EffectCost(description, r.baseline_fit.parameters, {}, singles[pick[k]].effects.back());
        });
    for (size_t k = 0; k < pick.size(); ++k) {
      refined.insert(singles[pick[k]].name());
      // The resumed fit starts from the first one, but its further starts
      // may end elsewhere: it replaces the first only if Replaces says so.
      if (Replaces(more[k], singles[pick[k]])) singles[pick[k]] = std::move(more[k]);
    }
  }
  return singles;
}

// The greedy second round: a second effect of the library on top of the
// single effect with the lowest BIC, `top` (if it lowers the BIC and its
// fit did not fail). Returns the pairs fitted.
std::vector<CandidateResult> GreedySecondRound(CandidateFitter& fitter, const CandidateResult& top,
                                               const std::vector<std::string>& library_candidates) {
  const AuditInputs& in = fitter.in;
  const AuditOptions& o = in.o;
  const FitContext& context = fitter.context;
  const bool top_usable = top.bic_change < 0.0 && top.fit.status != calibration::FitStatus::kFailed;
  if (!top_usable) return {};
  const dynamics::RobotDescription desc1 = WithEffect(in.description, top.fit.parameters, top.effects[0]).first;
  // The first effect's parameters that its single fit pinned at a bound
  // were standing in for what is still missing: they restart from their
  // defaults (seen: a tool's damping ratio at 0.3 that kept the pair with
  // the flange at 1.1 × the true model's error).
  dynamics::ParameterSet start1 = top.fit.parameters;
  for (const auto& e : top.fit.estimates) {
    if (e.at_bound && e.name.find('.') != std::string::npos) start1.Set(e.name, start1.spec(e.name).default_value);
  }
  const std::vector<std::string> free1 = FreeAfter(in.FreeFor(top.effects[0]), top.effects[0], top);
  std::vector<std::string> others;
  for (const std::string& n : library_candidates) {
    if (n != top.effects[0]) others.push_back(n);
  }
  in.Say("greedy round: " + std::to_string(others.size()) + " effects on top of " + top.effects[0]);
  return RunAll(
      static_cast<int>(others.size()), o.threads,
      [&](int i) { return fitter.Timed([&] { return FitCandidate(desc1, start1, top.effects, others[i], free1, context); }); },
      [&](int i) { return EffectCost(desc1, start1, top.effects, others[i]); });
}

// A pair whose one effect adds nothing (its parameters pinned where it
// vanishes: a spindle interface with scales 100 and 1e4, no interface at
// all) is the other effect alone (issue #33): that effect is fitted again
// alone from the pair's values, replaces its single fit if better, and
// the pair is not named.
void ResolveRedundantPairs(CandidateFitter& fitter, std::vector<CandidateResult>* pairs, AuditResult* r) {
  const AuditInputs& in = fitter.in;
  const AuditOptions& o = in.o;
  for (CandidateResult& p : *pairs) {
    if (p.effects.size() != 2 || p.pinned.empty() || p.fit.status == calibration::FitStatus::kFailed) continue;
    for (size_t drop = 0; drop < 2; ++drop) {
      const std::string& gone = p.effects[drop];
      const std::string& kept = p.effects[1 - drop];
      bool pinned_here = false;
      for (const auto& n : p.pinned) pinned_here |= n.rfind(gone + ".", 0) == 0;
      if (!pinned_here) continue;
      auto [dk, pk] = WithEffect(in.description, r->baseline_fit.parameters, kept);
      for (const auto& spec : pk.specs()) {
        if (p.fit.parameters.Has(spec.name)) pk.SetClamped(spec.name, p.fit.parameters.Get(spec.name));
      }
      const ModelErrors without = ComputeErrors(dynamics::RobotModel::Build(dk, pk), in.postures, in.measured,
                                                o.fmin_hz, o.fmax_hz, o.num_bands);
      const double scale = r->noise_floor * r->noise_floor;
      if (!((without.rss - p.errors.rss) / scale < o.identifiable_chi2)) continue;
      p.plausible = false;
      p.note += (p.note.empty() ? "" : "; ") + gone + " adds nothing (pinned where it vanishes): the pair is " + kept +
                " alone";
      p.redundant = gone;
      in.Say(p.name() + ": " + gone + " adds nothing; fitting " + kept + " alone from the pair's values");
      CandidateResult alone = fitter.Timed([&] {
        return FitCandidate(in.description, r->baseline_fit.parameters, {}, kept, in.FreeFor(kept), fitter.context,
                            true, &pk);
      });
      for (CandidateResult& c : r->candidates) {
        if (c.name() == kept && Replaces(alone, c)) c = alone;
      }
      break;
    }
  }
}

// Every single candidate (effects, virtual joints, parameter hypotheses)
// by BIC, then every pair by BIC, into r->candidates; r->best the accepted
// one (-1: none).
void RankCandidates(CandidateFitter& fitter, const CandidateLists& lists, const std::vector<CandidateResult>& singles,
                    const HypothesisFits& hypotheses, AuditResult* r_out) {
  const AuditOptions& o = fitter.in.o;
  AuditResult& r = *r_out;
  r.candidates = singles;
  for (const CandidateResult& h : hypotheses.singles) r.candidates.push_back(h);
  std::stable_sort(r.candidates.begin(), r.candidates.end(), ByBic);
  const size_t num_singles = r.candidates.size();
  // The best plausible single candidate that lowers the BIC is accepted.
  for (size_t i = 0; i < num_singles && r.best < 0; ++i) {
    if (r.candidates[i].bic_change < 0.0 && r.candidates[i].plausible) r.best = static_cast<int>(i);
  }
  bool explained_by_pair_of_parameters = false;
  for (const CandidateResult& h : hypotheses.pairs) {
    explained_by_pair_of_parameters |= h.plausible && h.bic_change < 0.0 && Explains(h, o, r.noise_floor);
  }
  std::vector<CandidateResult> pairs = hypotheses.pairs;
  // If it does not explain the data, a second effect is tried on top of the
  // single effect with the lowest BIC, plausible or not: with two effects
  // missing, the one fitted alone may need implausible values (a damping
  // ratio on its bound) to stand in for the other. Not when two of the
  // model's own parameters already explain it.
  const bool best_explains = r.best >= 0 && Explains(r.candidates[r.best], o, r.noise_floor);
  if (!singles.empty() && !best_explains && !explained_by_pair_of_parameters && o.greedy_second_round &&
      singles.size() > 1) {
    std::vector<CandidateResult> effect_pairs = GreedySecondRound(fitter, singles.front(), lists.library);
    for (auto& p : effect_pairs) pairs.push_back(std::move(p));
  }
  ResolveRedundantPairs(fitter, &pairs, &r);
  std::stable_sort(r.candidates.begin(), r.candidates.end(), ByBic);
  r.best = -1;
  for (size_t i = 0; i < num_singles && r.best < 0; ++i) {
    if (r.candidates[i].bic_change < 0.0 && r.candidates[i].plausible) r.best = static_cast<int>(i);
  }
  const bool best_explains_now = r.best >= 0 && Explains(r.candidates[r.best], o, r.noise_floor);
  std::stable_sort(pairs.begin(), pairs.end(), ByBic);
  for (auto& p : pairs) r.candidates.push_back(p);
  if (!best_explains_now && !pairs.empty()) {
    const double bar = r.best >= 0 ? r.candidates[r.best].bic : r.baseline_bic;
    if (pairs.front().bic < bar && pairs.front().plausible) r.best = static_cast<int>(num_singles);
  }
}

// The parameter uncertainty in the verdict; when it alone covers the
// failure, the headline and the first next step say so.
void NoteUncertainty(AuditResult* r_out) {
  AuditResult& r = *r_out;
  if (!(r.uncertainty && !r.uncertainty->parameters.empty())) return;
  UncertaintyAllowance& u = *r.uncertainty;
  std::string names;
  bool stiffness = false;
  for (const auto& n : u.parameters) {
    names += (names.empty() ? "" : ", ") + n;
    stiffness |= n.rfind("kq", 0) == 0;
  }
  const std::string how = stiffness ? " (a tracker campaign planned for the work region: kq-identify --plan N "
                                      "--target-postures work.csv)"
                                    : " (more or better-placed measurements of what fitted them)";
  const char* its = u.parameters.size() == 1 ? "its" : "their";
  if (u.covers_failure) {
    const CandidateResult* named = AcceptedCandidate(r);
    const bool effect_named = (r.grade == AuditGrade::kExplained || r.grade == AuditGrade::kMostlyExplained) &&
                              named && !named->is_parameter_hypothesis();
    u.sentence += effect_named
                      ? std::string("; the named effect fits, but the parameter uncertainty alone also covers the "
                                    "misfit, so these data do not establish it: narrow ") +
                            its + " uncertainty" + how + " and audit again"
                      : std::string("; so this misfit is not evidence of a missing effect: narrow ") + its +
                            " uncertainty" + how + " before adding one";
    r.headline += " The parameter uncertainty alone could explain it: within the " +
                  FormatNumber(100.0 * u.confidence) + " % region of " + names + " the error falls to " +
                  FormatNumber(u.error_noise_units, 3) + " x the noise floor.";
    r.next_steps.insert(r.next_steps.begin(), "Narrow the uncertainty of " + names + " before " +
                                                  (effect_named ? "trusting the named effect" : "adding an effect") +
                                                  ": within " + its + " " + FormatNumber(100.0 * u.confidence) +
                                                  " % confidence region the error falls to " +
                                                  FormatNumber(u.error_noise_units, 3) + " x the noise floor" + how +
                                                  ".");
  }
  while (!r.verdict.empty() && (r.verdict.back() == '.' || r.verdict.back() == ' ')) r.verdict.pop_back();
  r.verdict += "; " + u.sentence;
}

}  // namespace

AuditResult RunAudit(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                     const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                     const AuditOptions& options) {
  options.Validate();
  CheckUncertaintyEstimates(parameters, options);
  AuditOptions o = options;  // fit_line_stride 0 is resolved below
  CandidateLists lists = ResolveCandidates(description, parameters, &o);
  const AuditInputs in{description, parameters, postures, measured, o};

  AuditResult r;
  CalibrateBaseline(in, &o, &r);
  if (!r.significant_failure && o.rank_only_if_failing) {
    r.explained = true;
    r.grade = AuditGrade::kNoFailure;
    r.verdict = "the model agrees with the measurement within the noise floor; no effect is missing";
    r.headline = Headline(r, o);
    return r;
  }

  const dynamics::FrfSet fit_data = Decimate(measured, o.fit_line_stride);
  const BandedFitData banded = BandFitData(postures, fit_data, o.fmin_hz, o.fmax_hz);
  const FitContext context{postures,      fit_data,      measured, r.features, o, r.baseline_bic,
                           r.noise_floor, r.errors_before.total_rms_log_mag, parameters, banded};
  AllowUncertainty(in, context, &r);
  CandidateFitter fitter(in, context);
  const HypothesisFits hypotheses = FitParameterHypotheses(fitter, r);
  ScreenVirtualJointCandidates(in, context, &lists.effects, &r);
  if (!lists.explicit_list && o.try_parameters) AddLoadStiffnessCandidates(in, r, &lists.effects);
  const std::vector<CandidateResult> singles = FitSingleCandidates(fitter, lists.effects, r);
  if (singles.empty() && hypotheses.singles.empty()) {
    r.grade = r.significant_failure ? AuditGrade::kUnexplained : AuditGrade::kNoFailure;
    r.explained = !r.significant_failure;
    r.verdict = "no candidate effects to try";
    r.headline = Headline(r, o);
    return r;
  }
  RankCandidates(fitter, lists, singles, hypotheses, &r);
  GradeVerdict(o, &r);
  NoteUncertainty(&r);
  return r;
}

}  // namespace robomach::audit
