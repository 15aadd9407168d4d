#include "robomach/workflows/polish_robot_check.h"

#include <ostream>
#include <stdexcept>

#include "robomach/common/units.h"

namespace robomach::workflows {

Eigen::Isometry3d PartFrameFromMmDeg(const std::vector<double>& v) {
  if (v.size() != 6) throw std::invalid_argument("part frame: expected x,y,z,rx,ry,rz (6 numbers)");
  Eigen::Isometry3d X_BP = Eigen::Isometry3d::Identity();
  X_BP.translation() = Eigen::Vector3d(v[0], v[1], v[2]) * 1e-3;
  X_BP.linear() = (Eigen::AngleAxisd(DegToRad(v[5]), Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(DegToRad(v[4]), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(DegToRad(v[3]), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  return X_BP;
}

kinematics::PosePathCheck CheckPolishPathOnRobot(const dynamics::RobotModel& model, const Eigen::Isometry3d& X_BP,
                                                 const polishing::PolishingProcess& process,
                                                 const std::vector<polishing::PathRow>& rows,
                                                 const Eigen::VectorXd& seed) {
  Eigen::Isometry3d X_FC = Eigen::Isometry3d::Identity();
  X_FC.linear() = process.R_FC;
  X_FC.translation() = process.p_FC;
  const Eigen::Isometry3d X_CF = X_FC.inverse();
  std::vector<Eigen::Isometry3d> X_BF;
  X_BF.reserve(rows.size());
  for (const polishing::PathRow& row : rows) X_BF.push_back(X_BP * polishing::ContactFrame(row) * X_CF);
  return kinematics::CheckPosePath(model.description().arm, X_BF, seed);
}

RunFindings JudgePolishPathOnRobot(const kinematics::PosePathCheck& c) {
  RunFindings f;
  if (c.ok()) return f;
  f.Flag(std::to_string(c.num_unreachable) + " rows unreachable, " + std::to_string(c.num_outside_limits) +
         " outside the joint limits, " + std::to_string(c.num_jumps) + " with a joint jump > 0.5 rad (first: row " +
         std::to_string(c.first_bad_row + 1) + ")");
  return f;
}

nlohmann::json PolishRobotSummaryJson(const std::vector<polishing::PathRow>& rows,
                                      const kinematics::PosePathCheck& c) {
  return {{"rows", rows.size()},
          {"unreachable_rows", c.num_unreachable},
          {"outside_joint_limits_rows", c.num_outside_limits},
          {"joint_jump_rows", c.num_jumps},
          {"first_flagged_row", c.first_bad_row >= 0 ? nlohmann::json(c.first_bad_row + 1) : nlohmann::json(nullptr)},
          {"min_joint_limit_margin_deg", RadToDeg(c.min_limit_margin)},
          {"max_jacobian_condition", c.max_condition}};
}

}  // namespace robomach::workflows
