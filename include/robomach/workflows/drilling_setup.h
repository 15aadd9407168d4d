#pragma once
// drill-sim's set-up from its three files (docs/formats.md §9): the
// flexible-joint robot, the drill with its process, the material; checked
// against each other (one initial angle per joint, a hole axis the robot
// can feed along, motors that hold the robot at the start), with errors
// located in the file that is wrong.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/drilling/controller_runs.h"
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

/// drill-sim's options, field by field (robot_path is --robot, drill_path
/// --drill, material_path --material, controllers --controller, gains
/// --gains, tune_evaluations --tune-evaluations, motor_torque_limit_Nm
/// --motor-torque-limit-Nm).
struct DrillSimOptions {
  std::string robot_path;     // flexible-joint robot YAML (formats.md §9.3)
  std::string drill_path;     // drill and process YAML (formats.md §9.2)
  std::string material_path;  // material YAML (drill-force-fit's)
  /// Controller kinds (drilling::ControllerKinds() names), run in this order.
  std::vector<std::string> controllers{"pd-tdc"};
  /// "KIND=OMEGA,ZETA[,THIRD[,FILTER_S]]" each (drilling::ParametersFromGains);
  /// a kind not given runs on its defaults; the start of `tune`.
  std::vector<std::string> gains;
  bool tune{false};           // tune every kind's gains first (drilling::TuneController)
  int tune_evaluations{30};   // simulations per kind when tuning
  double motor_torque_limit_Nm{10.0};  // every joint [N·m]

  /// @throws OptionError naming the field: controllers empty, unknown or
  ///   given twice; tune_evaluations outside [5, 1000];
  ///   motor_torque_limit_Nm not > 0.
  void Validate() const;
};

struct DrillSimRun {
  DrillingSetup setup;
  std::vector<drilling::ControllerRun> runs;  // one per kind, in the options' order
  /// drilling::JudgeControllerRuns: diverged runs, implausible units.
  RunFindings verdict;

  RunStatus status() const { return verdict.status(); }
  /// drill-sim's --summary of one run (docs/formats.md §9.4):
  /// io::DrillRunSummaryJson with, when tuned, the tuning's
  /// `solver_status` (robomach::ToString) beside its `status` (NLopt's
  /// message).
  nlohmann::json Summary(const drilling::ControllerRun& run) const;
};

/// The line a run is told by: "pid: settling 0.0991 s, max |e| 0.1 deg,
/// last 10 % max |e| 0.001 deg" ("never" settled; "n/a (run stopped)" for
/// the last 10 % of a run stopped on divergence).
std::string DescribeRun(const drilling::ControllerRun& run);

/// drill-sim's run: checks the options, loads the set-up (LoadDrillingSetup),
/// reads the gains, tunes (with `tune`) and simulates every kind, and judges.
/// Messages, in this order: kWarning per section of the robot file that
/// drill-sim does not use; kInfo "tuning KIND (N simulations)" before each
/// tuning; kWarning when a pd-tdc run fails the TDE stability condition;
/// when all runs are done, kInfo DescribeRun per run, then kWarning per
/// finding of the verdict. Progress: stage "simulating KIND", samples done
/// of the run's.
/// @throws OptionError (Validate; "gains" for a text that is not
///   KIND=numbers or numbers ParametersFromGains refuses, after the files
///   are read); InputError from the files (LoadDrillingSetup).
DrillSimRun RunDrillSim(const DrillSimOptions& options, const MessageSink& tell = {},
                        const std::function<void(const std::string& stage, long done, long total)>& progress = {});

/// drill-force-fit's run on its two files: the measured force table and
/// the drill, the fit, the material file's text, and the unit findings.
/// Flagged (its `verdict`; the tool's exit 3), one finding each, when the fit
/// did not converge, the Kienzle exponent ended on its bound, the model
/// misses a row by more than 10 %, or a unit is implausible.
struct ForceFitRun {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
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
