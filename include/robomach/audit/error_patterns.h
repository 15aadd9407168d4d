#pragma once

// Where a model fails, as patterns (issue #5 §2.2): the trend of the error
// against posture descriptors with its correlation, the error map of
// postures against modes, and the modes without a counterpart in either
// direction (measured modes the model lacks, model modes the measurement
// does not show). Computed from an AuditResult after RunAudit; nothing here
// fits anything.

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/audit/model_audit.h"
#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::audit {

// ------------------------------------------------------------ descriptors --

/// Quantities a posture-dependent failure may follow, one row per posture.
struct PostureDescriptors {
  std::vector<std::string> pose_ids;  // rows
  /// Columns: "q1" … "qn" [rad]; "reach" [m], the horizontal distance of
  /// the TCP from the base z axis, √(x² + y²) of p_BT; "height" [m], z of
  /// p_BT; "gravity_torque_j2", "gravity_torque_j3" [N·m], G_2 and G_3 of
  /// dynamics::GravityTorque (signed: the torque the drive supplies).
  std::vector<std::string> names;
  std::vector<std::string> units;     // "rad", "m", "Nm" (ASCII: they go into PNG labels and CSV)
  Eigen::MatrixXd values;             // pose_ids.size() × names.size(), SI
};

/// The descriptors of `pose_ids` (each must be in `postures`) for `model`.
/// @throws std::invalid_argument naming a pose id missing from `postures`.
PostureDescriptors DescribePostures(const dynamics::RobotModel& model, const calibration::PostureMap& postures,
                                    const std::vector<std::string>& pose_ids);

// ----------------------------------------------------------------- trends --

/// One descriptor against the per-posture error.
struct Trend {
  std::string descriptor;
  std::string unit;
  Eigen::VectorXd values;               // per posture, in ErrorTrends::pose_ids order, SI
  /// Pearson r with ErrorTrends::error_before; NaN if undefined (no spread)
  /// or with fewer than 3 postures (two points always give r = ±1).
  double correlation_before{NAN};
  double correlation_after{NAN};        // with error_after; NaN without an accepted candidate
  /// |r| > ErrorTrends::critical_correlation, and the errors are a failure
  /// at some posture (ErrorTrends::failing_before / failing_after).
  bool significant_before{false};
  bool significant_after{false};
};

struct ErrorTrends {
  std::vector<std::string> pose_ids;
  /// rms log-magnitude error per posture over all lines of its FRFs (the
  /// CurveError rms values pooled by their line counts), of the calibrated
  /// current model and of the accepted candidate (empty if none).
  Eigen::VectorXd error_before;
  Eigen::VectorXd error_after;
  int n{0};                             // postures
  double significance_level{0.05};
  /// |r| above this rejects "no correlation" at significance_level
  /// (CriticalCorrelation(n)); NaN for n < 3. With five postures it is 0.88:
  /// a trend is only indicative, and one outlying posture can make or break it.
  double critical_correlation{NAN};
  /// Some posture's error exceeds significance_factor × the noise floor.
  /// Errors that are all consistent with the noise have no pattern to
  /// explain: their correlations describe the noise, and with ten
  /// descriptors one in two audits would show a "significant" one at 5 %.
  bool failing_before{false};
  bool failing_after{false};
  std::vector<Trend> trends;            // in PostureDescriptors::names order
};

/// rms log-magnitude error per posture of `errors` (pooled over the FRFs of
/// each posture by their line counts), in `pose_ids` order; NaN for a
/// posture without lines.
Eigen::VectorXd ErrorPerPosture(const ModelErrors& errors, const std::vector<std::string>& pose_ids);

// ---------------------------------------------------------- mode error map --

/// Relative errors per posture (rows) and model mode (columns). A model mode
/// matched in several FRFs of a posture (Hxx and Hyy) takes the match where
/// the measured peak is largest: there the measured mode is best determined.
struct ModeErrorMap {
  std::vector<std::string> pose_ids;  // rows, every measured posture
  std::vector<int> modes;             // columns: model mode numbers, 1-based, ascending
                                      // frequency; every mode matched at some posture
  Eigen::MatrixXd freq_error;         // f_model / f_measured − 1; NaN where no match
  Eigen::MatrixXd peak_error;         // peak_model / peak_measured − 1; NaN where no match
  Eigen::MatrixXi match;              // index in `matches`, −1 where no match
  std::vector<calibration::ModeMatch> matches;  // Comparison::matches the map was built from
};

/// The map of the matches in `comparison` over the postures of `pose_ids`.
ModeErrorMap BuildModeErrorMap(const calibration::Comparison& comparison, const std::vector<std::string>& pose_ids);

// ------------------------------------------------------- unmatched modes --

/// A mode seen on one side only, in one measured FRF.
struct UnmatchedMode {
  dynamics::FrfKey key;              // posture and direction
  double freq_hz{0.0};               // natural frequency [Hz]
  double damping_ratio{0.0};
  /// Peak contribution |p_r p_e| / (2ζω²) of the model mode, or the fitted
  /// one of the measured mode (FittedMode::peak_contribution) [m/N].
  double peak_contribution{0.0};
  /// peak_contribution over the largest of its side in the same FRF and band.
  double relative_visibility{0.0};
  int model_mode{-1};     // 0-based PostureDynamics::modes index; −1 for a measured mode
  int measured_mode{-1};  // index in MeasuredFeatures::modes; −1 for a model mode
};

struct ErrorPatternOptions {
  /// The audit's band [Hz] (AuditOptions::fmin_hz, fmax_hz).
  double fmin_hz{0.0};
  double fmax_hz{std::numeric_limits<double>::infinity()};
  /// The matching RunAudit compared the modes with (its defaults). A model
  /// mode counts as visible in an FRF if its peak contribution reaches
  /// matching.min_relative_visibility of the largest of the model modes
  /// inside the FRF's band; the second pass (see ErrorPatterns) uses
  /// max_log_freq_ratio and direction_weight.
  calibration::MatchOptions matching;
  /// Level of the correlation test.
  double significance_level{0.05};
  /// A posture fails if its error exceeds this factor × AuditResult::noise_floor
  /// (AuditOptions::significance_factor, same default).
  double significance_factor{AuditOptions{}.significance_factor};

  /// 0 <= fmin_hz < fmax_hz; matching valid (MatchOptions::Validate:
  /// min_relative_visibility in (0, 1], max_log_freq_ratio > 0,
  /// direction_weight >= 0 and finite; fields named "matching.FIELD");
  /// significance_factor >= 1; significance_level in (0, 1).
  /// @throws OptionError naming the field ("matching.direction_weight"), its
  ///   value and the bound.
  void Validate() const;
};

/// Everything of this header for one audit.
struct ErrorPatterns {
  PostureDescriptors descriptors;
  ErrorTrends trends;
  ModeErrorMap mode_map;
  /// The matching (calibration::MatchModes) tries only modes above its
  /// visibility rule, on both sides, against the largest in the FRF. A weak
  /// mode it left alone may still have a counterpart (a high mode's
  /// receptance peak is naturally small; a mode seen mostly in another
  /// direction is weak in this one). So a second pass pairs, per FRF, the
  /// measured and model modes (inside the band) that the matching left
  /// over, with the matching's cost |ln f ratio| + w |ln visibility ratio|
  /// and frequency window, greedily one to one, but without the visibility
  /// rule. Those pairs are counted in `weak_pairs`; what stays unpaired has
  /// no counterpart:
  ///
  /// Measured modes without a model counterpart, in FRF key order, then by
  /// frequency (every one: the modal fit already dropped computational modes).
  std::vector<UnmatchedMode> unmatched_measured;
  /// Model modes without a measured counterpart that are visible by the
  /// rule (see ErrorPatternOptions::matching) inside the FRF's band; in FRF
  /// key order, then by frequency.
  std::vector<UnmatchedMode> unmatched_model;
  int weak_pairs{0};
  /// FRFs whose modal fit found no mode (its status is not kOk): no model
  /// mode is reported unmatched there, since nothing could have matched it.
  std::vector<dynamics::FrfKey> frfs_without_modal_fit;
};

/// The modal-fit options RunAudit extracts the measured features with: the
/// defaults restricted to the audit's band. ExtractFeatures with them
/// reproduces the features AuditResult::modes_before indexes into (the fit is
/// deterministic).
calibration::ModalFitOptions AuditModalFitOptions(const AuditOptions& options);

/// The error patterns of an audit.
///
/// @param result    RunAudit's result: errors_before, modes_before and, if
///                  result.best >= 0, that candidate's errors.
/// @param model     the calibrated current model (description with
///                  result.baseline_fit.parameters); descriptors and model
///                  modes come from it.
/// @param postures  q [rad] per posture id; every measured posture.
/// @param measured  the measured FRFs of the audit.
/// @param features  the measured modes that result.modes_before indexes
///                  (ExtractFeatures(measured, AuditModalFitOptions(...))).
/// @throws std::invalid_argument if a measured posture is missing from
///   `postures`, or `features` is not the one `result` was matched with
///   (a match's measured index out of range or naming another FRF or
///   frequency).
ErrorPatterns AnalyzeErrorPatterns(const AuditResult& result,
                                   const std::shared_ptr<const dynamics::RobotModel>& model,
                                   const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                                   const calibration::MeasuredFeatures& features,
                                   const ErrorPatternOptions& options = {});

}  // namespace robomach::audit
