#pragma once

#include <memory>
#include <random>

#include "robomach/dynamics/robot_model.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::testing {

inline std::shared_ptr<const dynamics::RobotModel> Kr210(const std::string& config = "config/kr210.yaml") {
  return io::LoadRobotConfig(SourcePath(config)).Build();
}

inline io::RobotConfig Kr210Config(const std::string& config = "config/kr210.yaml") {
  return io::LoadRobotConfig(SourcePath(config));
}

/// A random posture inside the joint limits, kept 0.2 rad away from the
/// wrist singularity q5 = 0 (seeded; style.md §2.14).
inline Eigen::VectorXd RandomPosture(const dynamics::RobotModel& model, std::mt19937& rng) {
  const auto& lim = model.chain().limits();
  Eigen::VectorXd q(model.num_joints());
  for (int j = 0; j < q.size(); ++j) {
    const double lo = lim[j].bounded ? std::max(lim[j].lower, -3.0) : -3.0;
    const double hi = lim[j].bounded ? std::min(lim[j].upper, 3.0) : 3.0;
    q(j) = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  if (q.size() >= 5 && std::abs(q(4)) < 0.2) q(4) = q(4) < 0 ? -0.2 - q(4) : 0.2 + q(4);
  return q;
}

}  // namespace robomach::testing
