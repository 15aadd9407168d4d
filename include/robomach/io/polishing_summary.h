#pragma once
// The summary JSONs of polish-plan and polish-sim (docs/formats.md §7):
// removal statistics [um], the path, the parameters, the region (with its
// unpolished area), and polish-plan's contact, target, optimisation and
// cycloid/zig-zag comparison.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/io/polishing_files.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/plan_workflow.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::io {

/// "removal_um": mean, std, variance [um^2], cv, min, max, peak_to_valley,
/// coverage (area-weighted over the region); `stats_m` in m.
nlohmann::json RemovalSummaryJson(const polishing::RemovalStats& stats_m);

/// "path": contact length [mm], lifts, time [s], rows, largest speed [mm/s].
nlohmann::json PathSummaryJson(const std::vector<polishing::PathRow>& rows);

/// "region": the sampling [mm], points, margin [mm], area and area left
/// unpolished (polishing::DescribeUnpolished) [mm^2].
nlohmann::json RegionSummaryJson(const polishing::SampleGrid& grid, const polishing::RemovalStats& stats_m,
                                 double sample_mm, const polishing::PolishingProcess& process);

/// polish-plan's summary of a plan made with `options` on `context`:
/// removal_um, path, parameters, region (with the trimmed face and its rows
/// off the face), contact, and when there are target, optimisation (method,
/// budget, status (robomach::ToString(SolverStatus)) and stop_reason (the
/// optimiser's word: "converged", "max_time", ...), the best plan and the best of each family, the
/// history) and comparison (the optimised cycloid against the optimised
/// zig-zag).
nlohmann::json PolishPlanSummaryJson(const polishing::PlanOutcome& outcome, const polishing::PlanningContext& context,
                                     const polishing::PlanOptions& options);

}  // namespace robomach::io
