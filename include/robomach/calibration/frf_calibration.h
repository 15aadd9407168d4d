#pragma once

// Calibration of named model parameters against measured tool-tip FRFs
// (issue #4): modal features (natural frequencies, then peak amplitudes, as
// the seed's two-stage procedure, or jointly) or the whole curve
// (log-magnitude and phase over a band). Any parameter of the model's
// ParameterSet may be free; any measured direction pair may be used.

#include <array>
#include <complex>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/calibration/modal_fit.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/run_status.h"
#include "robomach/common/solver_status.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/parameters.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/dynamics/uncertainty.h"

namespace robomach::calibration {

// ------------------------------------------------------ measured features --

/// How the peak feature of a mode is taken (issue #34 item 6).
enum class PeakKind {
  /// |H| has its maximum inside the mode's peak search window: the peak is
  /// that maximum (a stationary value, insensitive to the window's ends).
  kMaximum,
  /// |H| grows through the window's end towards a stronger neighbour: the
  /// mode makes a shoulder on that neighbour's flank, not a peak of its own.
  /// The feature is |H| at the mode's own resonance f_n √(1 − 2ζ²)
  /// (OwnResonanceHz); the flank's value at the window's end would move with
  /// the estimated ζ by about 13 % per 1 % of frequency 8 % from the
  /// neighbour.
  kShoulder,
};

/// One mode identified in one measured FRF.
struct MeasuredMode {
  dynamics::FrfKey key;
  FittedMode fit;
  /// The maximum of |H_fit| within the mode's own peak search window
  /// (PeakSearchWindow: its half-power band, cut at the midpoints to the
  /// other fitted modes of the FRF): the peak amplitude of the seed's
  /// Table 3, taken from the fitted curve so that noise on single lines
  /// does not bias it upwards [m/N], and where it occurs [Hz]. For a
  /// shoulder (peak_kind), |H_fit| at the mode's own resonance instead.
  double peak_freq_hz{0.0};
  double peak_magnitude{0.0};
  PeakKind peak_kind{PeakKind::kMaximum};
};

struct MeasuredFeatures {
  std::map<dynamics::FrfKey, ModalFitResult> fits;
  /// The quick estimate of peak picking with half-power damping, per FRF,
  /// reported next to the fit for comparison.
  std::map<dynamics::FrfKey, std::vector<PeakEstimate>> peaks;
  std::vector<MeasuredMode> modes;
};

/// Where the peak of a mode is searched (issue #34 item 6): its own
/// half-power band f_n (1 ± ζ) (the lower end at least 0.05 f_n), cut at
/// the midpoint between f_n and each other mode's natural frequency
/// `other_freqs_hz`, whichever is narrower. The peak of one mode's
/// receptance, f_n √(1 − 2ζ²), lies in its half-power band for ζ <= 2/3;
/// the former f_n (1 ± 3ζ) reached the peak of a stronger neighbour 5-10 %
/// away (ζ = 3 %) and gave it to the weaker mode. [lo, hi] in Hz.
std::pair<double, double> PeakSearchWindow(double freq_hz, double damping_ratio,
                                           const std::vector<double>& other_freqs_hz);

/// The resonance of one mode's receptance, f_n √(1 − 2ζ²) [Hz] (f_n for
/// ζ >= 1/√2 would be 0: the receptance of such a mode has no peak).
double OwnResonanceHz(double freq_hz, double damping_ratio);

/// Fits every FRF of `measured` with FitModes and collects its modes.
/// FRFs whose fit has no stable mode contribute none (their status is in
/// `fits`).
MeasuredFeatures ExtractFeatures(const dynamics::FrfSet& measured, const ModalFitOptions& options = {});

// ------------------------------------------------------------- matching --

struct MatchOptions {
  /// A model mode is a candidate in an FRF H_re if its own peak contribution
  /// |p_r p_e| / (2ζω²) reaches this fraction of the largest one in that
  /// FRF; the same fraction applies to the measured modes (their fitted
  /// contributions). Weaker modes cannot be told from their neighbours.
  double min_relative_visibility{0.1};
  /// Largest |ln(f_model / f_measured)| of a match (0.4 ≈ ±40 %).
  double max_log_freq_ratio{0.4};
  /// Weight of |ln(visibility ratio)| (the tool-tip direction term) against
  /// |ln(frequency ratio)| in the matching cost.
  double direction_weight{0.25};

  /// min_relative_visibility in (0, 1]; max_log_freq_ratio > 0;
  /// direction_weight finite and >= 0.
  /// @throws OptionError naming the field, its value and the bound.
  void Validate() const;
};

/// A measured mode paired with a model mode of the same posture.
struct ModeMatch {
  dynamics::FrfKey key;
  int measured{-1};      // index in MeasuredFeatures::modes
  int model_mode{-1};    // 0-based index in PostureDynamics::modes (ascending frequency)
  double measured_freq_hz{0.0};
  double model_freq_hz{0.0};
  double measured_peak{0.0};  // [m/N]
  double model_peak{0.0};     // [m/N]
  /// The measured mode's PeakKind; model_peak is taken the same way.
  PeakKind peak_kind{PeakKind::kMaximum};
  double measured_damping{0.0};
  double model_damping{0.0};
  Eigen::Vector3d model_shape_T{Eigen::Vector3d::Zero()};
  double freq_error() const { return model_freq_hz / measured_freq_hz - 1.0; }  // relative
  double peak_error() const { return model_peak / measured_peak - 1.0; }       // relative
};

/// The postures, by id, that a calibration or comparison uses.
using PostureMap = std::map<std::string, Eigen::VectorXd>;  // q [rad]

/// The peak contribution of a model mode in the FRF H_re, as the matching
/// measures visibility (MatchOptions::min_relative_visibility):
/// |p_r p_e| / (2ζω²), ζ floored at 1e-6 so an undamped mode stays finite.
double ModelModeVisibility(const dynamics::Mode& mode, const dynamics::FrfKey& key);

/// Peak of |H_model| for the FRF `key` near a model mode, on the same
/// definition as MeasuredMode::peak_magnitude: the maximum within
/// PeakSearchWindow, whose neighbours are the other modes of the posture
/// that show in this FRF (peak contribution at least 1e-3 of the largest;
/// the measurement's neighbours are the modes its fit found), or, with
/// `kind` kShoulder (the measured mode's kind: both sides of a match use one
/// definition), |H_model| at the mode's own resonance OwnResonanceHz.
/// Returns {frequency [Hz], |H| [m/N]}.
std::pair<double, double> ModelPeak(const dynamics::PostureDynamics& d, const dynamics::FrfKey& key,
                                    int model_mode, PeakKind kind = PeakKind::kMaximum);

/// Matches measured modes to model modes by frequency and tool-tip direction
/// (greedy on the cost |ln f ratio| + w |ln visibility ratio|, one-to-one
/// per FRF), and fills in the model's features.
std::vector<ModeMatch> MatchModes(const std::map<std::string, dynamics::PostureDynamics>& model,
                                  const MeasuredFeatures& features, const MatchOptions& options = {});

/// The two residuals of the whole-curve objective at one line, from the
/// model's and the measured receptance: the log-magnitude error ln|Hm/H|
/// and the chord 2 sin(Δφ/2) of the phase error Δφ = arg(Hm/H). The chord
/// equals Δφ to O(Δφ³) but, unlike Δφ wrapped to (−π, π], is smooth where
/// the phase error passes ±π; wrapped phases gave numeric derivatives of
/// 2π/h there and stalled whole-curve fits for dozens of iterations.
///
/// Computed without a complex division, atan2 or sin (the audit evaluates it
/// for every line at every numeric-derivative step): with z = Hm conj(H),
/// cos Δφ = Re z/|z|, sin Δφ = Im z/|z|, and 2 sin(Δφ/2) = sin Δφ / cos(Δφ/2)
/// for cos Δφ >= 0 (no cancellation near Δφ = 0), ±2 √((1 − cos Δφ)/2)
/// otherwise (none near ±π). Agrees with ln|Hm/H|, 2 sin(arg(Hm/H)/2) to
/// round-off (tested).
inline std::array<double, 2> WholeCurveResiduals(std::complex<double> h_model, std::complex<double> h_measured) {
  const double nm = std::norm(h_model), nh = std::norm(h_measured);
  const double zr = h_model.real() * h_measured.real() + h_model.imag() * h_measured.imag();
  const double zi = h_model.imag() * h_measured.real() - h_model.real() * h_measured.imag();
  const double inv = 1.0 / std::sqrt(nm * nh);  // 1/|z|
  const double c = zr * inv, s = zi * inv;
  const double chord = c >= 0.0 ? s / std::sqrt(0.5 * (1.0 + c)) : std::copysign(2.0 * std::sqrt(0.5 * (1.0 - c)), s);
  return {0.5 * std::log(nm / nh), chord};
}

/// Whole-curve error of the model against one measured FRF over a band:
/// the rms over the lines of the residual pair of WholeCurveResiduals (as a
/// complex-magnitude rms: √(mean(r_mag² + r_phase²))). When the FRF carries
/// a noise model (Frf::noise_sigma) each residual is divided by its standard
/// deviation (LogResidualWeights), so the error is in units of the noise:
/// about √2 for a model that is right (both residuals of a line count).
double WholeCurveError(const dynamics::PostureDynamics& d, const dynamics::FrfKey& key,
                       const dynamics::Frf& measured, double fmin_hz, double fmax_hz);

/// How well a model fits measurements: matches per posture and summary errors.
struct Comparison {
  std::vector<ModeMatch> matches;
  std::vector<int> unmatched_measured;                  // indices in features.modes
  std::map<dynamics::FrfKey, double> whole_curve_error; // see WholeCurveError
  double max_abs_freq_error{0.0};                       // relative
  double max_abs_peak_error{0.0};                       // relative
  double rms_freq_error{0.0};
  double rms_peak_error{0.0};
};

/// Evaluates `model` at the postures and compares it with `measured`.
/// @throws std::invalid_argument if a measured posture is not in `postures`.
Comparison CompareWithMeasurement(const std::shared_ptr<const dynamics::RobotModel>& model,
                                  const PostureMap& postures, const dynamics::FrfSet& measured,
                                  const MeasuredFeatures& features, const MatchOptions& options = {},
                                  double fmin_hz = 0.0,
                                  double fmax_hz = std::numeric_limits<double>::infinity());

// ---------------------------------------------------------- calibration --

enum class Objective {
  kModalTwoStage,  // stage 1 natural frequencies, stage 2 peak amplitudes (the seed's procedure)
  kModalJoint,     // both feature kinds in one problem
  kWholeCurve,     // log-magnitude and phase residuals per line over a band
};
std::string ToString(Objective o);
/// "modal-two-stage", "modal-joint", "whole-curve"; @throws std::invalid_argument.
Objective ParseObjective(const std::string& name);

struct CalibrationOptions {
  Objective objective{Objective::kModalTwoStage};
  /// Names of the free parameters (any in the model's ParameterSet).
  std::vector<std::string> free_parameters{"m6_kg", "d6_m", "alpha_s", "beta_per_s"};
  MatchOptions matching;
  ModalFitOptions modal_fit;
  /// Expected scatter of the features, used as residual weights in the
  /// joint objective: relative natural frequency and relative peak amplitude.
  double freq_sigma{0.001};
  double peak_sigma{0.01};
  /// Band of the whole-curve objective [Hz].
  double fmin_hz{0.0};
  double fmax_hz{std::numeric_limits<double>::infinity()};
  int max_iterations{100};
  /// Rounds of (match, solve) while the matching changes.
  int max_match_rounds{3};
  /// A parameter is weakly identified if its standard deviation exceeds this
  /// fraction of its value.
  double weak_relative_std{0.1};
  /// Further starts when the fit from the given values does not lower the
  /// whole-curve misfit (WholeCurveMisfit), ends with a parameter on a
  /// bound or does not converge: the free parameters at their library
  /// defaults, and for a modal objective a whole-curve fit from the best
  /// result so far. The best by misfit is kept.
  bool extra_starts{true};
  /// Robust loss on the whole-curve objective (issue #33 §4, the second
  /// line of defence after the noise model's outlier lines): each line's
  /// pair of residuals r (log magnitude and phase chord, in units of the
  /// noise when the data carry a noise model) enters the cost through
  /// Huber's ρ(s) = s for s = |r|² <= c², 2 c |r| − c² above [Huber 1964],
  /// c = robust_scale (3: lines beyond 3 σ count linearly, a Gaussian line
  /// passes it with probability e^-4.5 = 1 %). The solver sees √ρ per line
  /// (both residuals scaled by √ρ / |r|), and the misfit that compares the
  /// starts (WholeCurveMisfit) uses the same ρ. 0: plain least squares, the
  /// default (the audit's BIC and the calibration's covariance assume it).
  /// - [Huber 1964] P. J. Huber, Robust estimation of a location parameter,
  ///   Ann. Math. Statist. 35(1), 73-101, 1964.
  double robust_scale{0.0};

  /// free_parameters not empty (their names are checked against the model
  /// by Calibrate); matching and modal_fit valid (their fields named
  /// "matching.direction_weight", "modal_fit.max_order"); freq_sigma and
  /// peak_sigma > 0 and finite; 0 <= fmin_hz < fmax_hz; max_iterations and
  /// max_match_rounds >= 1; weak_relative_std > 0; robust_scale finite and
  /// >= 0 (0: no robust loss).
  /// @throws OptionError naming the field, its value and the bound.
  void Validate() const;
};

/// kNotImproved: no start lowered the whole-curve misfit below that of the
/// start values, which the result keeps.
using FitStatus = SolverStatus;  // the library's one solver status

struct ParameterEstimate {
  std::string name;
  std::string unit;
  double initial{0.0};
  double value{0.0};
  double std_dev{NAN};         // 1 sigma from the covariance, scaled by the residual variance
  bool weakly_identified{false};
  bool at_bound{false};
  std::string stage;           // which stage fitted it
};

struct StageSummary {
  std::string name;                        // "frequencies", "peak amplitudes", "joint", "whole curve"
  std::vector<std::string> parameters;
  std::string termination;                 // Ceres termination type
  std::string message;                     // ceres::Solver::Summary::message, verbatim
  int iterations{0};
  int num_residuals{0};
  double initial_cost{0.0};
  double final_cost{0.0};
  bool covariance_ok{false};
};

struct CalibrationResult {
  FitStatus status{FitStatus::kFailed};
  std::string message;
  dynamics::ParameterSet parameters;       // the full set with calibrated values
  std::vector<ParameterEstimate> estimates;
  std::vector<StageSummary> stages;
  std::vector<std::string> weakly_identified;
  std::vector<ModeMatch> matches_before;   // matching at the initial values
  std::vector<ModeMatch> matches_after;
  /// WholeCurveMisfit of the start values and of the result: the result is
  /// accepted only if it is lower.
  double misfit_start{NAN};
  double misfit_final{NAN};
  /// Which start gave the result: "given", "defaults", "whole-curve polish",
  /// or "none (start kept)".
  std::string start_used;
  int starts_tried{0};
  /// Covariance of the free parameters' values (options.free_parameters
  /// order, parameter units): each stage's ceres::Covariance scaled by its
  /// residual variance; block-diagonal over the stages of the two-stage
  /// objective (the peak-amplitude stage's parameters are conditional on
  /// the frequency stage's, held at their fitted values); NaN rows and
  /// columns for a parameter without a covariance (held on a bound, or a
  /// stage whose covariance could not be computed). Empty if none.
  Eigen::MatrixXd covariance;
};

/// What --uncertainty-out writes of a calibration (docs/formats.md §12).
struct FittedUncertainty {
  /// The fitted parameters with a covariance, on the log scale (positive
  /// values: what a fit of a mass, a length or a damping coefficient
  /// determines is its relative error) or linear (a value <= 0).
  dynamics::ParameterUncertainty uncertainty;
  /// The free parameters left out, with why ("alpha_s: held on a bound,
  /// no covariance"; "beta_per_s: not determined, σ 240 % of its value").
  /// A parameter left out is taken as exact by the tools that read the file.
  std::vector<std::string> left_out;
};

/// The result's estimates and covariance as a parameter uncertainty.
/// A parameter without a covariance, or whose standard deviation exceeds
/// its value (the data do not determine it), is left out and named.
/// `source` names the tool and data ("frf-calibrate on hammer.csv").
FittedUncertainty FittedParameterUncertainty(const CalibrationResult& result, const std::string& source);

/// The whole-curve misfit of a model against measured FRFs in a band: the
/// sum over lines of the squared log-magnitude and phase residuals
/// (WholeCurveResiduals), each in units of its noise when the FRF carries a
/// noise model (LogResidualWeights) — the χ² of the data; +inf if the model
/// cannot be built or evaluated.
double WholeCurveMisfit(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                        const PostureMap& postures, const dynamics::FrfSet& measured,
                        double fmin_hz = 0.0, double fmax_hz = std::numeric_limits<double>::infinity(),
                        double robust_scale = 0.0);

/// Huber's ρ(s) of a line's squared residual s with scale c (CalibrationOptions::robust_scale):
/// s for s <= c² (and for c <= 0), 2 c √s − c² above.
double HuberRho(double s, double c);

/// Calibrates `options.free_parameters` of `description` starting from
/// `initial` against `measured` (with its modal `features`) at `postures`.
/// Ceres Levenberg–Marquardt with central numeric derivatives (the model is
/// double-only through KDL); parameters are scaled by their initial values
/// and kept within their ParameterSpec bounds. Uncertainty: ceres::Covariance
/// of each stage scaled by the residual variance 2 F / (m − n).
///
/// Two-stage: the free parameters that move the natural frequencies are
/// fitted to them first (Rayleigh damping does not move undamped frequencies,
/// so alpha_s and beta_per_s fall into the second stage automatically), then
/// the rest to the peak amplitudes with the first ones fixed.
///
/// The result must fit better than the start: its WholeCurveMisfit must be
/// lower than that of `initial`; otherwise further starts are tried
/// (CalibrationOptions::extra_starts) and, if none does better, the start
/// values are kept with status kNotImproved. "converged" is never the status
/// of a model that fits worse than where it began.
///
/// Not converged, a failed stage or an unidentifiable parameter are a status
/// and flags in the result, not exceptions.
/// @throws std::invalid_argument for an unknown or non-fittable parameter name,
///   or a measured posture missing from `postures`.
CalibrationResult Calibrate(const dynamics::RobotDescription& description,
                            const dynamics::ParameterSet& initial, const PostureMap& postures,
                            const dynamics::FrfSet& measured, const MeasuredFeatures& features,
                            const CalibrationOptions& options = {});

/// A calibrated model is flagged when its rms whole-curve residual exceeds
/// this many noise standard deviations: the audit's significance factor
/// (audit::AuditOptions::significance_factor).
inline constexpr double kCalibrationMisfitFlagNoiseUnits = 1.3;

/// The verdict on a calibration (frf-calibrate's exit 3, Python's
/// judge_calibration): kFlagged, with one finding each, when no start
/// improved on the start values, a stage did not converge or failed, a
/// parameter is weakly identified, or - when every measured FRF carries a
/// noise model, so that the misfit is a chi^2 - the rms residual exceeds
/// kCalibrationMisfitFlagNoiseUnits (the model cannot represent the data with
/// its free parameters: another effect, another robot). The findings are in
/// `verdict` (as in every result, issue #36); beside them, the misfit they
/// were judged on.
struct CalibrationVerdict {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  int residuals{0};  // two per measured line in the band
  /// sqrt(misfit_final / residuals) with noise models; NaN without.
  double rms_per_residual_in_noise_units{NAN};
};

/// `measured` and the band of `options` as given to Calibrate.
CalibrationVerdict JudgeCalibration(const CalibrationResult& result, const dynamics::FrfSet& measured,
                                    const CalibrationOptions& options);

}  // namespace robomach::calibration
