#include "robomach/common/solver_status.h"

#include "robomach/common/run_status.h"

namespace robomach {

const char* SolverStatusName(SolverStatus s) {
  switch (s) {
    case SolverStatus::kConverged: return "converged";
    case SolverStatus::kNotConverged: return "not_converged";
    case SolverStatus::kFailed: return "failed";
    case SolverStatus::kNotImproved: return "not_improved";
  }
  return "?";
}

const char* RunStatusName(RunStatus s) { return s == RunStatus::kOk ? "ok" : "flagged"; }

}  // namespace robomach
