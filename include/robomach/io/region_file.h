#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/stability/stability_map.h"

namespace robomach::io {

/// Plausible distance of a region's corner from the robot's base [mm]: a
/// robot's tool is 0.05 - 20 m from its base (as the tracker file's
/// kMin/MaxPlausibleTargetDistanceMm).
inline constexpr double kMinPlausibleRegionDistanceMm = 50.0, kMaxPlausibleRegionDistanceMm = 20000.0;

/// A rectangular work region as `region_*.yaml` describes it (see
/// config/region_demo.yaml for the documented schema), in SI and radians.
struct RegionSpec {
  Eigen::Vector3d origin_B{Eigen::Vector3d::Zero()};  // corner of the rectangle [m]
  Eigen::Vector3d u_B{Eigen::Vector3d::UnitX()};      // first plane axis (unit)
  Eigen::Vector3d v_B{Eigen::Vector3d::UnitY()};      // second plane axis (unit, ⟂ u)
  double size_u{0.0}, size_v{0.0};                     // [m]
  double grid_step{0.0};                               // [m]
  double lead{0.0};   // tool tilt about v [rad]; 0 = tool along −n, n = u × v
  double tilt{0.0};   // tool tilt about u [rad]
  bool rotation_free{false};
  double rotation_fixed{0.0};                     // [rad] about the tool axis
  double rotation_min{0.0}, rotation_max{0.0};    // [rad] when free
  Eigen::VectorXd seed_q;                         // preferred arm configuration [rad]
  std::string path;
  int origin_line{0}, origin_column{0};  // where origin_mm is, for messages
  /// Sense checks (docs/plausibility.md; the tool warns and exits 3): the
  /// corner within 50 mm of the base (metres typed under origin_mm), the
  /// seed posture all within one turn and fractional (radians under _deg).
  std::vector<std::string> implausible;

  int num_u() const;  // grid points along u (size/step + 1)
  int num_v() const;
  /// Tool direction z_T (spindle to tip) in B.
  Eigen::Vector3d ToolDirection() const;
  /// Targets in row-major order: row j along v, column i along u, with
  /// `feed_B` as the feed. x_ref is u projected normal to the tool.
  std::vector<stability::ToolPoseTarget> Targets(const Eigen::Vector3d& feed_B) const;
  /// In-plane coordinates [m] of target (row, col) from the origin.
  Eigen::Vector2d PlaneCoordinates(int row, int col) const { return {col * grid_step, row * grid_step}; }
};

/// Reads a region file. Keys: `origin_mm` [x, y, z], `u_axis`, `v_axis`
/// (base-frame directions; v is made orthogonal to u), `size_mm` [along u,
/// along v], `grid_step_mm`, optional `tool_axis` {`lead_deg`, `tilt_deg`},
/// `rotation_about_tool_axis` {`fixed_deg`} or {`free`: {`min_deg`,
/// `max_deg`}}, and `seed_posture_deg` (one angle per joint).
/// @throws InputError with file:line:col.
RegionSpec ReadRegionFile(const std::string& path, int num_joints);

/// One tool pose of a path CSV: `x_mm,y_mm,z_mm,tool_i,tool_j,tool_k`
/// (the tool axis from the tip towards the spindle, as CAM software writes
/// it), optional `feed_i,feed_j,feed_k` (else the cut's feed direction),
/// `rotation_deg` about the tool axis and `point_id`.
struct PathPoint {
  std::string id;
  stability::ToolPoseTarget target;
  double rotation{0.0};  // [rad]
  bool has_feed{false};
  int line{0};
};
std::vector<PathPoint> ReadToolPathFile(const std::string& path, const Eigen::Vector3d& default_feed_B);

}  // namespace robomach::io
