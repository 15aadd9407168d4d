#pragma once
// The time series of drill-sim's --out (docs/drilling.md): `t_s`, then per
// joint `q<i>_deg`, `e<i>_deg`, `tau_m<i>_Nm`, then `thrust_N`, `torque_Nm`,
// `offset_deg`; 17 significant digits.

#include <string>

#include "robomach/drilling/drilling_sim.h"

namespace robomach::io {

/// The CSV text of one run's series.
std::string DrillSeriesCsv(const drilling::SimResult& result);

}  // namespace robomach::io
