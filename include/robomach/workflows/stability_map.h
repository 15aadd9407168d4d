#pragma once
// stability-map's run (issue #36): one call from the files to the map, its
// depth intervals and its verdict; the tool parses options and writes the
// CSV, the heat maps and the summary; Python calls the same function.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/uncertainty.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/region_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/stability_map_file.h"
#include "robomach/stability/lobe_uncertainty.h"
#include "robomach/stability/stability_map.h"
#include "robomach/workflows/frf_predict.h"

namespace robomach::workflows {

struct StabilityMapOptions {
  std::string robot_path;   // robot config YAML
  std::string cut_path;     // cut file YAML
  std::string region_path;  // region file YAML: the grid, or with path_path the seed posture and rotation
  std::string path_path;    // tool-path CSV (formats.md): points along a path instead of the region's grid
  int threads{0};           // 0: all cores
  int speeds{0};            // speeds scanned for the best one; 0: the cut file's spindle_speed_count
  double max_depth_mm{50.0};  // largest depth searched for mode coupling [mm]
  int rotation_evaluations{20};  // per point when the region leaves the rotation free
  /// Parameter-uncertainty files (formats.md §12): each point's critical
  /// depth gets its interval. Empty: those the robot config names.
  std::vector<std::string> uncertainty_paths;
  dynamics::PropagationOptions uncertainty;

  /// @throws OptionError naming the field: region_path empty, max_depth_mm
  ///   outside (0, 10000], speeds outside [0, 100000], rotation_evaluations under 8,
  ///   threads outside [0, 256], the uncertainty's options.
  void Validate() const;
  /// Validate's checks but region_path's: those of the settings, which
  /// Python's stability_map (no region file, its own targets) shares.
  void ValidateSettings() const;
};

struct StabilityMapRun {
  io::RobotConfig config;  // as used (the uncertainty's estimates in it)
  std::vector<std::string> uncertainty_files;
  io::CutSpec cut;
  io::RegionSpec region;
  io::MapPoints points;  // the grid's or the path's targets (points.grid: a grid)
  int num_joints{0};
  stability::StabilityMapResult map;
  std::optional<stability::MapDepthIntervals> intervals;  // with uncertainty files
  /// The unit findings of the config, the cut and the region: the tool
  /// flags its result (exit 3) on any.
  std::vector<std::string> input_findings;

  /// Flagged on the map's findings or any input finding.
  RunStatus status() const {
    return input_findings.empty() ? map.status() : RunStatus::kFlagged;
  }
  /// "row 2, col 5" of a grid, "point 6 of the path" of a path.
  std::string Where(long index) const;
  /// The summary's result part (docs/formats.md §4.1; without the tool's
  /// name, its CSV path, warnings and exit code).
  nlohmann::json Summary(const StabilityMapOptions& o) const;
};

/// Reads the files, checks them, computes the map (progress stage
/// "points") and, with uncertainty files, each point's interval (stage
/// "points' intervals"); tells the closed form's agreement, the cost of
/// Monte Carlo, the intervals' methods and the smallest safe depth.
/// @throws OptionError (Validate); io::MissingFileError, InputError for the
///   files (a feed along the tool axis, no reachable point).
StabilityMapRun RunStabilityMap(const StabilityMapOptions& o, const MessageSink& tell = {},
                                const StageProgress& progress = {});

}  // namespace robomach::workflows
