#pragma once

// Shared by polish-plan and polish-sim: surface loading, the removal
// statistics in um, the summary JSON (formats.md §7) and the pictures.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::apps {

/// A NURBS YAML (formats.md §5). CAD files (.step/.stp/.iges/.igs) are
/// refused with a clear message: OpenCASCADE support is not built yet.
polishing::NurbsSurface LoadSurface(const std::string& path, int face);

/// formats.md §7 "removal_um" block (area-weighted over the region).
nlohmann::json RemovalJson(const polishing::RemovalStats& stats_m);
nlohmann::json PathJson(const std::vector<polishing::PathRow>& rows);

/// Pictures next to `png`: the removal map (png itself, colour scale in
/// um on the developed s, t plane), <stem>_histogram.png, <stem>_path.png
/// (path and guide lines, x-y view) and, if `history` is not empty,
/// <stem>_convergence.png. Returns the paths written.
std::vector<std::string> WritePictures(const std::string& png, const polishing::SampleGrid& grid,
                                       const std::vector<double>& removal_m,
                                       const std::vector<polishing::PathRow>& rows,
                                       const std::vector<std::vector<Eigen::Vector3d>>& guide_lines,
                                       const std::vector<double>& history, const std::string& title);

/// The list of picture files WritePictures would write (for clean-up and
/// distinct-path checks).
std::vector<std::string> PicturePaths(const std::string& png, bool with_convergence);

}  // namespace robomach::apps
