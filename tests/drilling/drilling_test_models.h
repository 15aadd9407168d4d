#pragma once

#include <vector>

#include "robomach/common/units.h"
#include "robomach/drilling/flexible_joint_robot.h"
#include "robomach/kinematics/modified_dh.h"

namespace robomach::drilling::testing {

/// A planar three-joint arm of uniform rods (seed 003 Table 2 masses and
/// lengths, motors left out), tip z along link 3. `vertical`: joint axes
/// horizontal, so gravity acts in the plane of motion (the seed's robot);
/// otherwise the joint axes are vertical and gravity does no work.
inline kinematics::SerialChain PlanarRodArm(bool vertical) {
  const double r = 0.02;
  const double m[3] = {5.0, 3.0, 1.0}, l[3] = {0.6, 0.4, 0.2};
  std::vector<kinematics::ModifiedDhRow> rows(3);
  for (int i = 0; i < 3; ++i) {
    rows[i].joint_name = "joint_" + std::to_string(i + 1);
    rows[i].a_prev = i == 0 ? 0.0 : l[i - 1];
    rows[i].inertial.mass = m[i];
    rows[i].inertial.com = Eigen::Vector3d(0.5 * l[i], 0, 0);
    const double it = m[i] * (3 * r * r + l[i] * l[i]) / 12.0;
    rows[i].inertial.inertia_com = Eigen::Vector3d(0.5 * m[i] * r * r, it, it).asDiagonal();
  }
  Eigen::Isometry3d X_B0 = Eigen::Isometry3d::Identity();
  if (vertical) X_B0.linear() = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Isometry3d X_nT = Eigen::Isometry3d::Identity();
  X_nT.translation() = Eigen::Vector3d(l[2], 0, 0);
  X_nT.linear() = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return kinematics::BuildModifiedDhChain(rows, X_B0, X_nT);
}

inline std::vector<JointDrive> SeedDrives(double damping) {
  return std::vector<JointDrive>(3, JointDrive{60000.0, damping, 1.98e-4, 120.0});
}

inline Eigen::VectorXd SeedPosture() {
  return Eigen::Vector3d(DegToRad(-90.0), DegToRad(90.0), DegToRad(90.0));
}

}  // namespace robomach::drilling::testing
