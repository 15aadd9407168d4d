#include "robomach/workflows/robot_config.h"

#include <utility>

#include "robomach/dynamics/joint_plausibility.h"

namespace robomach::workflows {

io::RobotConfig LoadRobotConfigChecked(const std::string& path) {
  io::RobotConfig cfg = io::LoadRobotConfig(path);
  for (std::string& f : dynamics::JointPlausibilityFindings(cfg.description, cfg.parameters, cfg.joint_value_locations)) {
    cfg.implausible.push_back(std::move(f));
  }
  return cfg;
}

}  // namespace robomach::workflows
