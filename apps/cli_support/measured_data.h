#pragma once

// The command-line side of the measured-FRF route of the library
// (workflows/measured_frfs.h), shared by the tools that read hammer-test
// FRFs (frf-calibrate, model-audit, frf-modes): the same options and the
// same stderr lines in every tool.

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/workflows/frf_calibrate.h"
#include "robomach/workflows/measured_frfs.h"
#include "cli_support.h"

namespace CLI {
class App;
}

namespace robomach::apps {

/// The measured FRFs as read (the library's route, workflows::MeasuredFrfs).
using MeasuredData = workflows::MeasuredFrfs;

/// workflows::ReadMeasuredFrfFiles for the command line: `pose_files` are
/// "ID=file.uff" (UsageError when malformed), the library's notes and
/// warnings go to stderr under `tool`, a missing file is exit 66.
/// `default_pose`: the posture of a file whose FRFs name none (frf-modes:
/// "P1"); empty: such a file is refused with a message that suggests
/// `pose_option`.
MeasuredData ReadMeasuredFiles(const std::string& tool, const std::vector<std::string>& files,
                               const std::vector<std::string>& pose_files, const std::string& what,
                               const std::string& pose_option = "--pose", bool keep_points = false,
                               const std::string& default_pose = "");

/// The noise options of the command line.
struct NoiseCliOptions {
  /// "auto" (coherence if the FRF has one and the averages are known, else
  /// the scatter), "coherence" (required), "scatter", or "none" (no noise
  /// model: every line, relative weights, the behaviour before issue #10).
  std::string model{"auto"};
  double min_snr{calibration::NoiseOptions{}.min_snr};
  int averages{0};  // 0: from the file
  bool drift_floor{false};  // calibration::NoiseOptions::wide_floor
  bool global_modal_fit{false};  // calibration::NoiseOptions::global_modal_fit (frf-modes)

  /// The workflows' noise options (frf-calibrate, model-audit).
  workflows::FrfNoiseOptions Workflow() const { return {model, min_snr, averages, drift_floor}; }
};

/// --noise-model, --min-snr, --averages, --drift-floor.
void AddNoiseOptions(CLI::App& app, NoiseCliOptions* options);

/// workflows::EstimateNoiseModels with the command line's options: one
/// line per FRF on stderr (source, rel, floor, usable band), warnings for
/// FRFs with no usable line. @throws UsageError for options out of range
///   or inconsistent with the data (coherence asked for an FRF without
///   coherence or without a number of averages), naming the FRF and what
///   to give.
calibration::NoiseModels EstimateNoiseModels(const std::string& tool, const MeasuredData& data,
                                             const NoiseCliOptions& options);

/// --uncertainty-out of frf-calibrate and model-audit (issue #37): writes
/// calibration::FittedParameterUncertainty(result, source) to `path`
/// (docs/formats.md §12), says on stderr what it wrote and which fitted
/// parameters it left out, and returns that for the summary ({"file",
/// "written", "parameters", "left_out"}). When no parameter has a
/// covariance nothing is written (a file the reader refuses): a warning
/// says why and the summary gets it ("written": false, "warning").
/// Nothing when `path` is empty (null).
nlohmann::json WriteFittedUncertainty(const std::string& tool, const std::string& path,
                                      const calibration::CalibrationResult& result, const std::string& source);

/// The UsageError of a noise option the data cannot meet (the OptionError
/// of workflows::EstimateNoiseModels on noise_model or averages: "--noise-model
/// coherence needs --averages N: ...").
UsageError NoiseOptionError(const NoiseCliOptions& options, const OptionError& error);

/// FromFields for a workflow that estimates noise models with `noise`: its
/// OptionError on noise_model or averages is NoiseOptionError, every other
/// one is named as `fields` say.
template <class F>
auto FromNoiseFields(const NoiseCliOptions& noise, const std::vector<FieldSource>& fields, F&& body)
    -> decltype(body()) {
  try {
    return body();
  } catch (const OptionError& e) {
    if (e.field() == "noise_model" || e.field() == "averages") throw NoiseOptionError(noise, e);
    ValidateOptions(fields, [] { throw; });
    throw;
  }
}

// FitData(data, noise): workflows::FitData (found by argument-dependent lookup).

}  // namespace robomach::apps
