#pragma once
// polish-sim's run (issue #21): a path file (formats.md §6), written by
// polish-plan or by anyone, attached to a surface and simulated with the
// process on the sampled region.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/common/run_status.h"
#include "robomach/io/polishing_files.h"
#include "robomach/io/polishing_summary.h"
#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/plan_workflow.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::workflows {

/// Flagged (its `verdict`; polish-sim's exit 3) when the path is faster than
/// the process allows.
struct PolishSimulation {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  io::PolishPathFile file;      // the rows attached to the surface (u, v filled)
  std::shared_ptr<const polishing::SampleGrid> grid;
  std::vector<double> removal;  // at every grid point [m]
  polishing::RemovalStats stats;
  double max_speed{0.0};        // the fastest segment [m/s]
  /// A segment is faster than the process's max_speed even when its length
  /// is read as short as the file's rounding allows (polish-plan writes
  /// positions to 1e-4 mm): the tool exits 3.
  bool speed_limit_exceeded{false};
};

/// @throws InputError naming the path file and the row's line for a row
///   off the surface or on its wrong side, the surface file for a surface
///   that cannot be sampled, the process file for a margin that leaves no
///   region.
PolishSimulation SimulatePolishPathFile(const polishing::NurbsSurface& surface,
                                        const polishing::PolishingProcess& process, const std::string& path_file,
                                        double sample_spacing, const std::string& surface_source,
                                        const std::string& process_source);

/// A path's figures for the summaries (io::PathSummaryJson): contact length
/// (polishing::ContactLength), lifts (CountLifts), time, rows, largest
/// speed (MaxSpeed).
io::PathFigures PathFiguresOf(const std::vector<polishing::PathRow>& rows);

/// The edge overrun a plan with `params` uses [m]: the parameters' own, at
/// most the largest its pattern allows with `process`
/// (polishing::MaxEdgeOverrun).
double EdgeOverrunUsed(const polishing::PathParameters& params, const polishing::PolishingProcess& process);

/// The figures of polish-plan's summary (io::PolishPlanSummaryJson): the
/// planned path's, and the edge overrun of the plan and of each plan the
/// optimisation reports.
io::PlanFigures PlanFiguresOf(const polishing::PlanOutcome& outcome, const polishing::PolishingProcess& process);

/// io::PlannedPathMetadata with the edge overrun the plan used: the `# key:
/// value` lines polish-plan writes at the top of its path.
std::vector<std::pair<std::string, std::string>> PlannedPathMetadata(const polishing::PathParameters& params,
                                                                     const polishing::PolishingProcess& process);

/// polish-sim's summary of a simulated path file: removal_um, path,
/// parameters (from the file's header), region, speed_limit_exceeded.
nlohmann::json PolishSimSummaryJson(const PolishSimulation& sim, const polishing::PolishingProcess& process,
                                    double sample_mm);

}  // namespace robomach::workflows
