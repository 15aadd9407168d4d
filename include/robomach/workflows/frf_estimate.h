#pragma once
// frf-estimate as one library call (issue #36 §1): raw hammer records ->
// the hits, accepted or rejected by name -> H1 or H2 with the coherence ->
// the verdict and the FRFs to write. The tool parses its options into
// FrfEstimateRunOptions, writes what RunFrfEstimate returns and draws it.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/calibration/frf_estimate.h"
#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/io/hammer_records.h"

namespace robomach::workflows {

/// frf-estimate's options, field by field (the tool's option is the field's
/// name with dashes; record_paths are its positional arguments, directions
/// --direction, response_ranges --response-range, estimate's fields its
/// window and detection options).
struct FrfEstimateRunOptions {
  std::vector<std::string> record_paths;
  std::string pose_id{"P1"};
  std::string excitation{"x"};                     // hammer direction at the tool tip: x, y or z
  std::map<std::string, std::string> directions;   // channel name -> x, y or z
  std::map<std::string, double> response_ranges;   // channel name -> overload range in its SI unit
  std::string estimator{"h1"};                     // h1 or h2
  int min_hits{3};                                 // fewer accepted hits: flagged
  std::string min_hits_name{"min_hits"};           // how the verdict names it (the tool: "--min-hits")
  calibration::FrfEstimateOptions estimate;        // windows, fmax_hz, detection thresholds

  /// @throws OptionError naming the field: excitation, estimator, min_hits
  ///   [1, 1e6], no record_paths; OptionError naming the field of
  ///   `estimate` (FrfEstimateOptions::Validate).
  void Validate() const;
};

struct FrfEstimateRun {
  io::HammerRecords records;
  std::vector<dynamics::FrfKey> keys;  // one per response channel
  calibration::FrfEstimateResult result;
  RunFindings verdict;                 // calibration::JudgeFrfEstimate
  /// The FRFs in receptance with their labels, when a hit was accepted.
  std::optional<io::EstimatedFrfs> frfs;
  bool every_hit_rejected() const { return result.status != calibration::FrfEstimateStatus::kOk; }
  /// The tool's --summary but for tool, records and exit_code:
  /// io::FrfEstimateSummaryJson with the estimator and the verdict's flags.
  nlohmann::json Summary(const std::string& estimator) const;
  /// What was estimated, for the tool's last line: "4 of 5 hits averaged
  /// (rejected: hit3 (double_hit)); 2 FRF(s) of 801 lines, 0 to 500 Hz".
  /// Only with FRFs (not every_hit_rejected()).
  std::string Outcome() const;
};

/// "NAME=AXIS" each (the tool's --direction) -> FrfEstimateRunOptions::directions.
/// @throws OptionError "directions" for a text without a name and '='.
std::map<std::string, std::string> ParseDirections(const std::vector<std::string>& texts);

/// Reads the records, names each channel's key, checks the options the
/// sample rate decides, estimates and judges. Messages: kInfo the records
/// and channels, one line per rejected hit and why; kWarning each of the
/// estimate's warnings, then each finding of the verdict ("result flagged:
/// ..."). An every-hit-rejected result is returned (the caller says so).
/// @throws OptionError naming the field: fmax_hz above the records' Nyquist
///   frequency, exponential_tau_s under kMinExponentialWindowSamples sample
///   periods, directions or response_ranges that name no channel;
///   io::MissingFileError, InputError for the records.
FrfEstimateRun RunFrfEstimate(const FrfEstimateRunOptions& options, const MessageSink& on_message = {});

}  // namespace robomach::workflows
