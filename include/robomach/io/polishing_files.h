#pragma once

// Readers and writers of the polishing files (formats.md §5-7): the NURBS
// patch YAML, the process YAML, tool-path CSV and removal-map CSV. Lengths
// are converted from mm to m here, once.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::io {

/// formats.md §5 NURBS patch. @throws InputError "file:line:col: ..." for a
/// knot vector that does not match the control points, a weight <= 0, ...
polishing::NurbsSurface ReadNurbsYaml(const std::string& path);

/// formats.md §7 process file. Unknown keys are rejected.
polishing::PolishingProcess ReadPolishingProcess(const std::string& path);

/// A tool path CSV as read (formats.md §6), SI.
struct PolishPathFile {
  std::string path;
  std::map<std::string, std::string> metadata;
  std::vector<polishing::PathRow> rows;
  std::vector<int> lines;  // file line of each row
  bool has_uv{false};
};
/// @throws InputError naming file, line and column: missing columns,
///   non-numbers, t_s not strictly increasing, non-unit or non-orthogonal
///   tool axes, a non-positive force.
PolishPathFile ReadPolishPath(const std::string& path);

/// Writes a path: `# key: value` metadata lines, then
/// t_s,x_mm,y_mm,z_mm,nx,ny,nz,tx,ty,tz,u,v. Atomic.
void WritePolishPath(const std::string& path, const std::vector<polishing::PathRow>& rows,
                     const std::vector<std::pair<std::string, std::string>>& metadata);

/// The `# key: value` lines polish-plan writes at the top of a planned path
/// (formats.md §6): pattern, offset_mm, edge_overrun_mm (the one used); for
/// the cycloid guides, radius_mm, pitch_mm, stagger_loops; line_angle_deg
/// where guide lines are parallel.
std::vector<std::pair<std::string, std::string>> PlannedPathMetadata(const polishing::PathParameters& params,
                                                                     const polishing::PolishingProcess& process);

/// Removal map CSV x_mm,y_mm,z_mm,u,v,removal_um of the region's points. Atomic.
void WriteRemovalMap(const std::string& path, const polishing::SampleGrid& grid, const std::vector<double>& removal_m);

}  // namespace robomach::io
