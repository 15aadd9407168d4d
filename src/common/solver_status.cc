#include "robomach/common/solver_status.h"

#include <stdexcept>

#include "robomach/common/run_status.h"
#include "robomach/common/enum_names.h"

namespace robomach {

namespace {
constexpr SolverStatus kAllSolverStatuses[] = {SolverStatus::kConverged, SolverStatus::kNotConverged,
                                               SolverStatus::kFailed, SolverStatus::kNotImproved};
}  // namespace

const char* ToString(SolverStatus s) {
  switch (s) {
    case SolverStatus::kConverged: return "converged";
    case SolverStatus::kNotConverged: return "not_converged";
    case SolverStatus::kFailed: return "failed";
    case SolverStatus::kNotImproved: return "not_improved";
  }
  return "?";
}

SolverStatus ParseSolverStatus(const std::string& name) {
  for (SolverStatus s : kAllSolverStatuses) {
    if (name == ToString(s)) return s;
  }
  throw std::invalid_argument("solver status '" + name +
                              "': expected converged, not_converged, failed or not_improved");
}

const char* ToString(RunStatus s) { return s == RunStatus::kOk ? "ok" : "flagged"; }

RunStatus ParseRunStatus(const std::string& name) {
  constexpr RunStatus kAll[] = {RunStatus::kOk, RunStatus::kFlagged};
  return ParseByName("run status", name, kAll);
}

}  // namespace robomach
