#pragma once
// frf-synth as library calls (issue #36): a robot config (effects added,
// parameters set) and a posture file -> a virtual hammer test, the "measured"
// tool-tip FRFs on a hammer-test grid with seeded noise, and its verdict.
// The tool parses its options into FrfSynthOptions and writes the FRFs and
// the summary of the run. Two calls, because the sample rate may come from
// the config: PrepareFrfSynth says where it came from, so that the tool can
// name the config's value when the grid does not fit it (RunFrfSynth).

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/messages.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/io/frf_quantity.h"
#include "robomach/io/robot_config.h"

namespace robomach::workflows {

/// --noise-rel is a fraction of |H| (docs/plausibility.md): hammer tests show
/// 0.1 to 10 %; above 50 % it is flagged (a percentage typed for a fraction),
/// above 10 (1000 %) nothing of the FRF is left: refused.
inline constexpr double kMaxPlausibleRelativeNoise = 0.5;
inline constexpr double kMaxRelativeNoise = 10.0;

/// frf-synth's options (the tool's option for each field: robot_path is
/// --robot, postures_path --postures, adds --add, sets --set; the test's
/// fields those of calibration::VirtualHammerOptions, relative_noise
/// --noise-rel, absolute_noise_m_per_N --noise-abs-m-per-N, ...).
struct FrfSynthOptions : FieldNames {
  std::string robot_path;     // robot config YAML
  std::string postures_path;  // posture file (formats.md §1)
  std::vector<std::string> adds;  // effects switched on with their default parameters
  std::vector<std::string> sets;  // "NAME=VALUE" in the parameter's unit
  /// The test's grid, noise, directions and seed. sample_rate_hz NaN: the
  /// config's hammer_test.sample_rate_hz, else 5120 Hz.
  calibration::VirtualHammerOptions hammer{.sample_rate_hz = NAN};
  // names, Name(field): how the unit findings name the fields (FieldNames;
  // the tool: its options, "--fmax-hz").

  /// The options alone, before any file is read.
  /// @throws OptionError naming the field: block_samples outside
  ///   [2, 2^22], averages outside [1 (2 with coherence), 100000],
  ///   relative_noise infinite or above kMaxRelativeNoise, fmax_hz or
  ///   hammer_cutoff_hz outside [0, 1e9] Hz, fmin_hz outside (0, 1e9] Hz or
  ///   not below fmax_hz, a sample_rate_hz other than NaN outside (0, 1e9]
  ///   Hz, an absolute noise negative or not finite.
  void Validate() const;
  /// The options that look like a unit mistake (docs/plausibility.md),
  /// "implausible (unit mistake?): ..." each: they flag the run.
  std::vector<std::string> UnitFindings() const;
};

/// The robot and the test as they will be used.
struct FrfSynthSetup {
  io::RobotConfig config;  // effects added and parameters set
  calibration::VirtualHammerOptions hammer;  // with the sample rate resolved
  /// "kr210.yaml:70:19" when the sample rate is the config's
  /// hammer_test.sample_rate_hz; empty when it is the options' or 5120 Hz.
  std::string sample_rate_at;
};

struct FrfSynthRun {
  io::RobotConfig config;
  calibration::VirtualHammerOptions hammer;  // as used (the sample rate resolved)
  dynamics::FrfSet frfs;
  /// The options' unit findings (FrfSynthOptions::UnitFindings), the
  /// config's and the posture file's: each told as a warning.
  std::vector<std::string> unit_findings;

  bool flagged() const { return !unit_findings.empty(); }
  RunStatus status() const { return flagged() ? RunStatus::kFlagged : RunStatus::kOk; }
  /// frf-synth --summary (formats.md §4.1) but for the keys only the tool
  /// knows (tool, out, format, quantity, exit_code, warnings): the inputs,
  /// the grid, the noise, per FRF its peak (receptance, with the noise),
  /// and `flagged`.
  nlohmann::json Summary(const FrfSynthOptions& options) const;
};

/// Validates, loads the config (its unit findings are warnings), applies
/// adds and sets and resolves the sample rate.
/// @throws OptionError (Validate; "adds", "sets"), InputError for the config.
FrfSynthSetup PrepareFrfSynth(const FrfSynthOptions& options, const MessageSink& tell = {});

/// Checks the test's options against the resolved sample rate, reads the
/// postures (their unit findings are warnings, then the options' findings
/// are) and synthesizes the FRFs.
/// @throws OptionError naming the VirtualHammerOptions field that fails
///   VirtualHammerOptions::Validate, with the options' unit findings as its likely
///   cause; InputError for the posture file.
FrfSynthRun RunFrfSynth(const FrfSynthOptions& options, FrfSynthSetup setup, const MessageSink& tell = {});

/// Both calls in one.
FrfSynthRun RunFrfSynth(const FrfSynthOptions& options, const MessageSink& tell = {});

/// The formats frf-synth writes its FRFs in: the CSV of formats.md §3 or
/// UFF58 ASCII (formats.md §4).
enum class FrfFileFormat { kCsv, kUff58 };

/// The format of frf-synth's output file `path`, by its extension (any
/// case): .csv is CSV, .uff, .unv and .uf are UFF58; with `allow_stdout`,
/// "-" (standard output) is CSV. `name` is how the messages name the file's
/// option (the tool: "--out").
/// @throws OptionError on `name` for another extension ("--out f.png:
///   expected a file name ending in .csv (the FRF CSV of docs/formats.md §3)
///   or .uff, .unv (UFF58), or '-' for standard output (CSV)"; without
///   `allow_stdout` the message ends at "(UFF58)").
FrfFileFormat FrfSynthOutputFormat(const std::string& path, const std::string& name, bool allow_stdout);

/// Writes the run's FRFs to `path` ("-": standard output, CSV) in `format`
/// as `quantity`: CSV with '# averages: N' when the test gave the coherence,
/// UFF58 without it. UFF58 has no field for the number of averages: with
/// coherence of more than one impact, a warning through `tell` says so before
/// the file is written ("UFF58 has no field for the number of averages: give
/// --averages 8 to the tools that read PATH", the option as
/// options.Name("averages")).
void WriteFrfSynthOutput(const FrfSynthRun& run, const FrfSynthOptions& options, const std::string& path,
                         FrfFileFormat format, io::FrfQuantity quantity, const MessageSink& tell = {});

}  // namespace robomach::workflows
