#pragma once

// drill-sim's workflow as one library call (issue #21): each controller kind
// asked for, with its given or default gains (or tuned first), simulated on
// one drilling scenario, with the time-delay estimation condition of the
// kinds that use it.
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/run_status.h"
#include "robomach/drilling/drilling_sim.h"

namespace robomach::drilling {

struct ControllerRunOptions {
  /// Controller kinds (ControllerKinds() names), simulated in this order.
  std::vector<std::string> kinds;
  /// Gains per kind; a kind not listed runs on DefaultParameters(kind).
  std::map<std::string, ControllerParameters> given;
  /// Tune each kind first (TuneController from its gains) with at most
  /// tune_evaluations simulations.
  bool tune{false};
  int tune_evaluations{30};  // drill-sim's default
  /// Per joint [N·m].
  Eigen::VectorXd motor_torque_limit;

  /// The bounds (issue #36); the size of motor_torque_limit is
  /// RunControllers' check (it needs the scenario):
  /// - kinds: each a ControllerKinds() name (OptionError "kinds", "unknown
  ///   controller kind 'NAME': expected pid, pd or pd-tdc").
  /// - tune_evaluations >= 1 when tune: NLopt takes a budget <= 0 as none.
  /// - motor_torque_limit, each >= 0 and finite [N m] (SimOptions::Validate's).
  /// @throws OptionError(field, "FIELD: expected ..., got VALUE") naming the bound.
  void Validate() const;
};

/// One controller's run.
struct ControllerRun {
  ControllerParameters parameters;  // what was simulated (tuned, given or default)
  bool tuned{false};
  TuneResult tune;                  // when tuned
  SimResult result;
  /// ||I - M^-1 Mbar|| (TdeStabilityMeasure) for kinds with time-delay
  /// estimation (uses_tde); NaN otherwise. The condition holds when < 1.
  bool uses_tde{false};
  double tde_measure{NAN};
  /// The kind uses time-delay estimation and its condition does not hold
  /// (a NaN measure, from a singular inertia, does not hold either).
  bool tde_condition_fails() const { return uses_tde && !(tde_measure < 1.0); }
};

/// What the runs tell as they go: `kind` is being tuned (`tuning`) or
/// simulated, `done` of `total` samples.
struct ControllerRunProgress {
  std::string kind;
  bool tuning{false};
  long done{0}, total{0};
  bool finished{false};
  const ControllerRun* run{nullptr};  // with `finished`: the run just done
};

/// Runs every kind of `options` on `scenario`.
/// @throws std::invalid_argument for an unknown kind or a torque limit of
///   the wrong size.
std::vector<ControllerRun> RunControllers(DrillingScenario& scenario, const ControllerRunOptions& options,
                                          const std::function<void(const ControllerRunProgress&)>& progress = {});

/// drill-sim's verdict (its exit 3): one finding per run that diverged, then
/// one per implausible unit of the set-up (`unit_findings`, as
/// workflows::LoadDrillingSetup gives them).
RunFindings JudgeControllerRuns(const std::vector<ControllerRun>& runs, const std::vector<std::string>& unit_findings);

}  // namespace robomach::drilling
