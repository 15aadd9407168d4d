#pragma once
// frf-predict as one library call (issue #36 §1): a robot config (with
// effects switched on and parameters set), a posture file and a frequency
// grid -> the tool-tip receptance, the modes and, with parameter
// uncertainty, the modes' intervals and the |H| bands -> the verdict and
// the summary the tool writes. The tool parses its options into
// FrfPredictOptions and writes what RunFrfPredict returns; Python's
// run_frf_predict binds the same call.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/frf_prediction.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/dynamics/uncertainty.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/robot_config.h"

namespace robomach::workflows {

/// Switches on the effects named in `adds` (with their default parameters)
/// and applies `sets` ("NAME=VALUE" in the parameter's unit) to `config`,
/// in that order: the tools' --add and --set.
/// @throws OptionError with field "adds" ("adds NAME: why") or "sets"
///   ("sets TEXT: why").
void ApplyAddsAndSets(const std::vector<std::string>& adds, const std::vector<std::string>& sets,
                      io::RobotConfig* config);

/// The parameter uncertainty of `files` put into `config`: the files'
/// estimates replace the config's parameters (a note says which changed),
/// since an estimate goes with its covariance. The tools' --uncertainty
/// (or the config's `uncertainty:` files). No files: nullopt, `config`
/// untouched.
/// @throws OptionError "sets" when `sets` ("NAME=VALUE", the tools' --set)
///   names a parameter the files estimate; the readers' errors.
std::optional<dynamics::ParameterUncertainty> UseUncertaintyFiles(const std::vector<std::string>& files,
                                                                  const std::vector<std::string>& sets,
                                                                  io::RobotConfig* config, const MessageSink& tell);

/// The lines fmin_hz, fmin_hz + df_hz, ... up to fmax_hz [Hz].
/// @throws OptionError naming fmin_hz, fmax_hz and df_hz: not finite,
///   0 <= fmin_hz < fmax_hz and df_hz > 0 violated, fewer than 2 lines
///   (df_hz), or more lines than dynamics::kMaxFrequencyLines (with the likely unit mistake when
///   fmax_hz is beyond dynamics::kMaxPlausibleFmaxHz).
Eigen::VectorXd FrequencyGrid(double fmin_hz, double fmax_hz, double df_hz);

/// A frequency file: a CSV with a freq_hz column, strictly increasing, >= 0.
/// @throws InputError with file, line and column.
Eigen::VectorXd ReadFrequencyFile(const std::string& path);

/// frf-predict's options, field by field (robot_path is --robot,
/// postures_path --postures, adds --add, sets --set, uncertainty_paths
/// --uncertainty).
struct FrfPredictOptions {
  std::string robot_path;     // robot config YAML
  std::string postures_path;  // posture file (formats.md §1)
  Eigen::VectorXd freq_hz;    // the lines [Hz] (FrequencyGrid or ReadFrequencyFile)
  std::string method{"modal"};  // modal (superposition) or direct (solve per line)
  std::vector<std::string> adds;
  std::vector<std::string> sets;
  /// Parameter uncertainty (formats.md §12): the estimates replace the
  /// config's values. Used only when `intervals` or `band_postures` asks
  /// for what it gives; then empty takes the config's `uncertainty:` files.
  std::vector<std::string> uncertainty_paths;
  dynamics::PropagationOptions uncertainty;
  bool intervals{false};     // each mode's interval per posture (--modes, --summary)
  size_t band_postures{0};   // the |H| band of the first N postures (the plots)
  /// The size of the FRF CSV in the bound's message: direction pairs written.
  size_t direction_pairs{9};

  /// @throws OptionError naming the field: a path empty, no frequency line,
  ///   a negative or non-finite or not increasing line, method not modal
  ///   or direct, the uncertainty's options.
  void Validate() const;
};

/// Postures x lines computed before anything is written (no partial outputs):
/// 2e6 is a 100-posture campaign on a 20 000-line grid, about 1 GB of CSV
/// with all nine direction pairs.
inline constexpr double kMaxFrfPredictLines = 2e6;

struct FrfPredictRun {
  io::RobotConfig config;  // as used: effects added, parameters set, the uncertainty's estimates
  std::shared_ptr<const dynamics::RobotModel> model;
  std::vector<io::Posture> postures;
  std::vector<io::PosturePrediction> predictions;  // per posture, on the options' lines
  std::vector<dynamics::PostureDynamics> dynamics;  // per posture: J, M, K, C, modes
  RunStatus prediction_status{RunStatus::kOk};      // PredictFrfs' (its findings are `warnings`)
  /// The findings of the prediction, each with the posture file's line
  /// ("postures.csv:4: joint 2 ..."); told as warnings.
  std::vector<std::string> warnings;
  /// The config's and the posture file's unit findings ("implausible (unit
  /// mistake?): ..."), told as warnings: they flag the run.
  std::vector<std::string> unit_findings;
  std::optional<dynamics::ParameterUncertainty> uncertainty;
  std::vector<std::string> uncertainty_files;  // the files it came from
  std::vector<dynamics::PostureModeIntervals> intervals;  // per posture, with `intervals`
  std::vector<dynamics::ReceptanceBand> bands;            // the first band_postures postures

  bool flagged() const { return prediction_status != RunStatus::kOk || !unit_findings.empty(); }
  RunStatus status() const { return !unit_findings.empty() ? RunStatus::kFlagged : prediction_status; }
  /// frf-predict --summary (formats.md §4.1): robot, parameters, per
  /// posture J, cond(J), M_q, K_q, C_q, the Cartesian matrices, compliance
  /// and modes (with their intervals), and the uncertainty used.
  nlohmann::json Summary(const FrfPredictOptions& options, const std::string& method_name) const;
};

/// What a run reports as it goes: `stage` ("postures", "postures'
/// intervals", "|H| bands") `done` of `total`.
using StageProgress = std::function<void(const std::string& stage, long done, long total)>;

/// Loads the config (its unit findings are warnings), applies adds and
/// sets, reads the uncertainty (a set parameter that the uncertainty also
/// gives is an OptionError on "sets"), reads the postures (their unit
/// findings are warnings), predicts, and computes the intervals and bands
/// asked for; the intervals' lines and the bands' method are kInfo messages.
/// @throws OptionError ("postures_path") when postures x lines exceeds
///   kMaxFrfPredictLines; InputError from the files.
FrfPredictRun RunFrfPredict(const FrfPredictOptions& options, const MessageSink& on_message = {},
                            const StageProgress& progress = {});

}  // namespace robomach::workflows
