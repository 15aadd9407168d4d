#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/common/progress.h"
#include "robomach/common/run_status.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/stability/posture_stability.h"

namespace robomach::stability {

/// A tool pose to evaluate: the TCP at p_BT with its z axis (spindle to tool
/// tip, into the work) along z_T, its x axis at `rotation` about z_T from
/// x_ref, and the feed direction (all in B).
struct ToolPoseTarget {
  Eigen::Vector3d p_BT{Eigen::Vector3d::Zero()};  // [m]
  Eigen::Vector3d z_T{Eigen::Vector3d::UnitZ()};  // unit
  Eigen::Vector3d x_ref{Eigen::Vector3d::UnitX()};  // unit, normal to z_T
  Eigen::Vector3d feed_B{Eigen::Vector3d::UnitX()};
  /// X_BT for a rotation [rad] about the tool axis.
  Eigen::Isometry3d Pose(double rotation) const;
};

enum class PointStatus {
  kOk,
  kUnreachable,        // IK did not reach the pose (1e-5 m, 1e-4 rad)
  kJointLimits,        // IK reached it only outside the joint limits
  kNearSingular,       // reached, but cond(J) > kNearSingularCondition
  kOtherConfiguration, // reached on another arm configuration than the seed's (wrist flip)
};
const char* ToString(PointStatus s);
/// The inverse of ToString. @throws std::invalid_argument naming the five.
PointStatus ParsePointStatus(const std::string& name);

struct MapOptions {
  Eigen::VectorXd seed_q;            // preferred arm configuration [rad]
  double rotation{0.0};              // fixed rotation about the tool axis [rad]
  bool optimise_rotation{false};     // choose it per point in [rotation_min, rotation_max]
  double rotation_min{-0.5 * kPi}, rotation_max{0.5 * kPi};  // [rad]
  int rotation_evaluations{20};      // budget of the NLopt search per point
  PostureStabilityOptions analysis;
  int threads{0};                    // 0 = all cores
  ProgressCallback progress;         // called from the calling thread

  /// @throws OptionError naming the field, its value and the bound:
  /// rotation finite; with optimise_rotation, rotation_min, rotation_max
  /// finite and rotation_max > rotation_min (the search interval), and
  /// rotation_evaluations >= 8 (the coarse scan takes 7, NLopt at least one
  /// more); threads >= 0; the nested analysis.* fields
  /// (PostureStabilityOptions::Validate, so at least one speed). seed_q's
  /// size is checked against the robot by EvaluateStabilityMap.
  void Validate() const;
};

struct MapPoint {
  PointStatus status{PointStatus::kUnreachable};
  Eigen::VectorXd q;           // [rad]; IK result even when flagged (empty if none)
  double rotation{0.0};        // [rad] the rotation used
  double jacobian_condition{NAN};
  PostureStability stability;  // evaluated for kOk and kNearSingular points
  std::string optimiser_status;  // NLopt outcome when the rotation is optimised
};

/// The first target whose feed direction has no part in the work plane
/// (normal to its tool axis, within 1e-6 of its length): no cutting frame;
/// -1 when every target has one.
int FirstFeedAlongToolAxis(const std::vector<ToolPoseTarget>& targets);

/// Evaluates a grid of rows × cols targets (row-major) or, with rows = 1, a
/// path. IK (KDL ChainIkSolverPos_LMA) is seeded from the neighbour so
/// the arm stays on one configuration: the first column from the point
/// above (the first point from seed_q), then each row along its columns.
/// Points are then analysed in parallel, one PostureEvaluator per thread,
/// each on its own copy of the model (KDL joints cache their last pose in
/// mutable members, so threads must not share a KDL chain).
/// With optimise_rotation, each point maximises its critical depth over
/// the rotation about the tool axis with NLopt (LN_COBYLA after a coarse
/// scan), re-solving the IK from the point's solution each time.
/// @throws std::invalid_argument if rows·cols != targets.size() or the seed
///   has the wrong size; OptionError for bad options (MapOptions::Validate).
std::vector<MapPoint> EvaluateStabilityMap(std::shared_ptr<const dynamics::RobotModel> model,
                                           const std::vector<ToolPoseTarget>& targets, int rows,
                                           int cols, const MillingProcess& process,
                                           const MapOptions& options);

/// stability-map's run: the points of EvaluateStabilityMap and its verdict,
/// flagged (exit 3) with one finding when any point is not kOk.
struct StabilityMapResult {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  std::vector<MapPoint> points;
  /// Points the IK reached within the joint limits (ok, near singular,
  /// other configuration); none is an error of the caller's region or path.
  long reached{0};
  long flagged_points{0};  // points whose status is not kOk
};

/// EvaluateStabilityMap with its verdict (the same arguments and errors).
StabilityMapResult ComputeStabilityMap(std::shared_ptr<const dynamics::RobotModel> model,
                                       const std::vector<ToolPoseTarget>& targets, int rows, int cols,
                                       const MillingProcess& process, const MapOptions& options);

/// How far the seed's simplified closed form agrees with the eigenvalue
/// criterion over a map (issue #6 asks to report it): the ratio closed-form
/// depth / mode-coupling depth at the points where the mode coupling found a
/// limit and the closed form a positive depth. NaN statistics when none.
struct ClosedFormAgreement {
  long points{0};
  double median{NAN};  // the upper median for an even count
  double min{NAN}, max{NAN};
};
ClosedFormAgreement CompareClosedForm(const std::vector<MapPoint>& points);

/// The points with the smallest and the largest finite critical depth (the
/// first of equal ones; -1 when no point has one) and how many have one.
struct CriticalDepthExtremes {
  long with_depth{0};
  long min_index{-1}, max_index{-1};
};
CriticalDepthExtremes FindCriticalDepthExtremes(const std::vector<MapPoint>& points);

}  // namespace robomach::stability
