#include "robomach/drilling/controller_runs.h"

#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/common/option_validate.h"
#include "robomach/drilling/controller_kinds.h"
#include "robomach/drilling/controllers.h"

namespace robomach::drilling {

void ControllerRunOptions::Validate() const {
  for (const std::string& kind : kinds) {
    try {
      FindControllerKind(kind);
    } catch (const std::invalid_argument& e) {
      throw OptionError("kinds", e.what());
    }
  }
  if (tune) CheckOptionAtLeast("tune_evaluations", tune_evaluations, 1);
  for (Eigen::Index j = 0; j < motor_torque_limit.size(); ++j) {
    CheckOptionAtLeast("motor_torque_limit", motor_torque_limit(j), 0.0);
    CheckOptionFinite("motor_torque_limit", motor_torque_limit(j));
  }
}

std::vector<ControllerRun> RunControllers(DrillingScenario& scenario, const ControllerRunOptions& o,
                                          const std::function<void(const ControllerRunProgress&)>& progress) {
  o.Validate();  // all names checked before any work
  const Eigen::Index n = scenario.effective_inertia().rows();
  if (o.motor_torque_limit.size() != n) {
    throw std::invalid_argument("RunControllers: expected one motor torque limit per joint (" +
                                std::to_string(n) + "), got " +
                                std::to_string(o.motor_torque_limit.size()));
  }
  SimOptions options;
  options.motor_torque_limit = o.motor_torque_limit;
  std::vector<ControllerRun> runs;
  for (const std::string& kind : o.kinds) {
    ControllerRun run;
    const auto given = o.given.find(kind);
    run.parameters = given != o.given.end() ? given->second : DefaultParameters(kind);
    if (o.tune) {
      if (progress) progress({kind, true, 0, o.tune_evaluations, false});
      run.tune = TuneController(run.parameters, scenario, options, o.tune_evaluations);
      run.parameters = run.tune.parameters;
      run.tuned = true;
    }
    auto ctl = MakeController(run.parameters, scenario, o.motor_torque_limit);
    SimOptions sim = options;
    const long total = scenario.num_samples();
    if (progress) {
      sim.progress = [&](long done, long) { progress({kind, false, done, total, false}); };
    }
    run.result = scenario.Run(*ctl, sim);
    if (FindControllerKind(kind).uses_time_delay_estimation()) {
      const Eigen::VectorXd mbar = scenario.effective_inertia().diagonal() * run.parameters.third;
      run.uses_tde = true;
      run.tde_measure = TdeStabilityMeasure(scenario.effective_inertia(), mbar);
    }
    if (progress) progress({kind, false, total, total, true, &run});
    runs.push_back(std::move(run));
  }
  return runs;
}

RunFindings JudgeControllerRuns(const std::vector<ControllerRun>& runs, const std::vector<std::string>& unit_findings) {
  RunFindings v;
  for (const ControllerRun& run : runs) {
    if (run.result.diverged) v.Flag(run.parameters.kind + ": the run left the 10 deg error range and was stopped");
  }
  for (const std::string& f : unit_findings) v.Flag("implausible (unit mistake?): " + f);
  return v;
}

}  // namespace robomach::drilling
