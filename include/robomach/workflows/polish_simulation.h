#pragma once
// polish-sim's run (issue #21): a path file (formats.md §6), written by
// polish-plan or by anyone, attached to a surface and simulated with the
// process on the sampled region.

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/common/run_status.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::workflows {

/// Flagged (RunFindings; polish-sim's exit 3) when the path is faster than
/// the process allows.
struct PolishSimulation : RunFindings {
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

/// polish-sim's summary of a simulated path file: removal_um, path,
/// parameters (from the file's header), region, speed_limit_exceeded.
nlohmann::json PolishSimSummaryJson(const PolishSimulation& sim, const polishing::PolishingProcess& process,
                                    double sample_mm);

}  // namespace robomach::workflows
