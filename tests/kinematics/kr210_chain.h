// The KR 210 R2700-2 arm as a modified-DH chain, shared by the kinematics
// tests.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "robomach/common/units.h"
#include "robomach/kinematics/modified_dh.h"

namespace robomach::kinematics::testing {

// The KR 210 R2700-2 geometry of config/kr210_dh.yaml (Craig's modified DH,
// the base turned 180° about x, tool0 0.215 m beyond the flange).
inline SerialChain Kr210() {
  const double d2r = kPi / 180.0;
  const double rows[6][6] = {{0, 0, -0.645, 0, -185, 185},    {90, 0.33, 0, 0, -140, -5},
                             {0, 1.15, 0, -90, -120, 168},     {90, 0.115, -1.22, 0, -350, 350},
                             {-90, 0, 0, 0, -125, 125},        {90, 0, 0, 0, -350, 350}};
  std::vector<ModifiedDhRow> table;
  for (int i = 0; i < 6; ++i) {
    ModifiedDhRow r;
    r.joint_name = "joint_" + std::to_string(i + 1);
    r.alpha_prev = rows[i][0] * d2r;
    r.a_prev = rows[i][1];
    r.d = rows[i][2];
    r.theta_offset = rows[i][3] * d2r;
    r.limits = {rows[i][4] * d2r, rows[i][5] * d2r, true};
    r.inertial.mass = 10.0;
    r.inertial.inertia_com = Eigen::Matrix3d::Identity();
    table.push_back(r);
  }
  Eigen::Isometry3d X_B0 = Eigen::Isometry3d::Identity();
  X_B0.linear() = Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Isometry3d X_nT = Eigen::Isometry3d::Identity();
  X_nT.translation() = Eigen::Vector3d(0, 0, -0.215);
  X_nT.linear() = Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return BuildModifiedDhChain(table, X_B0, X_nT);
}

}  // namespace robomach::kinematics::testing
