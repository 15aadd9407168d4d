#pragma once

// A sequence of tool poses followed by a serial chain (a polishing path, a
// drilling or milling pattern): the inverse kinematics of each pose seeded
// from the previous one, the joint-limit margin, the Jacobian's condition
// and the jumps between consecutive poses that a robot cannot execute
// continuously. The apps' "on the robot" checks call it (issue #11, #21).
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/kinematics/inverse_kinematics.h"
#include "robomach/kinematics/serial_chain.h"

namespace robomach::kinematics {

struct PosePathOptions {
  /// Tolerances of a reached pose (IkSolver's defaults: 1e-5 m, 1e-4 rad,
  /// far below what a process path needs).
  IkOptions ik;
  /// Largest change of any joint between consecutive reached poses [rad],
  /// > 0; a larger one (another IK branch, a 2π branch change to stay inside
  /// the limits) is a jump.
  double max_joint_step_rad{0.5};

  /// ik valid (IkOptions::Validate, its fields named "ik.max_iterations",
  /// ...); max_joint_step_rad > 0.
  /// @throws OptionError naming the field, its value and the bound.
  void Validate() const;
};

struct PosePathCheck {
  std::vector<Eigen::VectorXd> q;     // [rad]; empty where unreachable
  std::vector<char> reachable;        // 1 where the pose was reached
  std::vector<double> limit_margin;   // smallest distance to a joint limit [rad] (< 0: outside); NaN where unreachable
  std::vector<double> condition;      // condition number of the 6 × n Jacobian; NaN where unreachable
  int num_unreachable{0}, num_outside_limits{0}, num_jumps{0};
  int first_bad_row{-1};              // 0-based; -1 when every pose is fine
  double min_limit_margin{1e300}, max_condition{0.0};
  bool ok() const { return num_unreachable + num_outside_limits + num_jumps == 0; }
};

/// Follows the tip poses `X_BT` (of the chain's tip frame, in B). Each pose
/// is solved from the previous reached posture, then from `seed` if that
/// fails. Of the 2π branches of each joint, one inside its limits is taken
/// when there is one. @throws std::invalid_argument if `seed` does not have
/// one entry per joint.
PosePathCheck CheckPosePath(const SerialChain& chain, const std::vector<Eigen::Isometry3d>& X_BT,
                            const Eigen::VectorXd& seed, const PosePathOptions& options = {});

}  // namespace robomach::kinematics
