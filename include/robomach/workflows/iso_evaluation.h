#pragma once
// axis-accuracy's run (issue #36: the workflow, out of io): the ISO 230-2
// evaluation of a runs file (io::ReadIsoRuns), its verdict and its summary.

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/common/run_status.h"
#include "robomach/io/iso_runs_file.h"
#include "robomach/machine/iso230.h"

namespace robomach::workflows {

/// axis-accuracy's evaluation of a runs file: ISO 230-2 per axis, in file
/// order, with the unit plausibility findings and the fewest runs any target
/// has in a direction (ISO 230-2 asks for 5). Flagged (RunFindings;
/// axis-accuracy's exit 3) with one finding per implausible unit.
struct IsoEvaluation {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  io::IsoRuns runs;
  std::vector<std::pair<std::string, machine::Iso230Result>> results;
  std::vector<std::string> unit_findings;
  int min_runs{0};
};
/// @throws InputError naming the file and the axis for runs ISO 230-2
///   cannot evaluate (a target without one direction, fewer than 2 runs).
IsoEvaluation EvaluateIsoRunsFile(const std::string& path);

/// axis-accuracy's JSON (docs/formats.md §8.6): the standard, the unit and
/// per axis A, E, M, R, B (each way where ISO 230-2 defines it) and every
/// target's runs, means, standard deviations, reversal and repeatability,
/// in the file's unit.
nlohmann::json IsoSummaryJson(const IsoEvaluation& evaluation);

}  // namespace robomach::workflows
