#pragma once
// drill-sim's outputs (docs/formats.md §9.4, docs/drilling.md): the time
// series of --out (`t_s`, then per joint `q<i>_deg`, `e<i>_deg`,
// `tau_m<i>_Nm`, then `thrust_N`, `torque_Nm`, `offset_deg`; 17 significant
// digits) and the summary JSON of one controller's run.

#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "robomach/drilling/controller_runs.h"
#include "robomach/drilling/drilling_sim.h"

namespace robomach::io {

/// The CSV text of one run's series.
std::string DrillSeriesCsv(const drilling::SimResult& result);

/// One run's summary JSON: the controller, its gains and gain parameters
/// (tuned or defaults, with the tuning), the error band, settling time,
/// largest errors [deg], thrust statistics [N], full engagement, the
/// plant's modes [Hz], the motor torque limit [N m] (`motor_torque_limit`,
/// per joint), the cost, divergence, substeps and, for a TDE controller,
/// its stability measure.
nlohmann::json DrillRunSummaryJson(const drilling::ControllerRun& run, const drilling::DrillingScenario& scenario,
                                   const Eigen::VectorXd& motor_torque_limit);

}  // namespace robomach::io
