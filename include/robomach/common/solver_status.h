#pragma once
// How an iterative fit or optimisation of the library ended: one status for
// every solver (Ceres' TerminationType is the model; issue #21 "one solver
// status"): the joint-stiffness identification, the calibration against
// hammer FRFs, the drill force fit.

namespace robomach {

enum class SolverStatus {
  kConverged,     // the solver met its convergence test
  kNotConverged,  // it stopped at its iteration or time limit; the result is the best so far
  kFailed,        // no usable result (a failed factorisation, a non-finite cost)
  kNotImproved,   // it ran, but the result is no better than the start (the start is returned)
};

/// "converged", "not_converged", "failed", "not_improved": the spelling of
/// the tools' summaries and files, and of Python.
const char* SolverStatusName(SolverStatus s);

}  // namespace robomach
