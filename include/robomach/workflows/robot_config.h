#pragma once
// A robot config as every tool reads it (issue #36): the file
// (io::LoadRobotConfig, formats only) and the model's sense checks.

#include <string>

#include "robomach/io/robot_config.h"

namespace robomach::workflows {

/// io::LoadRobotConfig, then the joints' plausibility of the config's model
/// (dynamics::JointPlausibilityFindings: joint frequencies, sag under the
/// robot's own weight, damping ratio) appended to `implausible`, after the
/// reader's own findings: the warnings every tool and Python give for a
/// robot config, in that order.
/// @throws InputError from the reader.
io::RobotConfig LoadRobotConfigChecked(const std::string& path);

}  // namespace robomach::workflows
