#pragma once
// frf-calibrate as one library call (issue #36 §1): a robot config (with
// effects switched on and parameters set), a posture file and measured
// tool-tip FRFs (with held-out ones) -> the noise models, the modal fits,
// the calibrated parameters, the comparison with the measurement before and
// after, the calibrated config's text and the verdict. The tool parses its
// options into FrfCalibrateOptions and writes what RunFrfCalibrate returns
// (the config, the report folder); model-audit reads its FRFs the same way.

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/robot_config.h"
#include "robomach/workflows/measured_frfs.h"

namespace robomach::workflows {

/// The noise options of the tools that read measured FRFs (--noise-model,
/// --min-snr, --averages, --drift-floor; MeasuredFrfOptions' meaning).
struct FrfNoiseOptions {
  std::string noise_model{"auto"};  // auto, coherence, scatter, none
  double min_snr{calibration::NoiseOptions{}.min_snr};
  int averages{0};  // 0: from each file's '# averages: N'
  bool drift_floor{false};

  /// @throws OptionError naming the field, its value and the bound:
  /// noise_model one of auto, coherence, scatter, none; min_snr in
  /// [0.001, 1e6] and averages in [0, 1e6] (MeasuredFrfOptions' bounds).
  void Validate() const;
};

/// The measured-FRF route's options (measured_frfs.h) for `files` and
/// `pose_files` ("ID=file.uff"), the files named `what` in messages and the
/// ID=file form `pose_name` (the tools: "--pose").
/// @throws OptionError on `pose_field` ("pose_field 'TEXT': expected
///   ID=file.uff, e.g. pose_field P1=p1.uff") for a malformed ID=file.
MeasuredFrfOptions MeasuredFilesRoute(const std::vector<std::string>& files,
                                      const std::vector<std::string>& pose_files, const std::string& pose_field,
                                      const std::string& pose_name, const std::string& what);

/// EstimateNoiseModels (measured_frfs.h) with `noise`, min_snr and averages
/// checked first ("min_snr: expected a value in [0.001, 1e+06], got 0").
/// @throws OptionError: those bounds; noise_model or averages when the data
///   cannot meet them (EstimateNoiseModels' message, for the caller to
///   prefix with the option).
calibration::NoiseModels EstimateNoise(const MeasuredFrfs& data, const FrfNoiseOptions& noise,
                                       const MessageSink& tell = {});

/// frf-calibrate's options, field by field (robot_path is --robot,
/// postures_path --postures, measured_files --measured, pose_files --pose,
/// validate_files --validate, validate_pose_files --validate-pose, frees
/// --free, sets --set, adds --add, out_path --out).
struct FrfCalibrateOptions {
  std::string robot_path;     // robot config YAML
  std::string postures_path;  // posture file (formats.md §1)
  std::vector<std::string> measured_files;       // CSV or UFF58
  std::vector<std::string> pose_files;           // "ID=file.uff": a file of one posture
  std::vector<std::string> validate_files;       // held out, scored with the calibrated model
  std::vector<std::string> validate_pose_files;  // "ID=file.uff", held out
  /// Where the calibrated config goes: its relative `urdf:` path is made
  /// valid from there (the text is built, not written).
  std::string out_path;
  std::vector<std::string> frees;  // fitted besides the default ones
  bool only_free{false};           // fit only `frees`
  std::vector<std::string> sets;   // "NAME=VALUE", start values
  std::vector<std::string> adds;   // effects switched on
  std::string objective{"modal-two-stage"};  // modal-two-stage, modal-joint, whole-curve
  double fmin_hz{calibration::CalibrationOptions{}.fmin_hz};
  double fmax_hz{calibration::CalibrationOptions{}.fmax_hz};
  int max_iterations{calibration::CalibrationOptions{}.max_iterations};  // per stage
  double robust_loss_sigma{calibration::CalibrationOptions{}.robust_scale};  // Huber scale [noise]; 0: none
  FrfNoiseOptions noise;
  /// How the messages name the ID=file form (the tool: "--pose", "--validate-pose").
  std::string pose_files_name{"pose_files"}, validate_pose_files_name{"validate_pose_files"};

  /// @throws OptionError naming the field, its value and bound:
  ///   max_iterations outside [1, 100000], robust_loss_sigma outside
  ///   [0, 1e6], fmin_hz below 0 or fmax_hz not above fmin_hz (both
  ///   values named), no measured_files nor pose_files, an unknown objective, no
  ///   free parameter (only_free without frees).
  void Validate() const;
  /// The calibration's options: the objective, the free parameters
  /// (defaults unless only_free, then frees), the band and iterations.
  calibration::CalibrationOptions Calibration() const;
};

/// Everything frf-calibrate prints and writes.
struct FrfCalibrateRun {
  io::RobotConfig config;  // as calibrated from: effects added, parameters set
  calibration::CalibrationOptions options;  // as used
  std::shared_ptr<const dynamics::RobotModel> model_before, model_after;
  calibration::PostureMap postures;
  MeasuredFrfs measured_read, holdout_read;  // every line as read, with the unit findings
  calibration::NoiseModels noise, holdout_noise;
  dynamics::FrfSet measured, holdout;  // the usable lines the fit and the scores use
  /// Every measured line (the held-out FRFs too) with its noise model: the overlays.
  dynamics::FrfSet all_measured;
  calibration::NoiseModels all_noise;
  calibration::MeasuredFeatures features, holdout_features;  // the modal fits
  calibration::CalibrationResult result;
  /// The model before and after calibration against the measured modes
  /// (fit) and the held-out ones (holdout, with held-out FRFs).
  calibration::Comparison fit_before, fit_after, holdout_before, holdout_after;
  std::string config_text;  // the calibrated config (io::CalibratedConfigText)
  calibration::CalibrationVerdict verdict;
  /// What flags the run (exit 3), each told as a warning: the measured and
  /// held-out unit findings, the config's, the posture file's, the verdict's.
  std::vector<std::string> flags;

  RunStatus status() const { return flags.empty() ? RunStatus::kOk : RunStatus::kFlagged; }
  /// summary.json's `misfit`: start, calibrated, rms per residual in noise
  /// units, starts tried, start used and the flags.
  nlohmann::json Misfit() const;
  /// The lines the tool prints last (without its name): per set the matched
  /// modes and largest errors, each estimate, the whole-curve misfit.
  std::vector<std::string> ResultLines() const;
};

/// Loads the config (its unit findings are warnings), applies adds and
/// sets, reads the postures and the measured and held-out FRFs with their
/// noise models, fits the modes (a warning per failed modal fit), calibrates
/// (kInfo lines before the modal fits and the calibration), compares, builds
/// the calibrated config's text and judges: then tells a warning when the
/// config's `effects:` list is left out, for each of the posture file's
/// unit findings and each of the verdict's findings.
/// @throws OptionError (Validate; adds, sets, frees naming an unknown
///   parameter, pose_files, validate_pose_files, min_snr, noise_model,
///   averages); InputError and io::MissingFileError for the files.
FrfCalibrateRun RunFrfCalibrate(const FrfCalibrateOptions& options, const MessageSink& tell = {});

}  // namespace robomach::workflows
