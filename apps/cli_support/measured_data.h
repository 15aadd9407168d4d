#pragma once

// Shared by the tools that read hammer-test FRFs (frf-calibrate,
// model-audit): reading one or several files into one set, and the noise
// model of every FRF with its usable band (issue #10), with the same
// options and the same stderr lines in every tool.

#include <map>
#include <string>
#include <vector>

#include "robomach/calibration/frf_noise.h"
#include "robomach/dynamics/measured_frf.h"

namespace CLI {
class App;
}

namespace robomach::apps {

/// Measured FRFs as read, all lines (receptance), and the number of averages
/// each file declared (`# averages: N`, 0 if none).
struct MeasuredData {
  dynamics::FrfSet frfs;
  std::map<dynamics::FrfKey, int> averages;
  std::map<dynamics::FrfKey, std::string> file;
  /// Power of iω of the quantity each FRF's file holds (0 receptance,
  /// 1 mobility, 2 accelerance): misfits are reported in it.
  std::map<dynamics::FrfKey, int> file_power;
  /// FRFs whose receptance on its usable band is outside the plausible
  /// range (calibration::ReceptanceUnitFindings; printed as warnings): a
  /// unit mistake, which the tools flag (exit 3).
  std::vector<std::string> unit_findings;
};

/// Reads `files` (CSV or UFF58) and `pose_files` ("ID=file.uff") into one
/// set; warnings and notes go to stderr under `tool`. @throws InputError for
/// an FRF read twice or one without a posture (the message suggests
/// --pose, so every tool that calls this has that option),
/// UsageError for a malformed ID=file. `keep_points`: the point numbers of
/// a roving test stay in the keys (io::ReadFrfFile).
MeasuredData ReadMeasuredFiles(const std::string& tool, const std::vector<std::string>& files,
                               const std::vector<std::string>& pose_files, const std::string& what,
                               const std::string& pose_option = "--pose", bool keep_points = false);

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
};

/// --noise-model, --min-snr, --averages, --drift-floor.
void AddNoiseOptions(CLI::App& app, NoiseCliOptions* options);

/// The noise model of every FRF (empty for --noise-model none), one line per
/// FRF on stderr (source, rel, floor, usable band), warnings for FRFs with
/// no usable line. @throws UsageError for inconsistent options
///   (coherence asked for an FRF without coherence or without a number of
///   averages), naming the FRF and what to give.
calibration::NoiseModels EstimateNoiseModels(const std::string& tool, const MeasuredData& data,
                                             const NoiseCliOptions& options);

/// The data every fit uses: the usable lines with their σ (UsableData), or
/// all lines without a noise model for --noise-model none.
/// @throws InputError if no FRF has a usable line.
dynamics::FrfSet FitData(const MeasuredData& data, const calibration::NoiseModels& noise);

}  // namespace robomach::apps
