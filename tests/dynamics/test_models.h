#pragma once

#include <memory>
#include <random>

#include <Eigen/Geometry>

#include "robomach/common/units.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/kinematics/modified_dh.h"
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

// One link on a horizontal joint: DH frame 0 is turned +90° about base x,
// so the joint axis is −y_B and the COM at (l_c, 0, 0) of the link is at
// (l_c cos q, 0, l_c sin q) in B (z up). V = m g l_c sin q, so the gravity
// torque is G = ∂V/∂q = m g l_c cos q and ∂²V/∂q² = −m g l_c sin q:
// +m g l_c hanging down (q = −π/2), −m g l_c upright.
inline dynamics::RobotDescription Pendulum(double m, double lc) {
  kinematics::ModifiedDhRow r;
  r.joint_name = "j1";
  r.inertial.mass = m;
  r.inertial.com = Eigen::Vector3d(lc, 0.0, 0.0);
  r.inertial.inertia_com = Eigen::Vector3d(0.01, 0.02, 0.02).asDiagonal();
  Eigen::Isometry3d X_B0 = Eigen::Isometry3d::Identity();
  X_B0.linear() = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Isometry3d X_nT = Eigen::Isometry3d::Identity();
  X_nT.translation() = Eigen::Vector3d(2 * lc, 0.0, 0.0);
  dynamics::RobotDescription d;
  d.arm = kinematics::BuildModifiedDhChain({r}, X_B0, X_nT);
  d.joint_stiffness = Eigen::VectorXd::Constant(1, 1e5);
  d.end_effector.p_tcp = Eigen::Vector3d::Zero();
  return d;
}

}  // namespace robomach::testing
