#pragma once
// The ZOA lobes of a robot posture with the uncertainty of fitted model
// parameters (issue #37): each speed's critical depth and the smallest one
// as intervals, whose lower ends are the safe depths of cut.

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/dynamics/robot_model.h"
#include "robomach/dynamics/uncertainty.h"
#include "robomach/stability/lobes_workflow.h"
#include "robomach/stability/stability_map.h"

namespace robomach::stability {

struct ZoaBand {
  std::string id;
  Eigen::VectorXd speed_rad_s;                  // the ZOA's speeds (LobesOptions::zoa_speeds_rad_s)
  /// Per speed: the critical depth [m] and its interval; NaN where the lobes
  /// have no boundary at the estimates (those speeds are not propagated).
  std::vector<dynamics::OutputInterval> depth;
  /// The smallest critical depth over the speeds [m] (the lobe bottom a
  /// process engineer reads): its lower end is the depth that is stable at
  /// every speed with the confidence asked for.
  dynamics::OutputInterval min_depth;
  dynamics::PropagationResult propagation;      // method, reason, evaluations
};

/// The ZOA critical depths at `options.zoa_speeds_rad_s` of the tool tip of
/// `description` with `base` parameters at posture q (TipFromPosture with
/// `feed_B`, the process's teeth and options.max_speed_rad_s, then
/// ComputeZoaLobes as ComputeLobes runs it), with intervals from `u`. A
/// sample whose lobes lose the boundary at a propagated speed counts as
/// failed (PropagationResult::failed_samples).
/// @throws std::invalid_argument as dynamics::Propagate, or when the lobes
///   have no boundary at any speed at the estimates.
/// The ZOA critical depth [m] at each of options.zoa_speeds_rad_s of the
/// model at posture q (NaN where the lobes have no boundary): what
/// ZoaLobeBand propagates. Its smallest finite value is the lobe bottom.
Eigen::VectorXd ZoaCriticalDepths(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                                  const std::string& id, const Eigen::VectorXd& q, const Eigen::Vector3d& feed_B,
                                  const LobesOptions& options);

ZoaBand ZoaLobeBand(const dynamics::RobotDescription& description, const dynamics::ParameterSet& base,
                    const std::string& id, const Eigen::VectorXd& q, const Eigen::Vector3d& feed_B,
                    const LobesOptions& options, const dynamics::ParameterUncertainty& u,
                    const dynamics::PropagationOptions& propagation = {});

/// The interval of each map point's critical depth (its lower end is the
/// point's safe depth): the point's posture and rotation as the map found
/// them (the IK does not depend on the uncertain parameters), the analysis
/// (AnalysePosture: mode coupling and ZOA) repeated by the propagation.
/// The first-order derivatives come from LocalCriticalDepth at each point
/// (one eigenvalue problem and a few one-frequency receptances per step,
/// not an analysis): with forced first order it is the output (no
/// analysis at all), with auto it gives the derivatives and the analyses
/// the sigma points. It is built on the point's analysis when `base` holds
/// the uncertainty's estimates (`points` must then come from a map of
/// RobotModel::Build(description, base); the mode-coupling crossing is
/// checked to be one of these dynamics), else on one analysis at the
/// estimates. Where it cannot be built or does not reach a step, the
/// analysis is repeated per step and the point's reason says why.
/// Points not analysed (unreachable, joint limits) or without a finite
/// critical depth get NaN. `progress` is called with (points done, total)
/// from the calling thread; `threads` as MapOptions (0: all cores).
struct MapDepthIntervals {
  std::vector<dynamics::OutputInterval> depth;  // per point [m]
  int first_order{0}, monte_carlo{0};           // points by the method used
  std::string example_reason;                   // the reason of the first point that used Monte Carlo, else of the first
  long evaluations{0};
  int local_model{0};  // first-order points whose derivatives came from LocalCriticalDepth
  /// The point with the smallest finite lower bound (the safe depth that
  /// holds everywhere), -1 when none is finite.
  long SmallestLower() const {
    long best = -1;
    for (size_t i = 0; i < depth.size(); ++i) {
      if (std::isfinite(depth[i].lower) && (best < 0 || depth[i].lower < depth[static_cast<size_t>(best)].lower)) {
        best = static_cast<long>(i);
      }
    }
    return best;
  }
};
MapDepthIntervals StabilityMapIntervals(const dynamics::RobotDescription& description,
                                        const dynamics::ParameterSet& base,
                                        const std::vector<ToolPoseTarget>& targets,
                                        const std::vector<MapPoint>& points, const MillingProcess& process,
                                        const PostureStabilityOptions& analysis,
                                        const dynamics::ParameterUncertainty& u,
                                        const dynamics::PropagationOptions& propagation, int threads = 0,
                                        const ProgressCallback& progress = {});

}  // namespace robomach::stability
