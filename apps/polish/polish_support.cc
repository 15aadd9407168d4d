#include "polish_support.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/cad_face.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/polishing_files.h"

namespace robomach::apps {

void AddSurfaceChoiceOptions(CLI::App* app, SurfaceChoice* choice) {
  app->add_option("--face", choice->cad_face,
                  "face of a STEP/IGES file (1-based, in the file's order; polish-plan --list-faces lists them); "
                  "0 or not given: the largest by area (named on stderr). An error with a YAML surface")
      ->capture_default_str();
  app->add_option("--cad-unit-scale", choice->cad_unit_scale,
                  "multiply a STEP/IGES file's lengths (as read in mm) by this (> 0): 1000 for a file that says mm but "
                  "holds metres (the reader warns when a part is under 1 mm or over 10 m)")
      ->capture_default_str();
}

}  // namespace robomach::apps

#include "robomach/common/units.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"
#include "robomach/workflows/polish_robot_check.h"

namespace robomach::apps {

void RobotOptions::Add(CLI::App* app) {
  app->add_option("--robot", robot_path_, "robot config YAML: solve the IK of every tool frame, flag unreachable rows, "
                                          "joint-limit and singularity margins (summary 'robot' block)");
  app->add_option("--part-frame-mm-deg", part_frame_text_, "with --robot: the surface's frame in the robot base, "
                                                           "x,y,z [mm], rx,ry,rz [deg] about fixed x, y, z")
      ->capture_default_str();
  app->add_option("--robot-seed-deg", seed_text_, "with --robot: IK start of the first row [deg]")->capture_default_str();
  app->add_option("--joints", joints_out_,
                  "with --robot: joint trajectory CSV t_s,q1_deg..,reachable,limit_margin_deg,jacobian_condition");
}

void RobotOptions::Prepare(std::vector<std::pair<std::string, std::string>>* outs) {
  outs->push_back({"--joints", joints_out_});
  if (!joints_out_.empty() && robot_path_.empty()) throw UsageError("--joints needs --robot");
  part_ = ParseNumberList("--part-frame-mm-deg", part_frame_text_);
  seed_deg_ = ParseNumberList("--robot-seed-deg", seed_text_);
  if (part_.size() != 6) throw UsageError("--part-frame-mm-deg: expected x,y,z,rx,ry,rz (6 numbers)");
  if (robot_path_.empty()) return;
  RequireReadableFile(robot_path_, "robot config");
  robot_ = io::LoadRobotConfig(robot_path_).Build();
  if (static_cast<int>(seed_deg_.size()) != robot_->num_joints()) {
    throw UsageError("--robot-seed-deg: expected " + std::to_string(robot_->num_joints()) + " angles");
  }
}

bool RobotOptions::Check(const std::string& tool, const polishing::PolishingProcess& process,
                         const std::vector<polishing::PathRow>& rows, nlohmann::json* summary) {
  if (!robot_) return false;
  Eigen::VectorXd q0(robot_->num_joints());
  for (int j = 0; j < q0.size(); ++j) q0(j) = DegToRad(seed_deg_[j]);
  check_ = workflows::CheckPolishPathOnRobot(*robot_, workflows::PartFrameFromMmDeg(part_), process, rows, q0);
  (*summary)["robot"] = workflows::PolishRobotSummaryJson(rows, check_);
  const RunFindings verdict = workflows::JudgePolishPathOnRobot(check_);
  for (const Finding& f : verdict.findings) Warn(tool, f.message);
  return verdict.flagged();
}

void RobotOptions::WriteJoints(const std::vector<polishing::PathRow>& rows) const {
  if (robot_ && !joints_out_.empty()) io::WriteJointTrajectoryCsv(joints_out_, rows, check_, robot_->num_joints());
}

}  // namespace robomach::apps
