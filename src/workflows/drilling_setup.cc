#include "robomach/workflows/drilling_setup.h"

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/drilling/plausibility.h"

namespace robomach::workflows {

DrillingSetup LoadDrillingSetup(const std::string& robot_path, const std::string& drill_path,
                                const std::string& material_path, double motor_torque_limit_Nm) {
  DrillingSetup s;
  s.robot_file = io::ReadFlexibleRobotFile(robot_path);
  s.drill = io::ReadDrillFile(drill_path);
  if (!s.drill.has_process) {
    throw InputError({drill_path, 0, 0}, "expected a 'process:' section (feed, speed, posture, hole axis)");
  }
  s.material = io::ReadMaterialFile(material_path);
  s.robot = std::make_unique<drilling::FlexibleJointRobot>(s.robot_file.chain, s.robot_file.drives);
  const int n = s.robot->num_joints();
  if (s.drill.process.initial_posture.size() != n) {
    throw InputError(s.drill.initial_posture_at,
                     "initial_posture_deg: expected " + std::to_string(n) + " angles (one per joint), got " +
                         std::to_string(s.drill.process.initial_posture.size()));
  }
  try {
    s.scenario = std::make_unique<drilling::DrillingScenario>(s.robot.get(), s.drill.drill, s.material, s.drill.process);
  } catch (const std::invalid_argument& e) {
    throw InputError(s.drill.hole_axis_at, std::string("hole_axis: ") + e.what());
  }
  s.motor_torque_limit = Eigen::VectorXd::Constant(n, motor_torque_limit_Nm);
  if ((s.scenario->holding_torque().cwiseAbs().array() > s.motor_torque_limit.array()).any()) {
    throw InputError(s.drill.initial_posture_at,
                     "the motors cannot hold the robot at the initial posture within the torque limit "
                     "(--motor-torque-limit-Nm)");
  }
  s.unit_findings = drilling::ToolingFindings(s.drill.drill, &s.drill.process);
  // The readers' own findings carry the prefix the verdict adds again.
  for (const auto* list : {&s.robot_file.implausible, &s.drill.implausible}) {
    for (const std::string& f : *list) {
      const std::string prefix = "implausible (unit mistake?): ";
      s.unit_findings.push_back(f.rfind(prefix, 0) == 0 ? f.substr(prefix.size()) : f);
    }
  }
  for (const std::string& f : drilling::MaterialFindings(s.material)) s.unit_findings.push_back(material_path + ": " + f);
  return s;
}

ForceFitRun FitForceTableFiles(const std::string& table_path, const std::string& drill_path,
                               const drilling::ForceFitOptions& options) {
  ForceFitRun r;
  r.table = io::ReadForceTable(table_path);
  r.drill = io::ReadDrillFile(drill_path);
  if (r.table.rows.size() < 2) {
    throw InputError({table_path, r.table.lines.back(), 0},
                     "expected at least 2 rows to fit 3 coefficients to thrust and torque");
  }
  try {
    r.fit = drilling::FitDrillingForces(r.drill.drill, r.table.rows, options);
  } catch (const drilling::ForceTableRowError& e) {
    // Bad data at the row's line.
    throw InputError({table_path, r.table.lines.at(e.row()), 0}, e.what());
  }
  if (r.fit.status == drilling::FitStatus::kFailed) return r;
  r.material_yaml = io::MaterialYaml(r.fit, r.drill.drill, r.table);
  r.unit_findings = drilling::ForceTableFindings(r.table.rows);
  for (const auto& more : {drilling::MaterialFindings(r.fit.material), drilling::ToolingFindings(r.drill.drill, nullptr)}) {
    r.unit_findings.insert(r.unit_findings.end(), more.begin(), more.end());
  }
  if (r.fit.status != drilling::FitStatus::kConverged) r.Flag("the fit did not converge: " + r.fit.solver_message);
  if (r.fit.kienzle_exponent_at_bound) {
    r.Flag("the Kienzle exponent ended on its bound (" + FormatDouble(r.fit.material.kienzle_exponent) +
           ", range 0..0.95): the forces do not grow with the feed as a size effect can; check the units of "
           "feed_mm_per_rev, thrust_N and torque_Nm");
  }
  if (r.fit.max_rel_error_thrust > 0.10 || r.fit.max_rel_error_torque > 0.10) {
    r.Flag("the model misses a row by more than 10 %; check the table and the drill geometry");
  }
  for (const std::string& f : r.unit_findings) r.Flag("implausible (unit mistake?): " + f);
  return r;
}

}  // namespace robomach::workflows
