#pragma once

// model-audit's report folder (issue #5, #21): summary.json, index.html,
// errors.csv, candidates.csv, effects.yaml, the error-pattern files, the
// worst FRF and one overlay per posture. The tool reads, runs audit::RunAudit
// and calls WriteAuditReport; Python calls the same.
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/audit/model_audit.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::report {

struct AuditReportOptions {
  std::string robot_path;                  // shown in the report and summary.json
  std::vector<std::string> added_effects;  // switched on before the audit (model-audit --add)
  std::string noise_model{"auto"};         // as chosen (--noise-model), for the summary
  double min_snr{3.0};                     // as chosen (--min-snr)
  double fmin_hz{0.0};                     // the band of the audit
  double fmax_hz{1e300};
  double mostly_explained_fraction{0.5};   // the audit's thresholds, quoted in the report
  double clear_bic_gap{10.0};
  /// A previous audit's summary.json (null: none) and its folder, shown
  /// next to these errors (model-audit --compare).
  nlohmann::json previous;
  std::string compare_dir;
  std::function<void(const std::string&)> progress;  // may be empty
  /// Warnings the caller gave while reading the inputs (a file that looks
  /// like accelerance, a receptance of implausible size): in summary.json's
  /// `warnings` and the report, with the audit's own.
  std::vector<std::string> input_warnings;
  /// Where model-audit --write-config wrote the config with the named
  /// change (empty: not asked), for the report's "what to do".
  std::string written_config;
  /// What model-audit --uncertainty-out wrote ({"file", "parameters",
  /// "left_out"}; null: not asked), for summary.json.
  nlohmann::json uncertainty_out;

  /// @throws OptionError naming the field, its value and the bound:
  /// fmin_hz >= 0 and fmax_hz > fmin_hz (the band the error patterns are
  /// analysed in). The other numbers are only quoted in the report.
  void Validate() const;
};

struct AuditReport {
  nlohmann::json summary;        // what summary.json holds
  std::string effects_yaml;      // the YAML to add to the robot config (empty: none)
  bool failed_candidate{false};  // a candidate's fit failed (candidates.csv says why)
};

/// Writes the report of `result` into the folder `dir` (created; files of
/// an earlier run there that this one does not rewrite are removed). Each
/// file is written with io::WriteFileAtomically. `description` is the model
/// audited (added effects included); `measured_fit` the lines the fits
/// used, `measured_all` every measured line (the overlays show both);
/// `noise` the noise model of each FRF (empty: none).
/// @throws OptionError for bad options (AuditReportOptions::Validate).
AuditReport WriteAuditReport(const std::string& dir, const audit::AuditResult& result,
                             const dynamics::RobotDescription& description, const calibration::PostureMap& postures,
                             const dynamics::FrfSet& measured_fit, const dynamics::FrfSet& measured_all,
                             const calibration::NoiseModels& noise, const AuditReportOptions& options);

}  // namespace robomach::report
