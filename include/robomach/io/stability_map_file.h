#pragma once
// stability-map's points and outputs (docs/formats.md §4): the tool poses
// of a region's grid or of a tool-path file, the per-point CSV and the
// summary JSON's result part.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/dynamics/uncertainty.h"
#include "robomach/io/region_file.h"
#include "robomach/stability/stability_map.h"

namespace robomach::io {

/// The tool poses of a map and how its files name them: a grid (row, col
/// and the in-plane coordinates from the region's origin) or a path (the
/// point_id of each pose).
struct MapPoints {
  bool grid{true};
  int rows{0}, cols{0};       // a path is one row
  double grid_step{0.0};      // [m], grid only
  std::vector<stability::ToolPoseTarget> targets;  // row-major on a grid
  std::vector<std::string> ids;                    // path only
  /// Path only: each pose's rotation about the tool axis [rad], added to
  /// the region's (already turned into its x_ref; the CSV reports the sum).
  std::vector<double> path_rotation;
};

/// The grid of `region` (RegionSpec::Targets) with the cut's feed.
MapPoints MapPointsOfRegion(const RegionSpec& region, const Eigen::Vector3d& feed_B);

/// The poses of a tool-path CSV (ReadToolPathFile): a pose's rotation_deg
/// turns its x_ref about the tool axis.
/// @throws InputError as ReadToolPathFile.
MapPoints MapPointsOfPathFile(const std::string& path, const Eigen::Vector3d& default_feed_B);

/// The per-point CSV: row,col,x_mm,y_mm (grid) or point_id (path), the
/// pose, the joint angles, the mode-coupling, closed-form and regenerative
/// depths, the limiting mechanism, the chatter frequency, cond(J) and the
/// status. Written through WriteFileAtomically ("-" = stdout).
/// With `depth_intervals` (stability-map --uncertainty) the columns
/// critical_depth_mm_lower (the safe depth) and critical_depth_mm_upper follow.
void WriteStabilityMapCsv(const std::string& path, const MapPoints& points,
                          const std::vector<stability::MapPoint>& results, int num_joints,
                          const std::vector<dynamics::OutputInterval>* depth_intervals = nullptr);

/// The summary's result part (docs/formats.md §4.1): mode, points, grid
/// size, points reached, flagged and by status, and the smallest and
/// largest critical depth with where they are (as in the CSV; `extremes`:
/// stability::FindCriticalDepthExtremes of map.points).
nlohmann::json StabilityMapSummaryJson(const MapPoints& points, const stability::StabilityMapResult& map,
                                       const stability::CriticalDepthExtremes& extremes);

}  // namespace robomach::io
