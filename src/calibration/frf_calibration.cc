#include "robomach/calibration/frf_calibration.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <ceres/ceres.h>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/global_modal_fit.h"
#include "robomach/common/enum_names.h"
#include "robomach/common/errors.h"
#include "robomach/common/golden_section.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::calibration {
namespace {

using dynamics::FrfKey;
using dynamics::PostureDynamics;
using cd = std::complex<double>;



std::map<std::string, PostureDynamics> EvaluatePostures(const std::shared_ptr<const dynamics::RobotModel>& model,
                                                        const PostureMap& postures,
                                                        const std::vector<std::string>& ids) {
  dynamics::PostureEvaluator ev(model);
  std::map<std::string, PostureDynamics> out;
  for (const std::string& id : ids) {
    auto it = postures.find(id);
    if (it == postures.end()) {
      std::string known;
      for (const auto& [k, q] : postures) known += (known.empty() ? "" : ", ") + k;
      throw std::invalid_argument("posture " + id + " of the measured FRFs is not in the posture file (known: " +
                                  known + ")");
    }
    out.emplace(id, ev.Evaluate(it->second));
  }
  return out;
}

}  // namespace

std::pair<double, double> PeakSearchWindow(double freq_hz, double damping_ratio,
                                           const std::vector<double>& other_freqs_hz) {
  double lo = freq_hz * std::max(0.05, 1.0 - damping_ratio), hi = freq_hz * (1.0 + damping_ratio);
  for (double f : other_freqs_hz) {
    if (f < freq_hz) lo = std::max(lo, 0.5 * (f + freq_hz));
    if (f > freq_hz) hi = std::min(hi, 0.5 * (f + freq_hz));
  }
  return {lo, std::max(lo, hi)};
}

double OwnResonanceHz(double freq_hz, double damping_ratio) {
  return freq_hz * std::sqrt(std::max(0.0, 1.0 - 2.0 * damping_ratio * damping_ratio));
}

namespace {

struct PeakFeature {
  double freq_hz{0.0};
  double magnitude{0.0};
  PeakKind kind{PeakKind::kMaximum};
};

// The peak feature of one mode from |H| (`mag`, callable beyond the window):
// the largest local maximum of |H| on [lo, hi] (found on a grid of `grid`
// cells, the ends compared with |H| one cell beyond them, then refined by
// golden section within a cell on each side), a kMaximum. A maximum is
// stationary, so the value does not depend on where the window ends.
// Without one, the mode makes no peak of its own: a shoulder on a stronger
// neighbour's flank. The window's largest |H| is then the flank's value at
// the window's end, which moves with the estimated ζ and f_n: on a flank 8 %
// from a stronger mode (ζ ≈ 3 %) |H| changes by ~13 % per 1 % of frequency,
// so a model and a fit that differed by 7 % in ζ (0.23 % at the end)
// disagreed by 5 % (issue #34 item 6, the H3 yy 9.85 Hz mode of
// FrfCalibration.AcceptanceTwoStage...). A shoulder is described by |H| at
// the mode's own resonance f_r = f_n √(1 − 2ζ²) instead, where a 0.1 % error
// of f_n moves it by ~1 %; f_r is clamped to [band_lo, band_hi]. `forced`
// imposes the kind: the model takes the measurement's, so that both sides of
// a match use one definition. A model forced to kMaximum that has no maximum
// in its window (a mode at the border between the kinds) gets its f_r value
// too, which is near the value of a maximum about to vanish (within 1 % for
// the weak modes of ExtractFeatures.PeakOfAWeakModeIsItsOwn...).
template <class F>
PeakFeature FindPeakFeature(const F& mag, double lo, double hi, double freq_hz, double damping_ratio, int grid,
                            double band_lo, double band_hi, std::optional<PeakKind> forced) {
  if (forced != PeakKind::kShoulder && hi > lo) {
    const double step = (hi - lo) / grid;
    std::vector<double> v(grid + 3);  // v[i + 1] = |H(lo + i step)|, i = -1 .. grid + 1
    for (int i = -1; i <= grid + 1; ++i) v[i + 1] = mag(lo + i * step);
    int best = -1;
    for (int i = 0; i <= grid; ++i) {
      const double c = v[i + 1];
      if (c >= v[i] && c > v[i + 2] && (best < 0 || c > v[best + 1])) best = i;
    }
    if (best >= 0) {
      const double x = lo + best * step;
      const auto [fp, ap] = GoldenSectionMaximum(mag, std::max(lo, x - step), std::min(hi, x + step), 80, 1e-12);
      return ap >= v[best + 1] ? PeakFeature{fp, ap, PeakKind::kMaximum}
                               : PeakFeature{x, v[best + 1], PeakKind::kMaximum};
    }
  }
  const double fr = std::clamp(OwnResonanceHz(freq_hz, damping_ratio), band_lo, band_hi);
  return {fr, mag(fr), forced.value_or(PeakKind::kShoulder)};
}

// Neighbours of a model mode for its peak search window: the other modes
// of the posture that show in the FRF `key`, i.e. whose peak contribution
// reaches kNeighbourVisibility of the largest in it. The measured side cuts
// its window at the modes its fit found, which are the visible ones; a model
// mode that does not move the tip in this direction has no peak to reach
// and must not narrow the window either. 1e-3 is the 60 dB a hammer test
// resolves at best.
constexpr double kNeighbourVisibility = 1e-3;

}  // namespace

// ------------------------------------------------------------- features --

MeasuredFeatures ExtractFeatures(const dynamics::FrfSet& measured, const ModalFitOptions& options) {
  MeasuredFeatures out;
  for (const auto& [key, frf] : measured) {
    // The fit frf-modes and stability-lobes make (one fitter, issue #34).
    ModalFitResult fit = FitOneFrf(frf, options);
    if (fit.status == SolverStatus::kConverged) {
      for (size_t i = 0; i < fit.modes.size(); ++i) {
        const FittedMode& m = fit.modes[i];
        MeasuredMode mm;
        mm.key = key;
        mm.fit = m;
        std::vector<double> others;
        for (size_t j = 0; j < fit.modes.size(); ++j) {
          if (j != i) others.push_back(fit.modes[j].freq_hz);
        }
        const auto [wlo, whi] = PeakSearchWindow(m.freq_hz, m.damping_ratio, others);
        const double lo = std::clamp(wlo, fit.fmin_hz, fit.fmax_hz), hi = std::clamp(whi, lo, fit.fmax_hz);
        // 200 cells, as ModalFitResult::PeakIn.
        const PeakFeature p = FindPeakFeature([&](double f) { return std::abs(fit.Evaluate(f)); }, lo, hi,
                                              m.freq_hz, m.damping_ratio, 200, fit.fmin_hz, fit.fmax_hz,
                                              std::nullopt);
        mm.peak_freq_hz = p.freq_hz;
        mm.peak_magnitude = p.magnitude;
        mm.peak_kind = p.kind;
        out.modes.push_back(mm);
      }
    }
    out.fits.emplace(key, std::move(fit));
    out.peaks.emplace(key, PickPeaks(frf.Band(options.fmin_hz, options.fmax_hz)));
  }
  return out;
}

// ------------------------------------------------------------- matching --

double ModelModeVisibility(const dynamics::Mode& m, const FrfKey& key) {
  const double w = HzToRadPerSec(m.freq_hz);
  const double pr = m.p_T(static_cast<int>(key.response)), pe = m.p_T(static_cast<int>(key.excitation));
  return std::abs(pr * pe) / (2.0 * std::max(m.damping_ratio, 1e-6) * w * w);
}

std::pair<double, double> ModelPeak(const PostureDynamics& d, const FrfKey& key, int model_mode, PeakKind kind) {
  const dynamics::Mode& m = d.modes.at(model_mode);
  double vis_max = 0.0;
  for (const dynamics::Mode& o : d.modes) vis_max = std::max(vis_max, ModelModeVisibility(o, key));
  std::vector<double> others;
  for (size_t j = 0; j < d.modes.size(); ++j) {
    if (static_cast<int>(j) != model_mode && ModelModeVisibility(d.modes[j], key) >= kNeighbourVisibility * vis_max) {
      others.push_back(d.modes[j].freq_hz);
    }
  }
  const auto [lo, hi] = PeakSearchWindow(m.freq_hz, m.damping_ratio, others);
  const dynamics::ReceptanceEvaluator H(d);
  const int r = static_cast<int>(key.response), e = static_cast<int>(key.excitation);
  const PeakFeature p = FindPeakFeature([&](double x) { return std::abs(H.Entry(x, r, e)); }, lo, hi, m.freq_hz,
                                        m.damping_ratio, 60, 0.0, std::numeric_limits<double>::infinity(), kind);
  return {p.freq_hz, p.magnitude};
}

void MatchOptions::Validate() const {
  CheckOptionAbove("min_relative_visibility", min_relative_visibility, 0.0);
  CheckOptionRange("min_relative_visibility", min_relative_visibility, 0.0, 1.0);
  CheckOptionAbove("max_log_freq_ratio", max_log_freq_ratio, 0.0);
  CheckOptionAtLeast("direction_weight", direction_weight, 0.0);
  CheckOptionFinite("direction_weight", direction_weight);
}

void CalibrationOptions::Validate() const {
  if (free_parameters.empty()) {
    throw OptionError("free_parameters", "free_parameters: expected at least one parameter, got none");
  }
  ValidateNested("matching", matching);
  ValidateNested("modal_fit", modal_fit);
  CheckOptionAbove("freq_sigma", freq_sigma, 0.0);
  CheckOptionFinite("freq_sigma", freq_sigma);
  CheckOptionAbove("peak_sigma", peak_sigma, 0.0);
  CheckOptionFinite("peak_sigma", peak_sigma);
  CheckOptionBand("fmin_hz", fmin_hz, "fmax_hz", fmax_hz);
  CheckOptionAtLeast("max_iterations", max_iterations, 1);
  CheckOptionAtLeast("max_match_rounds", max_match_rounds, 1);
  CheckOptionAbove("weak_relative_std", weak_relative_std, 0.0);
  if (!(robust_scale >= 0.0) || !std::isfinite(robust_scale)) {
    throw OptionError("robust_scale", "CalibrationOptions::robust_scale must be >= 0 (0: no robust loss), got " +
                                          std::to_string(robust_scale));
  }
}

std::vector<ModeMatch> MatchModes(const std::map<std::string, PostureDynamics>& model,
                                  const MeasuredFeatures& features, const MatchOptions& o) {
  o.Validate();
  std::vector<ModeMatch> out;
  for (const auto& [key, fit] : features.fits) {
    auto pit = model.find(key.pose_id);
    if (pit == model.end()) continue;
    const PostureDynamics& d = pit->second;
    std::vector<int> meas;
    double meas_max = 0.0;
    for (size_t i = 0; i < features.modes.size(); ++i) {
      if (features.modes[i].key == key) {
        meas.push_back(static_cast<int>(i));
        meas_max = std::max(meas_max, features.modes[i].fit.peak_contribution);
      }
    }
    if (meas.empty()) continue;
    std::vector<double> vis(d.modes.size());
    double vis_max = 0.0;
    for (size_t k = 0; k < d.modes.size(); ++k) {
      vis[k] = ModelModeVisibility(d.modes[k], key);
      vis_max = std::max(vis_max, vis[k]);
    }
    struct Cand {
      double cost;
      int i, k;
    };
    std::vector<Cand> cands;
    for (int i : meas) {
      const FittedMode& fm = features.modes[i].fit;
      if (fm.peak_contribution < o.min_relative_visibility * meas_max) continue;
      for (size_t k = 0; k < d.modes.size(); ++k) {
        if (vis[k] < o.min_relative_visibility * vis_max) continue;
        const double lf = std::abs(std::log(d.modes[k].freq_hz / fm.freq_hz));
        if (lf > o.max_log_freq_ratio) continue;
        const double lv = std::abs(std::log(vis[k] / fm.peak_contribution));
        cands.push_back({lf + o.direction_weight * lv, i, static_cast<int>(k)});
      }
    }
    std::sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) { return a.cost < b.cost; });
    std::set<int> used_i, used_k;
    for (const Cand& c : cands) {
      if (used_i.count(c.i) || used_k.count(c.k)) continue;
      used_i.insert(c.i);
      used_k.insert(c.k);
      ModeMatch m;
      m.key = key;
      m.measured = c.i;
      m.model_mode = c.k;
      const MeasuredMode& mm = features.modes[c.i];
      m.measured_freq_hz = mm.fit.freq_hz;
      m.measured_damping = mm.fit.damping_ratio;
      m.measured_peak = mm.peak_magnitude;
      m.peak_kind = mm.peak_kind;
      m.model_freq_hz = d.modes[c.k].freq_hz;
      m.model_damping = d.modes[c.k].damping_ratio;
      m.model_shape_T = d.modes[c.k].shape_T;
      m.model_peak = ModelPeak(d, key, c.k, m.peak_kind).second;
      out.push_back(m);
    }
  }
  std::sort(out.begin(), out.end(), [](const ModeMatch& a, const ModeMatch& b) {
    return std::tie(a.key, a.measured_freq_hz) < std::tie(b.key, b.measured_freq_hz);
  });
  return out;
}

double WholeCurveError(const PostureDynamics& d, const FrfKey& key, const dynamics::Frf& measured,
                       double fmin_hz, double fmax_hz) {
  const dynamics::Frf band = measured.Band(fmin_hz, fmax_hz);
  if (band.size() == 0) return NAN;
  const Eigen::VectorXcd H = dynamics::ReceptanceEvaluator(d).Entry(band.freq_hz(), static_cast<int>(key.response),
                                                                     static_cast<int>(key.excitation));
  const Eigen::VectorXd w = LogResidualWeights(band);
  double s = 0.0;
  int n = 0;
  for (int i = 0; i < band.size(); ++i) {
    const cd hm = H(i);
    const cd h = band.receptance()(i);
    if (std::abs(h) == 0.0 || std::abs(hm) == 0.0) continue;
    const auto r = WholeCurveResiduals(hm, h);
    s += w(i) * w(i) * (r[0] * r[0] + r[1] * r[1]);
    ++n;
  }
  return n > 0 ? std::sqrt(s / n) : NAN;
}

Comparison CompareWithMeasurement(const std::shared_ptr<const dynamics::RobotModel>& model,
                                  const PostureMap& postures, const dynamics::FrfSet& measured,
                                  const MeasuredFeatures& features, const MatchOptions& options,
                                  double fmin_hz, double fmax_hz) {
  const auto dyn = EvaluatePostures(model, postures, measured.pose_ids());
  Comparison c;
  c.matches = MatchModes(dyn, features, options);
  std::set<int> matched;
  for (const ModeMatch& m : c.matches) matched.insert(m.measured);
  for (size_t i = 0; i < features.modes.size(); ++i) {
    if (!matched.count(static_cast<int>(i))) c.unmatched_measured.push_back(static_cast<int>(i));
  }
  for (const auto& [key, frf] : measured) {
    c.whole_curve_error[key] = WholeCurveError(dyn.at(key.pose_id), key, frf, fmin_hz, fmax_hz);
  }
  double sf = 0, sp = 0;
  for (const ModeMatch& m : c.matches) {
    c.max_abs_freq_error = std::max(c.max_abs_freq_error, std::abs(m.freq_error()));
    c.max_abs_peak_error = std::max(c.max_abs_peak_error, std::abs(m.peak_error()));
    sf += m.freq_error() * m.freq_error();
    sp += m.peak_error() * m.peak_error();
  }
  if (!c.matches.empty()) {
    c.rms_freq_error = std::sqrt(sf / c.matches.size());
    c.rms_peak_error = std::sqrt(sp / c.matches.size());
  }
  return c;
}

// ---------------------------------------------------------- calibration --

std::string ToString(Objective o) {
  switch (o) {
    case Objective::kModalTwoStage: return "modal-two-stage";
    case Objective::kModalJoint: return "modal-joint";
    case Objective::kWholeCurve: return "whole-curve";
  }
  return "?";
}

Objective ParseObjective(const std::string& name) {
  constexpr Objective kAll[] = {Objective::kModalTwoStage, Objective::kModalJoint, Objective::kWholeCurve};
  return ParseByName("objective", name, kAll);
}


CalibrationVerdict JudgeCalibration(const CalibrationResult& result, const dynamics::FrfSet& measured,
                                    const CalibrationOptions& options) {
  CalibrationVerdict v;
  if (result.status == FitStatus::kNotImproved) {
    v.verdict.Flag("the calibration did not improve on the start values; the calibrated config keeps them. " +
           result.message);
  } else if (result.status != FitStatus::kConverged || !result.weakly_identified.empty()) {
    v.verdict.Flag(result.message);
  }
  // Goodness of fit against the noise: a model that represents the data
  // leaves a misfit of about one noise variance per residual (two residuals
  // per line).
  bool in_noise_units = !measured.empty();
  int lines = 0;
  for (const auto& [k, f] : measured) {
    in_noise_units = in_noise_units && f.noise_sigma().has_value();
    lines += static_cast<int>(f.Band(options.fmin_hz, options.fmax_hz).size());
  }
  v.residuals = 2 * lines;
  if (in_noise_units) {
    const double per_residual = result.misfit_final / std::max(1, v.residuals);
    v.rms_per_residual_in_noise_units = std::sqrt(per_residual);
    if (per_residual > kCalibrationMisfitFlagNoiseUnits * kCalibrationMisfitFlagNoiseUnits) {
      std::ostringstream m;
      m.precision(3);
      m << "the calibrated model misses the data by " << v.rms_per_residual_in_noise_units
        << " times the noise (rms over " << v.residuals << " residuals): it cannot represent these data with "
        << "the free parameters (another effect, another robot?); see the overlays and model-audit";
      v.verdict.Flag(m.str());
    }
  }
  return v;
}

namespace {

enum class ResidualKind { kFrequency, kPeak, kJoint, kWholeCurve };

// Everything a residual evaluation needs. The free parameters are scaled
// by their initial values: x_i = value_i / scale_i, or, for a parameter
// bounded away from zero (a stiffness, a damping ratio, a scale factor),
// x_i = ln(value_i / scale_i). In the logarithm a fit moves such a
// parameter by factors, as its physics does, and a step cannot carry it to
// its lower bound by overshooting a linear extrapolation (seen with
// flange stiffnesses: linear steps parked the torsional stiffness at its
// lower bound, 1e3 of a true 2e6 N·m/rad).
struct ModelResidual {
  const dynamics::RobotDescription* description;
  dynamics::ParameterSet base;
  std::vector<std::string> names;
  std::vector<double> scale;
  std::vector<char> log_scale;
  const PostureMap* postures;
  std::vector<std::string> pose_ids;
  ResidualKind kind;
  std::vector<ModeMatch> matches;                     // modal kinds
  std::vector<std::pair<FrfKey, dynamics::Frf>> curves;  // whole curve, band-limited
  std::vector<Eigen::VectorXd> curve_weights;            // LogResidualWeights of each curve
  double freq_sigma{1.0}, peak_sigma{1.0};
  double robust_scale{0.0};  // CalibrationOptions::robust_scale (whole curve)
  int num_residuals{0};
  // The first exception other than a NumericalError raised in an evaluation
  // (bad input, a bug). Ceres cannot carry it, so the evaluation fails and
  // SolveStage rethrows it after the solve; shared by the copies.
  std::shared_ptr<std::exception_ptr> error = std::make_shared<std::exception_ptr>();

  int CountResiduals() const {
    switch (kind) {
      case ResidualKind::kFrequency:
      case ResidualKind::kPeak: return static_cast<int>(matches.size());
      case ResidualKind::kJoint: return 2 * static_cast<int>(matches.size());
      case ResidualKind::kWholeCurve: {
        int n = 0;
        for (const auto& [k, f] : curves) n += 2 * f.size();
        return n;
      }
    }
    return 0;
  }

  // Ceres keeps the iterates inside the bounds, but its numeric derivative
  // steps across a bound when a parameter sits on it, and x · scale may round
  // past it: such values are clamped to the bound (the derivative there is
  // then one-sided), not rejected, which would fail the whole evaluation.
  // The logarithm is offset by kLogOffset so that x stays well away from 0,
  // where Ceres' relative numeric-derivative step |x| · 1e-6 would shrink to
  // its floor √eps; parameters whose bounds reach below e^-(kLogOffset-1)
  // times their start stay linear (see the caller).
  static constexpr double kLogOffset = 12.0;
  double ToValue(double x, size_t i) const {
    return log_scale[i] ? scale[i] * std::exp(x - kLogOffset) : x * scale[i];
  }
  double ToX(double value, size_t i) const {
    return log_scale[i] ? std::log(value / scale[i]) + kLogOffset : value / scale[i];
  }
  /// d value / d x, for the uncertainty (delta method).
  double Slope(double x, size_t i) const { return log_scale[i] ? ToValue(x, i) : scale[i]; }

  dynamics::ParameterSet Values(const double* x) const {
    dynamics::ParameterSet p = base;
    for (size_t i = 0; i < names.size(); ++i) {
      const auto& spec = base.spec(names[i]);
      p.Set(names[i], std::clamp(ToValue(x[i], i), spec.lower, spec.upper));
    }
    return p;
  }

  bool operator()(double const* const* parameters, double* residuals) const {
    if (*error) return false;  // the solve ends; SolveStage rethrows
    try {
      const auto model = dynamics::RobotModel::Build(*description, Values(parameters[0]));
      const auto dyn = EvaluatePostures(model, *postures, pose_ids);
      int r = 0;
      if (kind == ResidualKind::kWholeCurve) {
        std::map<std::string, dynamics::ReceptanceEvaluator> evaluators;
        for (const auto& [id, d] : dyn) evaluators.emplace(id, dynamics::ReceptanceEvaluator(d));
        for (size_t c = 0; c < curves.size(); ++c) {
          const auto& [key, frf] = curves[c];
          const Eigen::VectorXcd H = evaluators.at(key.pose_id).Entry(
              frf.freq_hz(), static_cast<int>(key.response), static_cast<int>(key.excitation));
          const Eigen::VectorXd& w = curve_weights[c];
          for (int i = 0; i < frf.size(); ++i) {
            const auto e = WholeCurveResiduals(H(i), frf.receptance()(i));
            double a = w(i) * e[0], b = w(i) * e[1];
            if (robust_scale > 0.0) {
              // √ρ per line: both residuals scaled by √ρ(s) / √s.
              const double sq = a * a + b * b;
              if (sq > robust_scale * robust_scale) {
                const double f = std::sqrt(HuberRho(sq, robust_scale) / sq);
                a *= f;
                b *= f;
              }
            }
            residuals[r++] = a;
            residuals[r++] = b;
          }
        }
        return true;
      }
      for (const ModeMatch& m : matches) {
        const PostureDynamics& d = dyn.at(m.key.pose_id);
        if (m.model_mode >= static_cast<int>(d.modes.size())) return false;
        if (kind == ResidualKind::kFrequency || kind == ResidualKind::kJoint) {
          residuals[r++] = (d.modes[m.model_mode].freq_hz / m.measured_freq_hz - 1.0) / freq_sigma;
        }
        if (kind == ResidualKind::kPeak || kind == ResidualKind::kJoint) {
          const double peak = ModelPeak(d, m.key, m.model_mode, m.peak_kind).second;
          residuals[r++] = std::log(peak / m.measured_peak) / peak_sigma;
        }
      }
      return true;
    } catch (const NumericalError&) {
      return false;  // e.g. a mass matrix not positive definite at a trial point: Ceres shortens the step
    } catch (...) {
      *error = std::current_exception();
      return false;
    }
  }
};

struct StageOutcome {
  StageSummary summary;
  std::vector<double> values;   // in parameter units
  std::vector<double> std_dev;  // in parameter units, NaN if unknown
  /// Covariance in parameter units (NaN rows and columns for a parameter
  /// held on a bound; empty without a covariance).
  Eigen::MatrixXd covariance;
  ceres::TerminationType termination{ceres::FAILURE};
};

StageOutcome SolveStage(const std::string& stage_name, ModelResidual residual, const CalibrationOptions& o) {
  StageOutcome out;
  out.summary.name = stage_name;
  out.summary.parameters = residual.names;
  const int n = static_cast<int>(residual.names.size());
  residual.num_residuals = residual.CountResiduals();
  out.summary.num_residuals = residual.num_residuals;
  std::vector<double> x(n);
  for (int i = 0; i < n; ++i) x[i] = residual.ToX(residual.base.Get(residual.names[i]), i);
  if (residual.num_residuals < n) {
    out.summary.termination = "FAILURE";
    out.summary.message = "fewer residuals (" + std::to_string(residual.num_residuals) + ") than free parameters (" +
                          std::to_string(n) + "): too few matched modes";
    for (int i = 0; i < n; ++i) {
      out.values.push_back(residual.ToValue(x[i], i));
      out.std_dev.push_back(NAN);
    }
    return out;
  }
  const std::vector<std::string> names = residual.names;
  const ModelResidual map = residual;  // for the parameter mapping after the solve
  const dynamics::ParameterSet& base = map.base;
  const int m = residual.num_residuals;
  ceres::NumericDiffOptions nd;
  nd.relative_step_size = 1e-6;
  auto* cost = new ceres::DynamicNumericDiffCostFunction<ModelResidual, ceres::CENTRAL>(
      new ModelResidual(std::move(residual)), ceres::TAKE_OWNERSHIP, nd);
  cost->AddParameterBlock(n);
  cost->SetNumResiduals(m);
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, x.data());
  for (int i = 0; i < n; ++i) {
    const auto& spec = base.spec(names[i]);
    if (spec.lower > -1e299) problem.SetParameterLowerBound(x.data(), i, map.ToX(spec.lower, i));
    if (spec.upper < 1e299) problem.SetParameterUpperBound(x.data(), i, map.ToX(spec.upper, i));
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = o.max_iterations;
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-10;
  so.gradient_tolerance = 1e-14;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.num_threads = 1;
  // The bounds make the problem constrained, and Ceres then refines every
  // trust-region step by a projected line search. With its default
  // (cubic) interpolation each trial point costs a numeric Jacobian,
  // 2n + 1 model evaluations; bisection needs only the cost there. On
  // 6 x 2 x 4096-line data this cut a 9-parameter fit from 141 Jacobians
  // (33 s) to 22 (6 s) with the same result.
  so.line_search_interpolation_type = ceres::BISECTION;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (*map.error) std::rethrow_exception(*map.error);
  out.termination = summary.termination_type;
  out.summary.termination = ceres::TerminationTypeToString(summary.termination_type);
  out.summary.message = summary.message;
  out.summary.iterations = static_cast<int>(summary.iterations.size());
  out.summary.initial_cost = summary.initial_cost;
  out.summary.final_cost = summary.final_cost;
  for (int i = 0; i < n; ++i) {
    double v = map.ToValue(x[i], i);
    if (!std::isfinite(v)) {
      // A numerical outcome (the status says so), not a parameter value to
      // reject as bad input: the stage keeps the start value.
      v = base.Get(names[i]);
      out.termination = ceres::FAILURE;
      out.summary.termination = "FAILURE";
      out.summary.message = "the solver ended with a non-finite value of " + names[i] + "; " + out.summary.message;
    }
    out.values.push_back(std::clamp(v, base.spec(names[i]).lower, base.spec(names[i]).upper));
  }
  out.std_dev.assign(n, NAN);
  // Covariance of the scaled parameters, from Jᵀ J at the solution, scaled by
  // the residual variance estimate 2 F / (m − n) (the residual weights are
  // nominal, so the data's own scatter sets the uncertainty).
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.null_space_rank = 0;
  co.min_reciprocal_condition_number = 1e-14;
  ceres::Covariance cov(co);
  // Parameters that ended on a bound are held in the covariance (their
  // one-sided derivative does not describe an interval, and a bound-pinned
  // damping made the whole matrix singular): the others' uncertainty is
  // conditional on them; theirs is reported as unknown.
  std::vector<int> pinned;
  for (int i = 0; i < n; ++i) {
    const auto& spec = base.spec(names[i]);
    const double v = map.ToValue(x[i], i), tol = 1e-9 * std::max(1.0, std::abs(v));
    if (std::abs(v - spec.lower) < tol || std::abs(v - spec.upper) < tol) pinned.push_back(i);
  }
  if (!pinned.empty() && static_cast<int>(pinned.size()) < n) {
    problem.SetManifold(x.data(), new ceres::SubsetManifold(n, pinned));
  }
  std::vector<std::pair<const double*, const double*>> blocks = {{x.data(), x.data()}};
  const bool cov_ok = static_cast<int>(pinned.size()) < n && cov.Compute(blocks, &problem);
  if (*map.error) std::rethrow_exception(*map.error);
  if (cov_ok) {
    std::vector<double> c(n * n);
    cov.GetCovarianceBlock(x.data(), x.data(), c.data());
    const double dof = std::max(1, m - n);
    const double s2 = 2.0 * summary.final_cost / dof;
    auto held = [&](int i) { return std::find(pinned.begin(), pinned.end(), i) != pinned.end(); };
    out.covariance = Eigen::MatrixXd::Constant(n, n, NAN);
    for (int i = 0; i < n; ++i) {
      if (held(i)) continue;
      out.std_dev[i] = std::sqrt(std::max(0.0, c[i * n + i] * s2)) * std::abs(map.Slope(x[i], i));
      for (int j = 0; j < n; ++j) {
        if (!held(j)) out.covariance(i, j) = c[i * n + j] * s2 * map.Slope(x[i], i) * map.Slope(x[j], j);
      }
    }
    out.summary.covariance_ok = true;
  }
  return out;
}

bool SameMatching(const std::vector<ModeMatch>& a, const std::vector<ModeMatch>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!(a[i].key == b[i].key) || a[i].measured != b[i].measured || a[i].model_mode != b[i].model_mode) {
      return false;
    }
  }
  return true;
}

// Throws unless every free parameter is known, fittable and named once: a
// fit of a name the model does not have would silently fit nothing.
void CheckFreeParameters(const dynamics::ParameterSet& initial, const CalibrationOptions& o) {
  for (const std::string& name : o.free_parameters) {
    if (!initial.Has(name)) throw std::invalid_argument("unknown parameter '" + name + "'; known: " + initial.NameList());
    if (!initial.spec(name).fittable) throw std::invalid_argument("parameter '" + name + "' is not fittable");
  }
  {
    std::set<std::string> seen;
    for (const std::string& name : o.free_parameters) {
      if (!seen.insert(name).second) throw std::invalid_argument("parameter '" + name + "' is free twice");
    }
  }
}

// What every stage of one calibration shares: the robot, its postures, the
// data and their features, the options and the residual each stage starts from.
struct CalibrationContext {
  const dynamics::RobotDescription& description;
  const dynamics::ParameterSet& initial;
  const PostureMap& postures;
  const dynamics::FrfSet& measured;
  const MeasuredFeatures& features;
  const CalibrationOptions& o;
  std::vector<std::string> pose_ids;
  ModelResidual proto;

  // The dynamics of every measured posture for the parameters `p`.
  std::map<std::string, PostureDynamics> Evaluate(const dynamics::ParameterSet& p) const {
    return EvaluatePostures(dynamics::RobotModel::Build(description, p), postures, pose_ids);
  }
  // The solver's scale of each parameter: |initial value|, 1 where that is 0.
  std::vector<double> Scales(const std::vector<std::string>& names) const {
    std::vector<double> s;
    for (const std::string& nm : names) {
      const double v = std::abs(initial.Get(nm));
      s.push_back(v > 0.0 ? v : 1.0);
    }
    return s;
  }
};

// The free parameters of the two-stage objective split into those that move
// the natural frequencies (stage 1) and the rest (stage 2, peak amplitudes);
// both empty for the other objectives.
struct StageSplit {
  std::vector<std::string> stage1, stage2;
};

StageSplit SplitByFrequencyEffect(const CalibrationContext& c) {
  // Which free parameters move the undamped natural frequencies: a relative
  // change of 1e-3 must move some frequency by more than 1e-9 relative
  // (round-off of the eigen-solution is ~1e-13).
  StageSplit out;
  if (c.o.objective == Objective::kModalTwoStage) {
    const auto d0 = c.Evaluate(c.initial);
    for (const std::string& nm : c.o.free_parameters) {
      dynamics::ParameterSet p = c.initial;
      const double v = c.initial.Get(nm);
      const double dv = v != 0.0 ? 1e-3 * v : 1e-6;
      const auto& spec = c.initial.spec(nm);
      p.Set(nm, v + dv <= spec.upper ? v + dv : v - dv);
      const auto d1 = c.Evaluate(p);
      double change = 0.0;
      for (const auto& [id, d] : d0) {
        for (size_t k = 0; k < d.modes.size() && k < d1.at(id).modes.size(); ++k) {
          change = std::max(change, std::abs(d1.at(id).modes[k].freq_hz / d.modes[k].freq_hz - 1.0));
        }
      }
      (change > 1e-9 ? out.stage1 : out.stage2).push_back(nm);
    }
  }
  return out;
}

// The state of the stage fits: the parameters so far and, for the last
// round, each fitted parameter's std and stage, the stages' summaries and
// outcomes and whether they all ended well.
struct RoundState {
  dynamics::ParameterSet current;
  std::map<std::string, std::pair<double, std::string>> std_devs;  // name -> (std, stage)
  std::vector<StageSummary> stages;
  std::vector<StageOutcome> outcomes;  // the last round's, for the covariance
  bool ok = true, converged = true;
};

// One stage: the parameters `free` fitted with the residual `kind` about the
// current parameters and the mode matching `matches`; the fitted values
// become the current ones for the next stage.
void RunStage(const CalibrationContext& c, const std::vector<ModeMatch>& matches, const std::string& name,
              ResidualKind kind, const std::vector<std::string>& free, RoundState* st) {
  if (free.empty()) return;
  const CalibrationOptions& o = c.o;
  ModelResidual r = c.proto;
  r.base = st->current;
  r.names = free;
  r.scale = c.Scales(free);
  for (const std::string& nm : free) {
    const double lower = c.initial.spec(nm).lower, v = c.initial.Get(nm);
    r.log_scale.push_back(lower > 0.0 && v > 0.0 && std::log(lower / std::abs(v)) > 1.0 - ModelResidual::kLogOffset);
  }
  r.kind = kind;
  r.matches = matches;
  r.robust_scale = o.robust_scale;
  if (kind == ResidualKind::kWholeCurve) {
    for (const auto& [key, frf] : c.measured) {
      dynamics::Frf band = frf.Band(std::max(o.fmin_hz, 1e-12), o.fmax_hz);
      if (band.size() > 0) {
        r.curve_weights.push_back(LogResidualWeights(band));
        r.curves.emplace_back(key, std::move(band));
      }
    }
  }
  StageOutcome s = SolveStage(name, std::move(r), o);
  for (size_t i = 0; i < free.size(); ++i) {
    st->current.Set(free[i], s.values[i]);
    st->std_devs[free[i]] = {s.std_dev[i], name};
  }
  if (s.termination == ceres::FAILURE || s.termination == ceres::USER_FAILURE) st->ok = false;
  if (s.termination != ceres::CONVERGENCE) st->converged = false;
  st->stages.push_back(s.summary);
  st->outcomes.push_back(std::move(s));
}

// The stages of the objective, repeated while the fit changes which measured
// mode matches which model mode (at most max_match_rounds times); `matches`
// ends as the matching of the final parameters.
RoundState RunRounds(const CalibrationContext& c, const StageSplit& split, std::vector<ModeMatch>* matches) {
  const CalibrationOptions& o = c.o;
  RoundState st;
  st.current = c.initial;
  for (int round = 0; round < std::max(1, o.max_match_rounds); ++round) {
    st.stages.clear();
    st.outcomes.clear();
    st.std_devs.clear();
    st.ok = true;
    st.converged = true;
    switch (o.objective) {
      case Objective::kModalTwoStage:
        RunStage(c, *matches, "frequencies", ResidualKind::kFrequency, split.stage1, &st);
        RunStage(c, *matches, "peak amplitudes", ResidualKind::kPeak, split.stage2, &st);
        break;
      case Objective::kModalJoint:
        RunStage(c, *matches, "joint", ResidualKind::kJoint, o.free_parameters, &st);
        break;
      case Objective::kWholeCurve:
        RunStage(c, *matches, "whole curve", ResidualKind::kWholeCurve, o.free_parameters, &st);
        break;
    }
    const auto rematched = MatchModes(c.Evaluate(st.current), c.features, o.matching);
    const bool same = SameMatching(rematched, *matches);
    *matches = rematched;
    if (same || o.objective == Objective::kWholeCurve) break;
  }
  return st;
}

// The covariance of the free parameters, block-diagonal over the stages: a
// later stage's parameters are conditional on the earlier ones, held at
// their fitted values.
Eigen::MatrixXd StageCovariance(const std::vector<StageOutcome>& outcomes, const CalibrationOptions& o) {
  const int n = static_cast<int>(o.free_parameters.size());
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Constant(n, n, NAN);
  auto index = [&](const std::string& nm) {
    return static_cast<int>(std::find(o.free_parameters.begin(), o.free_parameters.end(), nm) -
                            o.free_parameters.begin());
  };
  for (const StageOutcome& s : outcomes) {
    if (s.covariance.size() == 0) continue;
    for (size_t i = 0; i < s.summary.parameters.size(); ++i) {
      for (size_t j = 0; j < s.summary.parameters.size(); ++j) {
        covariance(index(s.summary.parameters[i]), index(s.summary.parameters[j])) =
            s.covariance(static_cast<int>(i), static_cast<int>(j));
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (i != j && std::isfinite(covariance(i, i)) && std::isfinite(covariance(j, j)) &&
          std::isnan(covariance(i, j))) {
        covariance(i, j) = 0.0;  // different stages
      }
    }
  }
  return covariance;
}

// One estimate per free parameter (initial and fitted value, std and the
// stage that fitted it, whether it is weakly identified or on a bound), the
// weakly identified ones also listed by name.
void AddEstimates(const CalibrationContext& c, const RoundState& st, CalibrationResult* result) {
  const CalibrationOptions& o = c.o;
  for (const std::string& nm : o.free_parameters) {
    ParameterEstimate e;
    e.name = nm;
    e.unit = c.initial.spec(nm).unit;
    e.initial = c.initial.Get(nm);
    e.value = st.current.Get(nm);
    auto it = st.std_devs.find(nm);
    if (it != st.std_devs.end()) {
      e.std_dev = it->second.first;
      e.stage = it->second.second;
    }
    e.weakly_identified = !(e.std_dev <= o.weak_relative_std * std::abs(e.value));
    const auto& spec = c.initial.spec(nm);
    const double tol = 1e-9 * std::max(1.0, std::abs(e.value));
    e.at_bound = std::abs(e.value - spec.lower) < tol || std::abs(e.value - spec.upper) < tol;
    if (e.weakly_identified) result->weakly_identified.push_back(nm);
    result->estimates.push_back(e);
  }
}

// The status from the stages' terminations and the message that explains it
// (each stage's termination when one failed or did not converge, the weakly
// identified parameters).
void SetStatusAndMessage(const RoundState& st, const CalibrationOptions& o, CalibrationResult* result) {
  std::ostringstream msg;
  if (!st.ok) {
    result->status = FitStatus::kFailed;
    msg << "a stage failed:";
    for (const auto& s : st.stages) msg << " [" << s.name << ": " << s.termination << ", " << s.message << "]";
  } else if (!st.converged) {
    result->status = FitStatus::kNotConverged;
    msg << "not converged:";
    for (const auto& s : st.stages) msg << " [" << s.name << ": " << s.termination << ", " << s.message << "]";
  } else {
    result->status = FitStatus::kConverged;
    msg << "converged";
  }
  if (!result->weakly_identified.empty()) {
    msg << "; weakly identified (std > " << o.weak_relative_std * 100 << " % of the value, or no covariance):";
    for (const auto& n : result->weakly_identified) msg << ' ' << n;
  }
  result->message = msg.str();
}

CalibrationResult CalibrateOnce(const dynamics::RobotDescription& description, const dynamics::ParameterSet& initial,
                                const PostureMap& postures, const dynamics::FrfSet& measured,
                                const MeasuredFeatures& features, const CalibrationOptions& o) {
  CheckFreeParameters(initial, o);
  CalibrationContext c{description, initial, postures, measured, features, o, measured.pose_ids(), {}};
  // Fails early, with the message, if a measured posture is unknown.
  CalibrationResult result;
  result.parameters = initial;
  result.matches_before = MatchModes(c.Evaluate(initial), features, o.matching);

  c.proto.description = &description;
  c.proto.postures = &postures;
  c.proto.pose_ids = c.pose_ids;
  c.proto.freq_sigma = o.freq_sigma;
  c.proto.peak_sigma = o.peak_sigma;

  const StageSplit split = SplitByFrequencyEffect(c);
  std::vector<ModeMatch> matches = result.matches_before;
  const RoundState st = RunRounds(c, split, &matches);
  result.parameters = st.current;
  result.stages = st.stages;
  result.matches_after = matches;
  result.covariance = StageCovariance(st.outcomes, o);
  AddEstimates(c, st, &result);
  SetStatusAndMessage(st, o, &result);
  return result;
}

}  // namespace

FittedUncertainty FittedParameterUncertainty(const CalibrationResult& result, const std::string& source) {
  FittedUncertainty out;
  out.uncertainty.source = source;
  std::vector<int> kept;
  const int n = static_cast<int>(result.estimates.size());
  const bool has_cov = result.covariance.rows() == n && result.covariance.cols() == n;
  for (int i = 0; i < n; ++i) {
    const ParameterEstimate& e = result.estimates[i];
    const double var = has_cov ? result.covariance(i, i) : NAN;
    if (!std::isfinite(var)) {
      out.left_out.push_back(e.name + (e.at_bound ? ": held on a bound, no covariance" : ": no covariance"));
      continue;
    }
    const double sd = std::sqrt(std::max(0.0, var));
    if (e.value != 0.0 && sd > std::abs(e.value)) {
      std::ostringstream why;
      why << e.name << ": not determined, σ " << std::lround(100.0 * sd / std::abs(e.value)) << " % of its value";
      out.left_out.push_back(why.str());
      continue;
    }
    kept.push_back(i);
    dynamics::UncertainParameter p;
    p.name = e.name;
    p.value = e.value;
    p.scale = e.value > 0.0 ? dynamics::UncertainScale::kLog : dynamics::UncertainScale::kLinear;
    out.uncertainty.parameters.push_back(p);
  }
  const int k = static_cast<int>(kept.size());
  out.uncertainty.covariance.resize(k, k);
  for (int a = 0; a < k; ++a) {
    for (int b = 0; b < k; ++b) {
      // d log v = dv / v on the log scale.
      double c = result.covariance(kept[a], kept[b]);
      if (out.uncertainty.parameters[a].scale == dynamics::UncertainScale::kLog) c /= result.estimates[kept[a]].value;
      if (out.uncertainty.parameters[b].scale == dynamics::UncertainScale::kLog) c /= result.estimates[kept[b]].value;
      out.uncertainty.covariance(a, b) = c;
    }
  }
  out.uncertainty.covariance = 0.5 * (out.uncertainty.covariance + out.uncertainty.covariance.transpose()).eval();
  return out;
}

double HuberRho(double s, double c) {
  if (!(c > 0.0) || s <= c * c) return s;
  return 2.0 * c * std::sqrt(s) - c * c;
}

double WholeCurveMisfit(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                        const PostureMap& postures, const dynamics::FrfSet& measured, double fmin_hz,
                        double fmax_hz, double robust_scale) {
  try {
    const auto dyn = EvaluatePostures(dynamics::RobotModel::Build(description, parameters), postures,
                                      measured.pose_ids());
    double s = 0.0;
    for (const auto& [key, frf] : measured) {
      const dynamics::Frf band = frf.Band(fmin_hz, fmax_hz);
      if (band.size() == 0) continue;
      const Eigen::VectorXcd H = dynamics::ReceptanceEvaluator(dyn.at(key.pose_id))
                                     .Entry(band.freq_hz(), static_cast<int>(key.response),
                                            static_cast<int>(key.excitation));
      const Eigen::VectorXd w = LogResidualWeights(band);
      for (int i = 0; i < band.size(); ++i) {
        if (std::abs(band.receptance()(i)) == 0.0) continue;
        const auto r = WholeCurveResiduals(H(i), band.receptance()(i));
        s += HuberRho(w(i) * w(i) * (r[0] * r[0] + r[1] * r[1]), robust_scale);
      }
    }
    return std::isfinite(s) ? s : std::numeric_limits<double>::infinity();
  } catch (const NumericalError&) {
    // The model cannot be evaluated at these values (a mass matrix not
    // positive definite): infinitely far from the data. Anything else (a
    // posture missing from the posture file, a bug) is the caller's.
    return std::numeric_limits<double>::infinity();
  }
}

CalibrationResult Calibrate(const dynamics::RobotDescription& description, const dynamics::ParameterSet& initial,
                            const PostureMap& postures, const dynamics::FrfSet& measured,
                            const MeasuredFeatures& features, const CalibrationOptions& o) {
  o.Validate();
  const double misfit_start =
      WholeCurveMisfit(description, initial, postures, measured, o.fmin_hz, o.fmax_hz, o.robust_scale);
  const auto misfit_of = [&](const CalibrationResult& r) {
    return WholeCurveMisfit(description, r.parameters, postures, measured, o.fmin_hz, o.fmax_hz, o.robust_scale);
  };
  const auto doubtful = [](const CalibrationResult& r) {
    if (r.status != FitStatus::kConverged) return true;
    for (const ParameterEstimate& e : r.estimates) {
      if (e.at_bound) return true;
    }
    return false;
  };
  CalibrationResult best = CalibrateOnce(description, initial, postures, measured, features, o);
  best.start_used = "given";
  double best_misfit = misfit_of(best);
  int tried = 1;
  const auto consider = [&](CalibrationResult r, const std::string& label) {
    ++tried;
    const double m = misfit_of(r);
    // A converged fit off the bounds wins over a doubtful one; otherwise the misfit decides.
    const bool better = doubtful(best) != doubtful(r) && m <= misfit_start ? !doubtful(r) : m < best_misfit;
    if (better) {
      best = std::move(r);
      best.start_used = label;
      best_misfit = m;
    }
  };
  if (o.extra_starts && (!(best_misfit <= misfit_start) || doubtful(best))) {
    dynamics::ParameterSet defaults = initial;
    bool differs = false;
    for (const std::string& n : o.free_parameters) {
      const double d = initial.spec(n).default_value;
      if (d != initial.Get(n)) {
        defaults.Set(n, d);
        differs = true;
      }
    }
    if (differs) consider(CalibrateOnce(description, defaults, postures, measured, features, o), "defaults");
    if (o.objective != Objective::kWholeCurve) {
      CalibrationOptions wc = o;
      wc.objective = Objective::kWholeCurve;
      const dynamics::ParameterSet from = best_misfit <= misfit_start ? best.parameters : initial;
      const bool from_modal = best_misfit <= misfit_start;
      CalibrationResult polished = CalibrateOnce(description, from, postures, measured, features, wc);
      polished.matches_before = best.matches_before;
      consider(std::move(polished), "whole-curve polish");
      // The modal stage can move a parameter its features hardly see to a
      // bound (the demo data with spindle_interface free: the modal stage
      // got m6, d6, alpha, beta right and tilting_scale 1e4 at its bound),
      // and the polish from there stays in that basin. Still doubtful: the
      // whole curve from the start values too.
      if (from_modal && doubtful(best)) {
        CalibrationResult fresh = CalibrateOnce(description, initial, postures, measured, features, wc);
        fresh.matches_before = best.matches_before;
        consider(std::move(fresh), "whole-curve from the start values");
      }
    }
  }
  best.starts_tried = tried;
  best.misfit_start = misfit_start;
  best.misfit_final = best_misfit;
  // Round-off allowance: a fit that returns to an optimal start is not worse.
  if (!(best_misfit <= misfit_start * (1.0 + 1e-9))) {
    // No start did as well as where we began: keep the start values.
    CalibrationResult kept = best;
    kept.parameters = initial;
    kept.matches_after = kept.matches_before;
    for (ParameterEstimate& e : kept.estimates) {
      e.value = e.initial;
      e.std_dev = NAN;
      e.at_bound = false;
    }
    kept.covariance.resize(0, 0);  // the fit's, not the start's
    kept.status = FitStatus::kNotImproved;
    kept.start_used = "none (start kept)";
    kept.misfit_final = misfit_start;
    std::ostringstream m;
    m.precision(4);
    m << "no fit improved on the start values (whole-curve misfit " << misfit_start << " at the start, best of "
      << tried << " starts " << best_misfit << "): the start values are kept; the model cannot represent these "
      << "data with these free parameters, or the data are from another set-up";
    kept.message = m.str();
    return kept;
  }
  if (best.start_used != "given") {
    best.message += "; result from the start '" + best.start_used + "' (" + std::to_string(tried) + " starts tried)";
  }
  return best;
}

}  // namespace robomach::calibration
