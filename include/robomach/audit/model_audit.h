#pragma once

// Model audit (issue #5 §2): where a calibrated model fails against measured
// tool-tip FRFs, how large the measurement noise is, and which effect of the
// library, added and fitted together with the calibration parameters,
// explains the failure best (ranked by BIC, greedily for a second effect).

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "robomach/calibration/frf_calibration.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/parameters.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::audit {

struct AuditOptions {
  /// Calibration parameters, always free (the audit first calibrates the
  /// current model with them, then refits them with every candidate).
  std::vector<std::string> calibration_parameters{"m6_kg", "d6_m", "alpha_s", "beta_per_s"};
  /// Effects to try; empty: every library effect not yet in the model.
  std::vector<std::string> candidates;
  /// Band of all errors and fits [Hz].
  double fmin_hz{0.0};
  double fmax_hz{std::numeric_limits<double>::infinity()};
  /// Number of equal bands (on a log-frequency axis) per FRF for "worst bands".
  int num_bands{8};
  /// Whole-curve error above significance_factor × noise floor is a
  /// significant failure. With a correct model the rms log-magnitude error
  /// equals the noise floor up to the sampling scatter of an rms over
  /// ~2000 lines (±1.6 % relative at 1σ) plus the bias of a fitted model
  /// (k/n ≈ 0.1 %), so 1.3 leaves ample margin while a 30 % excess is a
  /// plainly visible misfit.
  double significance_factor{1.3};
  /// A model "explains" the data if its total error is within this factor of
  /// the noise floor (the same bound as significance_factor).
  double explained_factor{1.3};
  /// Try a second effect on top of the best one if the best alone does not
  /// explain the data.
  bool greedy_second_round{true};
  /// Skip the candidate ranking when the current model has no significant
  /// failure (nothing to explain).
  bool rank_only_if_failing{true};
  int max_iterations{100};
  /// The fits use every fit_line_stride-th line of each FRF (errors are
  /// always on all lines). 0: automatic, the largest stride (at most 4) that
  /// keeps 1.7 lines in the half-power band 2ζf of the most lightly damped
  /// measured mode: 2 at the default hammer grid (Δf = 0.25 Hz, 2ζf = 0.84
  /// Hz at 10.5 Hz), 1 at Δf = 0.625 Hz, where a stride of 2 left the 10 Hz
  /// modes less than a line and candidate fits missed the truth.
  int fit_line_stride{0};
  /// Identifiability screen of a candidate's parameters: a factor of two
  /// on a parameter must change the χ² (residuals over the noise floor) by
  /// at least this much for it to be fitted (4: a 2σ change).
  double identifiable_chi2{4.0};
  /// Candidates fitted at the same time (each fit is single-threaded).
  int threads{2};
  /// Called with one line per step (for progress on stderr); may be empty.
  std::function<void(const std::string&)> progress;
};

/// @throws std::invalid_argument naming the field for a bad option.
void CheckValid(const AuditOptions& options);

/// Band of one FRF with its rms log-magnitude error.
struct BandError {
  double fmin_hz{0.0};
  double fmax_hz{0.0};
  double rms_log_mag{0.0};  // rms of ln|H_model| − ln|H_measured| over the band's lines
  int lines{0};
};

/// Whole-curve error of one measured FRF (posture and direction).
struct CurveError {
  dynamics::FrfKey key;
  double rms_log_mag{0.0};      // over the audit band
  int lines{0};
  std::vector<BandError> bands;  // worst first
};

/// The errors of one model against all measured FRFs.
struct ModelErrors {
  std::vector<CurveError> curves;  // in FrfSet key order
  double total_rms_log_mag{0.0};   // over all lines of all FRFs
  double rss{0.0};                 // sum of squared log-magnitude residuals
  int lines{0};
};

/// Log-magnitude errors of `model` against `measured` in [fmin, fmax]. When
/// the measured FRFs carry a noise model (calibration::UsableData), every
/// residual is divided by its noise standard deviation
/// (calibration::LogResidualWeights): the errors are then in units of the
/// noise, 1 for a model that is right.
/// @throws std::invalid_argument if a measured posture is not in `postures`.
ModelErrors ComputeErrors(const std::shared_ptr<const dynamics::RobotModel>& model,
                          const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                          double fmin_hz, double fmax_hz, int num_bands);

/// Noise floor of the measurement: the rms scatter of ln|H| about a smooth
/// curve, from the second difference of ln|H| between neighbouring lines,
/// d_i = L_{i−1} − 2 L_i + L_{i+1}. For independent line noise e of standard
/// deviation s on a curve that is locally straight over 2 Δf, var(d) = 6 s².
/// Lines near sharp peaks break "locally straight"; the median of |d|
/// (with 0.6745 σ for a normal variable) ignores them as long as they are
/// fewer than half. Returns s, comparable with CurveError::rms_log_mag of a
/// correct model; NaN if there are fewer than 3 lines in the band. If every
/// FRF carries a noise model the errors are already in its units: 1.
double EstimateNoiseFloor(const dynamics::FrfSet& measured, double fmin_hz, double fmax_hz);

/// One candidate effect (or pair, in the greedy round) fitted to the data.
struct CandidateResult {
  std::vector<std::string> effects;  // the added effects, in order of addition
  calibration::CalibrationResult fit;
  ModelErrors errors;
  double bic{0.0};
  double bic_change{0.0};   // against the calibrated current model (negative: better)
  int added_parameters{0};  // fitted effect parameters (counted in the BIC)
  /// Fittable effect parameters that these data cannot determine: halving
  /// or doubling one (the others held) changes the fit's χ² by less than
  /// AuditOptions::identifiable_chi2 noise variances, so its 95 % interval
  /// spans more than a factor of two each way. They are held at their start
  /// values (library defaults), not fitted, and listed here.
  std::vector<std::string> not_identifiable;
  /// Calibration parameters held at their calibrated values because the
  /// effect's parameters can replace them exactly (see `note`).
  std::vector<std::string> held_calibration;
  /// Which start the reported fit came from: "scan" (best-first grid scan
  /// from the calibrated model) or "defaults" (library defaults with the
  /// model's own start values; tried when the first did not explain the data).
  std::string start;
  /// Every fitted effect parameter converged, inside its bounds and not pinned at one.
  bool plausible{false};
  std::string note;         // why not plausible, or the fit's message
  std::string name() const;  // "a" or "a+b"
};

struct AuditResult {
  calibration::CalibrationResult baseline_fit;  // the current model calibrated
  ModelErrors errors_before;
  calibration::Comparison modes_before;         // per-mode errors (matching)
  calibration::MeasuredFeatures features;       // the measured modes modes_before indexes
  double noise_floor{0.0};
  double baseline_bic{0.0};
  bool significant_failure{false};
  /// Best first (by BIC); the greedy pairs follow the single candidates.
  std::vector<CandidateResult> candidates;
  /// Index in `candidates` of the accepted explanation, -1 if none.
  int best{-1};
  std::vector<std::string> missing_effects;
  bool explained{false};
  std::string verdict;  // one sentence for people
  /// When not explained: where the remaining error lies (see DescribePattern),
  /// also appended to the verdict; empty otherwise.
  std::string pattern;
  /// Trouble that did not stop the audit (a failed fit of an effect given
  /// with --add), for the caller to report.
  std::vector<std::string> warnings;
};

/// BIC of a Gaussian least-squares fit: n ln(RSS/n) + k ln n.
double Bic(double rss, int n, int k);

/// Audits the model of `description` with `parameters` (its values are the
/// start of every fit) against `measured` at `postures`.
/// @throws std::invalid_argument for bad options, an unknown candidate or
///   parameter, or a measured posture missing from `postures`.
AuditResult RunAudit(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                     const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                     const AuditOptions& options = {});

/// The description with `effect` appended and parameters for it: `base`'s
/// values kept, the new effect's at their defaults.
std::pair<dynamics::RobotDescription, dynamics::ParameterSet> WithEffect(
    const dynamics::RobotDescription& description, const dynamics::ParameterSet& base, const std::string& effect);

/// Words for the pattern of a model's errors: how many FRFs fail
/// significantly, the band that is worst in most FRFs and whether it is the
/// same at every posture and direction (then the cause does not follow the
/// posture), and the range of the per-posture error.
std::string DescribePattern(const ModelErrors& errors, double noise_floor, double significance_factor);

/// The YAML lines that add the candidate's effects with their fitted
/// parameters to a robot config's `effects:` list.
std::string EffectYaml(const CandidateResult& candidate);

}  // namespace robomach::audit
