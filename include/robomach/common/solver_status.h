#pragma once
// How an iterative fit or optimisation of the library ended: the one status
// of every solver and fit (Ceres' TerminationType is the model; issue #21
// "one solver status", issue #36 "one status enum"): the joint-stiffness
// identification, the calibration against hammer FRFs, the modal fits
// (FitModes, FitGlobalModes), the noise model's scatter fit, the drill force
// fit, the drilling controller's tuning and the polishing optimisers. A
// solver's own reason for stopping (NLopt's "max_time", the modal fit's "no
// stable pole") is its result's message or stop reason beside the status.
// The verdict of a whole run ("ok", "flagged") is RunStatus (run_status.h).

#include <string>

namespace robomach {

enum class SolverStatus {
  kConverged,     // the solver met its convergence test
  kNotConverged,  // it stopped at its iteration or time limit; the result is the best so far
  kFailed,        // no usable result (a failed factorisation, a non-finite cost, no stable pole)
  kNotImproved,   // it ran, but the result is no better than the start (the start is returned)
};

/// "converged", "not_converged", "failed", "not_improved": the one spelling
/// of the tools' summaries and files, and of Python.
const char* ToString(SolverStatus s);
/// The inverse of ToString; throws std::invalid_argument naming the four
/// words on any other.
SolverStatus ParseSolverStatus(const std::string& name);

}  // namespace robomach
