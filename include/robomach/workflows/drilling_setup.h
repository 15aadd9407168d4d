#pragma once
// drill-sim's set-up from its three files (docs/formats.md §9): the
// flexible-joint robot, the drill with its process, the material; checked
// against each other (one initial angle per joint, a hole axis the robot
// can feed along, motors that hold the robot at the start), with errors
// located in the file that is wrong.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/run_status.h"
#include "robomach/drilling/drilling_sim.h"
#include "robomach/drilling/flexible_joint_robot.h"
#include "robomach/drilling/force_fit.h"
#include "robomach/io/drilling_files.h"

namespace robomach::workflows {

struct DrillingSetup {
  io::FlexibleRobotFile robot_file;
  io::DrillFile drill;
  drilling::DrillingMaterial material;
  std::unique_ptr<drilling::FlexibleJointRobot> robot;
  std::unique_ptr<drilling::DrillingScenario> scenario;  // on *robot
  Eigen::VectorXd motor_torque_limit;                    // per joint [N·m]
  /// Unit plausibility of the drill, process and material
  /// (drilling/plausibility.h), each naming its file where it is not the
  /// drill file's own value: a run on them is flagged (exit 3).
  std::vector<std::string> unit_findings;
};

/// @throws InputError naming the file (and line) for a drill file without a
///   process, an initial posture of the wrong size, a hole axis the robot
///   cannot feed along, a holding torque above the limit.
DrillingSetup LoadDrillingSetup(const std::string& robot_path, const std::string& drill_path,
                                const std::string& material_path, double motor_torque_limit_Nm);

/// drill-force-fit's run on its two files: the measured force table and
/// the drill, the fit, the material file's text, and the unit findings.
/// Flagged (RunFindings; the tool's exit 3), one finding each, when the fit
/// did not converge, the Kienzle exponent ended on its bound, the model
/// misses a row by more than 10 %, or a unit is implausible.
struct ForceFitRun : RunFindings {
  io::ForceTableFile table;
  io::DrillFile drill;
  drilling::ForceFitResult fit;
  std::string material_yaml;  // MaterialYaml of the fit (empty when it failed)
  /// Unit plausibility of the table, the fitted material and the drill
  /// (drilling/plausibility.h): the tool exits 3 on any.
  std::vector<std::string> unit_findings;
};

/// @throws InputError naming the file and line for a table of fewer than 2
///   rows or a row the force model cannot use.
ForceFitRun FitForceTableFiles(const std::string& table_path, const std::string& drill_path,
                               const drilling::ForceFitOptions& options = {});

}  // namespace robomach::workflows
