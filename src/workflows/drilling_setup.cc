#include "robomach/workflows/drilling_setup.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/solver_status.h"
#include "robomach/common/units.h"
#include "robomach/drilling/controller_kinds.h"
#include "robomach/drilling/plausibility.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/drill_series_file.h"

namespace robomach::workflows {
namespace {

// One --gains text, "KIND=OMEGA,ZETA[,THIRD[,FILTER_S]]": the kind's
// parameters (drilling::ParametersFromGains).
drilling::ControllerParameters ParseGains(const std::string& text, std::string* kind) {
  const auto eq = text.find('=');
  *kind = text.substr(0, eq);
  if (eq == std::string::npos) {
    throw OptionError("gains", "gains: expected KIND=OMEGA,ZETA[,THIRD] with KIND " + drilling::ControllerKindList() +
                                   ", got \"" + text + "\"");
  }
  const std::string numbers = text.substr(eq + 1);
  std::vector<double> v;
  for (size_t pos = 0; pos <= numbers.size();) {
    const size_t comma = std::min(numbers.find(',', pos), numbers.size());
    double x = 0.0;
    if (!io::ParseFiniteNumber(numbers.substr(pos, comma - pos), &x)) {
      throw OptionError("gains", "gains: expected numbers separated by commas, got \"" + numbers + "\"");
    }
    v.push_back(x);
    pos = comma + 1;
  }
  try {
    return drilling::ParametersFromGains(*kind, v);
  } catch (const std::invalid_argument& e) {
    throw OptionError("gains", "gains " + text + ": " + e.what());
  }
}

}  // namespace

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
  s.scenario = AtLocation(s.drill.hole_axis_at, "hole_axis: ", [&] {
    return std::make_unique<drilling::DrillingScenario>(s.robot.get(), s.drill.drill, s.material, s.drill.process);
  });
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

void DrillSimOptions::Validate() const {
  if (controllers.empty()) throw OptionError("controllers", "controllers: expected at least one controller");
  for (size_t i = 0; i < controllers.size(); ++i) {
    try {
      drilling::FindControllerKind(controllers[i]);
    } catch (const std::invalid_argument& e) {
      throw OptionError("controllers", std::string("controllers: ") + e.what());
    }
    if (std::find(controllers.begin(), controllers.begin() + i, controllers[i]) != controllers.begin() + i) {
      throw OptionError("controllers", "controllers: \"" + controllers[i] + "\" given twice");
    }
  }
  if (!(tune_evaluations >= 5 && tune_evaluations <= 1000)) {
    throw OptionError("tune_evaluations",
                      "tune_evaluations " + std::to_string(tune_evaluations) + " is outside [5, 1000]");
  }
  if (!(motor_torque_limit_Nm > 0.0 && std::isfinite(motor_torque_limit_Nm))) {
    throw OptionError("motor_torque_limit_Nm",
                      "motor_torque_limit_Nm " + FormatNumber(motor_torque_limit_Nm) + ": expected a finite value > 0 N·m");
  }
}

nlohmann::json DrillSimRun::Summary(const drilling::ControllerRun& run) const {
  nlohmann::json j = io::DrillRunSummaryJson(run, *setup.scenario, setup.motor_torque_limit);
  return j;
}

std::string DescribeRun(const drilling::ControllerRun& run) {
  const drilling::SimResult& r = run.result;
  const bool stopped = r.diverged;  // the last 10 % was never simulated
  std::ostringstream line;
  line << run.parameters.kind << ": settling "
       << (std::isnan(r.settling_time) ? std::string("never") : FormatNumber(r.settling_time) + " s")
       << ", max |e| " << FormatNumber(RadToDeg(r.max_abs_error.maxCoeff())) << " deg, last 10 % max |e| "
       << (stopped ? std::string("n/a (run stopped)")
                   : FormatNumber(RadToDeg(r.max_abs_error_last_10pc.maxCoeff())) + " deg");
  return line.str();
}

DrillSimRun RunDrillSim(const DrillSimOptions& o, const MessageSink& tell,
                        const std::function<void(const std::string&, long, long)>& progress) {
  o.Validate();
  DrillSimRun out;
  out.setup = LoadDrillingSetup(o.robot_path, o.drill_path, o.material_path, o.motor_torque_limit_Nm);
  for (const auto& u : out.setup.robot_file.unused_sections) {
    Tell(tell, Message::Kind::kWarning, o.robot_path + ": section '" + u + "' is not used by drill-sim");
  }
  drilling::ControllerRunOptions ro;
  for (const std::string& text : o.gains) {
    std::string kind;
    const drilling::ControllerParameters p = ParseGains(text, &kind);
    ro.given[kind] = p;
  }
  ro.kinds = o.controllers;
  ro.tune = o.tune;
  ro.tune_evaluations = o.tune_evaluations;
  ro.motor_torque_limit = out.setup.motor_torque_limit;
  out.runs = drilling::RunControllers(*out.setup.scenario, ro, [&](const drilling::ControllerRunProgress& p) {
    if (p.tuning) {
      Tell(tell, Message::Kind::kInfo, "tuning " + p.kind + " (" + std::to_string(p.total) + " simulations)");
    } else if (p.finished) {
      if (p.run && p.run->tde_condition_fails()) {
        Tell(tell, Message::Kind::kWarning,
             "pd-tdc: the TDE stability condition ||I - M^-1 Mbar|| < 1 fails (" + FormatNumber(p.run->tde_measure) +
                 "); lower the Mbar ratio");
      }
    } else if (progress) {
      progress("simulating " + p.kind, p.done, p.total);
    }
  });
  // All runs done: the result lines, then the verdict (diverged runs, unit
  // plausibility: drilling/plausibility.h), so that every summary written
  // after lists its warnings.
  for (const drilling::ControllerRun& run : out.runs) Tell(tell, Message::Kind::kInfo, DescribeRun(run));
  out.verdict = drilling::JudgeControllerRuns(out.runs, out.setup.unit_findings);
  for (const Finding& f : out.verdict.findings) Tell(tell, Message::Kind::kWarning, f.message);
  return out;
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
  if (r.fit.status != drilling::FitStatus::kConverged) r.verdict.Flag("the fit did not converge: " + r.fit.solver_message);
  if (r.fit.kienzle_exponent_at_bound) {
    r.verdict.Flag("the Kienzle exponent ended on its bound (" + FormatDouble(r.fit.material.kienzle_exponent) +
           ", range 0..0.95): the forces do not grow with the feed as a size effect can; check the units of "
           "feed_mm_per_rev, thrust_N and torque_Nm");
  }
  if (r.fit.max_rel_error_thrust > 0.10 || r.fit.max_rel_error_torque > 0.10) {
    r.verdict.Flag("the model misses a row by more than 10 %; check the table and the drill geometry");
  }
  for (const std::string& f : r.unit_findings) r.verdict.Flag("implausible (unit mistake?): " + f);
  return r;
}

}  // namespace robomach::workflows
