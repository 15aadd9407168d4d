#pragma once
// Measured tool-tip FRFs from files, with the noise model of each FRF and
// its usable lines: the one route every tool and Python call takes from
// hammer-test files to the data a fit uses (issue #36 §1; issue #10 for the
// noise model). frf-calibrate, model-audit and frf-modes read through it.
//
//   files (CSV of formats.md §3, UFF58) -> FrfSet + averages, quantities,
//   unit findings -> noise model per FRF (coherence or scatter) -> the
//   usable lines with their σ (what every fit and error uses).

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "robomach/calibration/frf_noise.h"
#include "robomach/common/messages.h"
#include "robomach/dynamics/measured_frf.h"

namespace robomach::workflows {

/// Where each FRF's noise comes from (calibration::EstimateFrfNoise).
enum class NoiseModelChoice {
  kAuto,       // the coherence when the FRF has one and the averages are known, else the scatter
  kCoherence,  // the coherence, required
  kScatter,    // the scatter of the data about a smooth fit
  kNone,       // no noise model: every line, weights 1/|H| (the behaviour before issue #10)
};
/// "auto", "coherence", "scatter", "none".
const char* ToString(NoiseModelChoice c);
/// @throws OptionError (field noise_model) naming the accepted names.
NoiseModelChoice ParseNoiseModelChoice(const std::string& name);

struct MeasuredFrfOptions {
  std::vector<std::string> files;  // CSV or UFF58
  /// (pose ID, file): a UFF58 file whose records name no posture.
  std::vector<std::pair<std::string, std::string>> posed_files;
  /// The posture of a file whose FRFs name none (frf-modes: "P1"); empty:
  /// such a file is refused with a message that suggests `pose_option`.
  std::string default_pose;
  std::string what{"measured FRF file"};  // how messages name the files
  std::string pose_option{"--pose"};      // how messages name the ID=file form
  /// Keep the point numbers of a roving test in the keys (io::ReadFrfFile).
  bool keep_points{false};

  NoiseModelChoice noise_model{NoiseModelChoice::kAuto};
  double min_snr{calibration::NoiseOptions{}.min_snr};  // usable where |H| >= min_snr x floor
  int averages{0};                // impacts behind the coherence; 0: from each file's '# averages: N'
  bool drift_floor{false};        // calibration::NoiseOptions::wide_floor
  bool global_modal_fit{false};   // calibration::NoiseOptions::global_modal_fit

  /// @throws OptionError naming the field, its value and bound: min_snr
  ///   outside [1e-3, 1e6], averages outside [0, 1e6].
  void Validate() const;
};

/// Measured FRFs as read, all lines (receptance), with what each file said.
struct MeasuredFrfs {
  dynamics::FrfSet frfs;
  std::map<dynamics::FrfKey, int> averages;        // '# averages: N' of its file, 0 if none
  std::map<dynamics::FrfKey, std::string> file;    // the file it came from
  /// Power of iω of the quantity each FRF's file holds (0 receptance,
  /// 1 mobility, 2 accelerance): misfits are reported in it.
  std::map<dynamics::FrfKey, int> file_power;
  /// FRFs whose receptance on its usable band is outside the plausible
  /// range (calibration::ReceptanceUnitFindings): a unit mistake, which the
  /// tools flag (exit 3). Each was also told as a warning.
  std::vector<std::string> unit_findings;
  /// The noise model of every FRF (empty for NoiseModelChoice::kNone).
  calibration::NoiseModels noise;

  /// The data every fit uses: the usable lines with their σ
  /// (calibration::UsableData), or all lines without a noise model.
  /// @throws InputError (naming a file) if no FRF has a usable line.
  dynamics::FrfSet FitData() const;
};

/// Reads the files into one set (no noise model yet): warnings and notes
/// of the readers and the unit findings go to `on_message`.
/// @throws InputError for an FRF read twice, a file whose FRFs name no
///   posture (without default_pose), files that hold no FRF;
///   io::MissingFileError for a file that is not there or not readable;
///   OptionError for a bad option (Validate).
MeasuredFrfs ReadMeasuredFrfFiles(const MeasuredFrfOptions& options, const MessageSink& on_message = {});

/// The noise model of every FRF of `data` (kInfo: one line per FRF with its
/// source, levels and usable band; a warning for an FRF with no usable line
/// or a coherence left unused); empty for NoiseModelChoice::kNone.
/// @throws OptionError for options the data cannot meet (the coherence
///   asked for an FRF without one: field noise_model; or without a number
///   of averages: field averages), naming the FRF and what to give;
///   InputError naming the file
///   when an FRF's noise cannot be estimated.
calibration::NoiseModels EstimateNoiseModels(const MeasuredFrfs& data, const MeasuredFrfOptions& options,
                                             const MessageSink& on_message = {});

/// data->noise = EstimateNoiseModels(*data, ...).
void AttachNoiseModels(MeasuredFrfs* data, const MeasuredFrfOptions& options, const MessageSink& on_message = {});

/// MeasuredFrfs::FitData with the noise models `noise` (of the same FRFs).
dynamics::FrfSet FitData(const MeasuredFrfs& data, const calibration::NoiseModels& noise);

/// ReadMeasuredFrfFiles, then AttachNoiseModels.
MeasuredFrfs ReadMeasuredFrfs(const MeasuredFrfOptions& options, const MessageSink& on_message = {});

}  // namespace robomach::workflows
