#pragma once
// model-audit as one library call (issue #36 §1): a robot config (with
// effects switched on and the parameters' uncertainty), a posture file and
// measured tool-tip FRFs -> the noise models -> audit::RunAudit -> the
// change the audit names (with the config text that holds it) and the
// verdict. The tool parses its options into ModelAuditOptions and writes
// what RunModelAudit returns (the report folder, the config, the YAML).

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "robomach/audit/model_audit.h"
#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/io/robot_config.h"
#include "robomach/workflows/frf_calibrate.h"
#include "robomach/workflows/measured_frfs.h"

namespace robomach::workflows {

/// model-audit's options, field by field (robot_path is --robot,
/// postures_path --postures, measured_files --measured, pose_files --pose,
/// adds --add, uncertainty_paths --uncertainty, no_parameter_hypotheses
/// --no-parameter-hypotheses, write_config --write-config).
struct ModelAuditOptions {
  std::string robot_path;     // robot config YAML
  std::string postures_path;  // posture file (formats.md §1)
  std::vector<std::string> measured_files;  // CSV or UFF58
  std::vector<std::string> pose_files;      // "ID=file.uff": a file of one posture
  std::string pose_files_name{"pose_files"};  // how messages name the ID=file form (the tool: "--pose")
  /// Effects switched on before the audit; their fittable parameters are
  /// calibrated with the calibration parameters.
  std::vector<std::string> adds;
  /// Parameter uncertainty (formats.md §12): its estimates replace the
  /// config's values. Empty: the files the config names (`uncertainty:`).
  std::vector<std::string> uncertainty_paths;
  double confidence{audit::AuditOptions{}.uncertainty_confidence};  // of the uncertainty's region, in (0, 1)
  /// The whole list of candidates (audit::AuditOptions::candidates); empty: the default.
  std::vector<std::string> candidates;
  bool no_parameter_hypotheses{false};
  int virtual_joints{audit::AuditOptions{}.virtual_joints_fitted};  // fitted after the screen
  double fmin_hz{audit::AuditOptions{}.fmin_hz};
  double fmax_hz{audit::AuditOptions{}.fmax_hz};
  int max_iterations{audit::AuditOptions{}.max_iterations};  // per fit
  double robust_loss_sigma{audit::AuditOptions{}.robust_scale};  // Huber scale [noise]; 0: none
  FrfNoiseOptions noise;
  /// Where the config with the named change goes: with a change, its text
  /// is built (not written), a relative `urdf:` path made valid from there.
  /// Empty: no text.
  std::string write_config;

  /// @throws OptionError naming the field, its value and bound: fmin_hz
  ///   outside [0, 1e9], fmax_hz not above fmin_hz, max_iterations outside
  ///   [1, 100000], virtual_joints outside [0, 50], robust_loss_sigma
  ///   outside [0, 1e6], confidence outside (0, 1), an effect in adds
  ///   twice, no measured_files nor pose_files, an unknown effect in
  ///   candidates (names starting with kq are parameters).
  void Validate() const;
};

/// Everything model-audit prints and writes.
struct ModelAuditRun {
  io::RobotConfig config;  // as audited: effects added, the uncertainty's estimates
  calibration::PostureMap postures;
  MeasuredFrfs measured_read;  // every line as read, with the unit findings
  calibration::NoiseModels noise;
  dynamics::FrfSet measured;  // the usable lines every fit and error uses
  audit::AuditOptions audit_options;  // as used
  audit::AuditResult audit;
  /// The change the audit names: the named candidate (explained or mostly
  /// explained), or with no failure the calibrated current model (its fit
  /// the baseline's); none otherwise. In words: change_description.
  std::optional<audit::CandidateResult> change;
  std::string change_description;
  /// The config with the change (write_config given and a change named).
  std::string config_text;
  RunFindings verdict;  // audit::JudgeAudit

  /// model-audit's exit 3 but for its outputs: the verdict, a measured
  /// receptance or a config value of implausible unit.
  bool flagged() const {
    return verdict.flagged() || !measured_read.unit_findings.empty() || !config.implausible.empty();
  }
  RunStatus status() const { return flagged() ? RunStatus::kFlagged : RunStatus::kOk; }
};

/// Loads the config (its unit findings are warnings), switches on adds,
/// puts the uncertainty's estimates in (a note says which changed), reads
/// the postures and the measured FRFs with their noise models, checks the
/// band, audits (`progress`: one line per step) and builds the config text
/// of the named change. Warnings: a baseline calibration that did not
/// converge, a config whose flow-style `effects:` list is left out.
/// @throws OptionError (Validate; adds, uncertainty_paths, pose_files,
///   min_snr, noise_model, averages); InputError and io::MissingFileError
///   for the files (a measured posture not in the posture file, fewer than
///   3 lines in the band); std::invalid_argument from the audit.
ModelAuditRun RunModelAudit(const ModelAuditOptions& options, const MessageSink& tell = {},
                            const std::function<void(const std::string&)>& progress = {});

}  // namespace robomach::workflows
