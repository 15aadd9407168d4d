#pragma once
// A polishing path on a robot (issue 11 "on the robot"; polish-plan and
// polish-sim --robot): the part frame in the robot base, the flange pose of
// every row, the arm's IK along them, the joint trajectory CSV and the
// summary's "robot" block.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "robomach/common/run_status.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/kinematics/pose_path.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/process.h"

namespace robomach::workflows {

/// X_BP from x, y, z [mm] and rx, ry, rz [deg] about the fixed x, y, z axes
/// (R = Rz Ry Rx). @throws std::invalid_argument unless 6 numbers.
Eigen::Isometry3d PartFrameFromMmDeg(const std::vector<double>& xyz_mm_rxyz_deg);

/// Each row's contact frame C (z = the surface normal towards the tool,
/// x = tool x) in B, the flange pose X_BF = X_BP X_PC X_FC^-1 with the
/// process's contact frame in the flange, followed by the arm
/// (kinematics::CheckPosePath: IK seeded from the previous row, the first
/// from `seed` [rad]).
kinematics::PosePathCheck CheckPolishPathOnRobot(const dynamics::RobotModel& model, const Eigen::Isometry3d& X_BP,
                                                 const polishing::PolishingProcess& process,
                                                 const std::vector<polishing::PathRow>& rows,
                                                 const Eigen::VectorXd& seed);

/// Flagged when a row is unreachable, outside the joint limits or after a
/// joint jump > 0.5 rad: one finding that counts them and names the first
/// (1-based) row.
RunFindings JudgePolishPathOnRobot(const kinematics::PosePathCheck& check);

/// The summary's "robot" block: rows, unreachable, outside the limits and
/// joint-jump rows, the first flagged row (1-based, null when none), the
/// smallest joint-limit margin [deg] and the largest Jacobian condition.
nlohmann::json PolishRobotSummaryJson(const std::vector<polishing::PathRow>& rows,
                                      const kinematics::PosePathCheck& check);


}  // namespace robomach::workflows
