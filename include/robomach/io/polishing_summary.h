#pragma once
// The summary JSONs of polish-plan and polish-sim (docs/formats.md §7):
// removal statistics [um], the path, the parameters, the region (with its
// unpolished area), and polish-plan's contact, target, optimisation and
// cycloid/zig-zag comparison.
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/io/polishing_files.h"
#include "robomach/polishing/plan_workflow.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::io {

/// "removal_um": mean, std, variance [um^2], cv, min, max, peak_to_valley,
/// coverage (area-weighted over the region); `stats_m` in m.
nlohmann::json RemovalSummaryJson(const polishing::RemovalStats& stats_m);

/// A path's figures as the summaries report them, computed by the caller
/// (workflows::PathFiguresOf; issue #36: io writes them, it runs no
/// algorithm).
struct PathFigures {
  double contact_length_m{0.0};   // polishing::ContactLength
  int lifts{0};                   // polishing::CountLifts
  double time_s{0.0};             // last row's t minus the first's (0 without rows)
  size_t rows{0};
  double max_speed_m_per_s{0.0};  // polishing::MaxSpeed
};

/// The figures of a plan that polish-plan's summary reports besides the
/// outcome's own (workflows::PlanFiguresOf): the path's, and the edge
/// overrun each reported plan used [m] (its parameters' own, at most the
/// largest its pattern allows: polishing::MaxEdgeOverrun).
struct PlanFigures {
  PathFigures path;              // of outcome.plan.path.rows
  double edge_overrun_m{0.0};    // of outcome.params
  /// With an optimisation: of its best, of each of its family_best (in
  /// order) and of its best_parallel (0 when that is not valid).
  double best_edge_overrun_m{0.0};
  std::vector<double> family_edge_overrun_m;
  double parallel_edge_overrun_m{0.0};
};

/// "path": contact length [mm], lifts, time [s], rows, largest speed [mm/s].
nlohmann::json PathSummaryJson(const PathFigures& figures);

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
/// zig-zag). `figures` are the outcome's (workflows::PlanFiguresOf).
nlohmann::json PolishPlanSummaryJson(const polishing::PlanOutcome& outcome, const polishing::PlanningContext& context,
                                     const polishing::PlanOptions& options, const PlanFigures& figures);

}  // namespace robomach::io
