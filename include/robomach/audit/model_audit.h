#pragma once

// Model audit (issue #5 §2): where a calibrated model fails against measured
// tool-tip FRFs, how large the measurement noise is, and which effect of the
// library, added and fitted together with the calibration parameters,
// explains the failure best (ranked by BIC, greedily for a second effect).

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "robomach/common/run_status.h"
#include "robomach/calibration/frf_calibration.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/parameters.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/dynamics/uncertainty.h"

namespace robomach::audit {

struct AuditOptions {
  /// Calibration parameters, always free (the audit first calibrates the
  /// current model with them, then refits them with every candidate).
  std::vector<std::string> calibration_parameters{"m6_kg", "d6_m", "alpha_s", "beta_per_s"};
  /// Candidates to try; empty: every library effect not yet in the model,
  /// the parameter hypotheses and the virtual-joint screen below. A list is
  /// the whole list: effect names (virtual_joint_<place>_<axis> included)
  /// and model parameter names (kq2_Nm_per_rad: a parameter hypothesis,
  /// paired with the others named); no screen, no other hypotheses.
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
  /// Graded verdict (issue #18): a candidate that does not explain the data
  /// but removes at least this fraction of the excess misfit, with errors in
  /// units of the noise floor, (before − after) / (before − 1), and is
  /// clearly ahead by BIC (clear_bic_gap) "mostly explains" it and is named.
  /// 0.8: the remainder is at most a fifth of what the calibrated model
  /// missed, so the effect accounts for the bulk of the failure; the issue's
  /// held-out cases of effects not quite of library form (a base rocking
  /// about its floor point with Rayleigh damping, a holder with its own
  /// mass on interface springs) reached 0.93 and 0.996, a sensor-mounting
  /// resonance outside the library 0.01.
  double mostly_explained_fraction{0.8};
  /// "Clearly ahead by BIC": the named candidate's BIC is below that of
  /// every alternative with as many effects or fewer (the other candidates
  /// of its round and of the rounds before it, and the calibrated current
  /// model) by more than this. 10 is "very strong" evidence on the scale of
  /// Kass & Raftery, J. Am. Stat. Assoc. 90 (1995) 773-795, for 2 ln B
  /// (ΔBIC ≈ 2 ln B > 10: a Bayes factor above ~150).
  double clear_bic_gap{10.0};
  /// Try a second effect on top of the best one if the best alone does not
  /// explain the data.
  bool greedy_second_round{true};
  /// Skip the candidate ranking when the current model has no significant
  /// failure (nothing to explain).
  bool rank_only_if_failing{true};
  /// Iterations of one candidate fit; a fit that stops there is run again
  /// from its start with four times as many (the better of the two counts).
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
  /// Parameter hypotheses (issue #33): before and beside the effects, the
  /// model's own parameters named here are freed, each alone and the best
  /// pairs, with the calibration parameters; one that explains the data is
  /// reported as a parameter that is off, not as a missing effect.
  /// Default: every joint stiffness kq1..kqn (the names must be parameters
  /// of the model and not calibration parameters).
  std::vector<std::string> parameter_candidates;
  bool try_parameters{true};
  /// Pairs of parameter hypotheses fitted: every pair of the best
  /// `parameter_pairs_from` single hypotheses (by BIC; 3: three pairs).
  int parameter_pairs_from{3};
  /// Compliance anywhere along the chain (issue #33): every virtual joint
  /// (dynamics effect virtual_joint_<place>_<axis>) is screened by a
  /// stiffness scan with a linearised re-adjustment of the calibration
  /// parameters, and the `virtual_joints_fitted` best are fitted fully as
  /// candidates. 0: no virtual joints.
  int virtual_joints_fitted{3};
  /// calibration::CalibrationOptions::robust_scale of every fit (a Huber
  /// loss per line, in units of the noise; 0: plain least squares). The
  /// errors, the BIC and the grades stay those of plain least squares.
  double robust_scale{0.0};
  /// Candidates fitted at the same time (each fit is single-threaded).
  int threads{2};
  /// The uncertainty of model parameters the audit does not calibrate
  /// (issue #37 §4): kq-identify's joint stiffnesses, a previous
  /// calibration's effect parameters (docs/formats.md §12). Its estimates
  /// must be the values in the parameters audited (model-audit puts them
  /// there). Empty: none. Parameters the audit calibrates anyway and names
  /// the model does not have are left out (AuditResult::uncertainty says so).
  dynamics::ParameterUncertainty parameter_uncertainty;
  /// Confidence level of the region the parameters may move in.
  double uncertainty_confidence{0.95};
  /// Called with one line per step (for progress on stderr); may be empty.
  std::function<void(const std::string&)> progress;

  /// calibration_parameters not empty; 0 <= fmin_hz < fmax_hz; num_bands,
  /// max_iterations and threads >= 1; significance_factor and
  /// explained_factor > 1; mostly_explained_fraction in (0, 1];
  /// clear_bic_gap >= 0; fit_line_stride, parameter_pairs_from and
  /// virtual_joints_fitted >= 0; identifiable_chi2 finite and >= 0;
  /// robust_scale finite and >= 0; uncertainty_confidence in (0, 1); the
  /// parameter_uncertainty (if any) valid (dynamics::CheckValid: its
  /// message, as an OptionError of field "parameter_uncertainty").
  /// @throws OptionError naming the field, its value and the bound
  ///   ("AuditOptions::num_bands must be >= 1, got 0").
  void Validate() const;
};

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

/// The graded verdict of an audit (issue #18).
enum class AuditGrade {
  /// No significant failure: the current model agrees with the measurement
  /// within significance_factor × the noise floor; nothing is missing.
  kNoFailure,
  /// A significant failure that the named effect(s) bring within
  /// explained_factor × the noise floor.
  kExplained,
  /// A significant failure that the named effect(s) do not bring within the
  /// noise, but reduce by at least mostly_explained_fraction of the excess
  /// misfit while clearly ahead by BIC (clear_bic_gap): the effect is real
  /// but not exactly of the library's form, or its parameters are bounded.
  kMostlyExplained,
  /// A significant failure that no candidate explains or mostly explains.
  kUnexplained,
};

/// "no_failure", "explained", "mostly_explained", "unexplained" (the JSON
/// summary's verdict.grade).
std::string ToString(AuditGrade grade);
/// The inverse of ToString. @throws std::invalid_argument naming the four.
AuditGrade ParseAuditGrade(const std::string& name);

/// The fraction of the excess misfit a model with error `after` removes
/// from one with error `before`: (b − a) / (b − 1) with b, a the errors in
/// units of `noise_floor` (1 is a model that is right). 1 when `after` is at
/// the noise, 0 when nothing changed, negative when it got worse; NaN when
/// `before` is within the noise (no excess to remove) or an input is not
/// finite.
double FractionRemoved(double before, double after, double noise_floor);

/// One candidate fitted to the data: an effect (or pair, in the greedy
/// round) added to the model, or model parameters freed (a parameter
/// hypothesis: `effects` empty, `parameters` the freed ones).
struct CandidateResult {
  std::vector<std::string> effects;  // the added effects, in order of addition
  /// Model parameters freed besides the calibration parameters (parameter
  /// hypotheses: "kq2_Nm_per_rad"); empty for effects.
  std::vector<std::string> parameters;
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
  /// Effect parameters on a bound that the data push there (moving one into
  /// the interior raises χ² by identifiable_chi2 or more): they make the
  /// candidate implausible, and a mostly-explained verdict lists them.
  std::vector<std::string> pinned;
  /// Every fitted effect parameter converged, inside its bounds and not pinned at one.
  bool plausible{false};
  /// A pair whose effect of this name adds nothing (pinned where it
  /// vanishes; removing it changes χ² by less than identifiable_chi2): the
  /// pair is the other effect alone and is never named.
  std::string redundant;
  std::string note;         // why not plausible, or the fit's message
  std::string name() const;  // "a" or "a+b" (effects, then freed parameters)
  /// Effects plus freed parameters: 1 for a single candidate, 2 for a pair.
  int size() const { return static_cast<int>(effects.size() + parameters.size()); }
  bool is_parameter_hypothesis() const { return effects.empty() && !parameters.empty(); }
};

/// A model parameter that a parameter hypothesis finds off its configured value.
struct ParameterChange {
  std::string name;     // "kq2_Nm_per_rad"
  std::string unit;     // "N·m/rad"
  double configured{NAN};  // the value the audit started from (the config's)
  double fitted{NAN};
  double std_dev{NAN};     // 1 σ of the fitted value
  double ratio() const { return fitted / configured; }
};

/// One virtual joint of the screen (issue #33): its best stiffness on the
/// scan and the error there after a linearised re-adjustment of the
/// calibration parameters, in units of the noise floor.
struct ScreenedVirtualJoint {
  std::string effect;
  double stiffness{NAN};         // [N·m/rad or N/m]
  double predicted_error{NAN};   // rms whole-curve residual after a linearised recalibration, noise units
  bool fitted{false};            // one of the best, fitted fully as a candidate
};

/// What the parameter uncertainty allows (issue #37 §4): the calibrated
/// model's error with the uncertain parameters at their most favourable
/// values within the confidence region, the calibration parameters refitted.
/// A failure this covers is not evidence of a missing effect.
struct UncertaintyAllowance {
  std::vector<std::string> parameters;  // the uncertain parameters moved
  /// In the file but not moved, with why ("m6_kg: calibrated by the audit").
  std::vector<std::string> left_out;
  double confidence{NAN};
  /// The region: (θ − θ̂)ᵀ Σ⁻¹ (θ − θ̂) <= chi2, chi2 the χ² quantile of
  /// `confidence` with as many degrees of freedom as the covariance's rank.
  double chi2{NAN};
  int rank{0};
  /// The most favourable point: found by Gauss–Newton steps constrained to
  /// the region (the calibration parameters re-adjusted linearly), then the
  /// calibration refitted there. Its values, the Mahalanobis distance
  /// √((θ − θ̂)ᵀ Σ⁻¹ (θ − θ̂)) and the region's radius √chi2.
  dynamics::ParameterSet at;
  double distance{NAN}, radius{NAN};
  ModelErrors errors;  // of the refitted model at that point
  double error_noise_units{NAN};  // errors.total_rms_log_mag / noise floor
  /// FractionRemoved of the calibrated model's error (error_before) by it.
  double fraction_removed{NAN};
  /// A significant failure that the uncertainty brings within
  /// significance_factor × the noise floor.
  bool covers_failure{false};
  std::string sentence;  // in the verdict and the report
};

/// A calibration parameter of the calibrated current model that ended on a
/// bound: the calibration stands in for something missing (issue #33).
struct BoundFlag {
  std::string name;
  double value{NAN};
  bool lower{true};
  std::string message;  // "m6_kg on its lower bound 2.9 kg: ..."
};

struct AuditResult {
  /// The parameter values the audit started from (the config's).
  dynamics::ParameterSet configured;
  calibration::CalibrationResult baseline_fit;  // the current model calibrated
  /// The model as configured (the start values, not calibrated): its errors,
  /// and the calibration parameters the calibration left on a bound.
  ModelErrors errors_configured;
  std::vector<BoundFlag> baseline_on_bound;
  /// The model the where-it-fails pictures are drawn from: "calibrated", or
  /// "configured" when the calibration ended with a parameter on a bound
  /// and the configured model's modes are closer to the measured ones.
  std::string pictures_from{"calibrated"};
  dynamics::ParameterSet pictures_parameters;  // the parameters of that model
  ModelErrors errors_before;
  calibration::Comparison modes_before;         // per-mode errors (matching) of the pictures' model
  calibration::MeasuredFeatures features;       // the measured modes modes_before indexes
  double noise_floor{0.0};
  double baseline_bic{0.0};
  bool significant_failure{false};
  /// Singles best first (by BIC), then the pairs "a+b" (greedy effect and parameter pairs) best first.
  std::vector<CandidateResult> candidates;
  /// Index in `candidates` of the accepted candidate, -1 if none: the best
  /// plausible one that lowers the BIC (the explanation when the grade is
  /// kExplained; see `graded` for the one a kMostlyExplained grade names).
  int best{-1};
  /// The named effects: the accepted candidate's when the grade is
  /// kExplained or kMostlyExplained, empty otherwise (and empty when the
  /// named candidate is a parameter hypothesis).
  std::vector<std::string> missing_effects;
  /// The parameters that are off when the named candidate is a parameter
  /// hypothesis (issue #33), with their configured and fitted values.
  std::vector<ParameterChange> parameter_changes;
  /// The virtual-joint screen, best first (empty when not run), and the
  /// same measure for the calibrated model without one.
  std::vector<ScreenedVirtualJoint> virtual_joint_screen;
  double virtual_joint_screen_baseline{NAN};
  /// With AuditOptions::parameter_uncertainty and a significant failure:
  /// which part of the misfit the uncertainty could explain.
  std::optional<UncertaintyAllowance> uncertainty;
  AuditGrade grade{AuditGrade::kUnexplained};
  /// grade is kNoFailure or kExplained: the model (with the named effects)
  /// agrees with the measurement within the noise. False for
  /// kMostlyExplained: an effect is named, but a misfit remains.
  bool explained{false};
  std::string verdict;  // one sentence for people (with the pattern and the reasons)
  /// The verdict in one short sentence, for the first line of a report: the
  /// grade, the named effect and the errors before and after in units of
  /// the noise floor (the fraction removed when mostly explained).
  std::string headline;
  /// Index in `candidates` of the candidate the grade was decided on, -1 if
  /// none: the named one for kExplained (= best) and kMostlyExplained;
  /// for kUnexplained the accepted one (best), else the single candidate
  /// with the lowest BIC whose fit converged. The numbers below are its.
  /// kMostlyExplained names, per number of effects (singles first, then
  /// the greedy pairs), the candidate with the lowest BIC among the fits
  /// that converged, plausible or not (a parameter pinned at a bound is a
  /// likely reason for the remainder), so `graded` may differ from `best`.
  int graded{-1};
  /// The graded candidate against the current model, errors in units of the
  /// noise floor; NaN without one.
  double error_before_noise_units{NAN};  // errors_before.total_rms_log_mag / noise_floor
  double remainder_noise_units{NAN};     // the accepted candidate's error / noise_floor
  double fraction_removed{NAN};          // FractionRemoved(before, after, noise_floor)
  /// BIC of the runner-up minus that of the accepted candidate, and the
  /// runner-up's name: the alternative with the lowest BIC among the other
  /// candidates with as many effects or fewer and the calibrated current
  /// model ("current model"). Compared with AuditOptions::clear_bic_gap.
  double bic_gap{NAN};
  std::string runner_up;
  /// When not explained: where the remaining error lies (see DescribePattern),
  /// also appended to the verdict; empty otherwise.
  std::string pattern;
  /// kMostlyExplained: the likely reasons for the remainder, one phrase each:
  /// fitted parameters of the named effects (or calibration parameters) on
  /// a bound, the effect's damping parameter on a bound ("its damping"),
  /// and, when no parameter is on a bound, "its form" (the real effect is
  /// not exactly of the library's form). Empty otherwise.
  std::vector<std::string> reasons;
  /// When a significant failure is not explained: what to try next, one
  /// sentence each (the closest parameter hypothesis and virtual joint with
  /// the error each reaches, calibration parameters on a bound, the
  /// measurement chain). Empty otherwise.
  std::vector<std::string> next_steps;
  /// Trouble that did not stop the audit (a failed fit of an effect given
  /// with --add), for the caller to report.
  std::vector<std::string> warnings;
};

/// model-audit's verdict (its exit 3; Python's audit()["status"]): flagged,
/// one finding each, when the model fails significantly and is not
/// explained (the finding is the verdict), for each of the result's
/// warnings, and when a candidate's fit failed.
RunFindings JudgeAudit(const AuditResult& r);

/// The candidate that stands for "the model after": the named one when the
/// grade is explained or mostly explained, else the accepted one (r.best),
/// else none (nullptr). model-audit's report and YAML show this one.
const CandidateResult* AcceptedCandidate(const AuditResult& r);

/// BIC of a Gaussian least-squares fit: n ln(RSS/n) + k ln n.
double Bic(double rss, int n, int k);

/// Audits the model of `description` with `parameters` (its values are the
/// start of every fit) against `measured` at `postures`.
/// @throws std::invalid_argument for bad options, an unknown candidate or
///   parameter, or a measured posture missing from `postures`.
AuditResult RunAudit(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                     const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                     const AuditOptions& options = {});

/// dynamics::WithEffect, by its old name here.
using dynamics::WithEffect;

/// Words for the pattern of a model's errors: how many FRFs fail
/// significantly, the band that is worst in most FRFs and whether it is the
/// same at every posture and direction (then the cause does not follow the
/// posture), and the range of the per-posture error.
std::string DescribePattern(const ModelErrors& errors, double noise_floor, double significance_factor);

/// The YAML lines that add the candidate's effects with their fitted
/// parameters to a robot config's `effects:` list, and (issue #33) the
/// `parameters:` block with the model and calibration parameters fitted
/// with them, so that the config plus these lines is the fitted model.
std::string EffectYaml(const CandidateResult& candidate);

/// The named candidate in words for people: a library effect's name; a
/// virtual joint's place, axis and stiffness ("virtual_joint_link3_rx (an
/// elastic rotation about link 3's x axis, right after joint 3; 4.1e6
/// N·m/rad)"); a parameter hypothesis's changes ("kq2_Nm_per_rad 40 %
/// lower than configured (1.88e6 instead of 3.13e6 N·m/rad)").
std::string DescribeCandidate(const CandidateResult& candidate, const dynamics::ParameterSet& configured);

/// Where a virtual joint sits, in words ("an elastic rotation about link
/// 3's x axis, right after joint 3"); the effect's own description for
/// any other effect.
std::string DescribeVirtualJoint(const std::string& effect);

/// The description and parameters of the model with the candidate's change
/// (effects added, parameters fitted): what --write-config writes.
std::pair<dynamics::RobotDescription, dynamics::ParameterSet> CandidateModel(
    const dynamics::RobotDescription& description, const CandidateResult& candidate);

}  // namespace robomach::audit
