#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include <Eigen/Cholesky>

#include "robomach/common/units.h"
#include "robomach/drilling/drilling_sim.h"
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

/// Q235 steel's shear stresses and Kienzle exponent, rounded (config/drilling/q235.yaml).
inline DrillingMaterial Q235Like() {
  DrillingMaterial m;
  m.shear_stress_thrust = 930e6;
  m.shear_stress_torque = 600e6;
  m.kienzle_exponent = 0.24;
  return m;
}

/// The seed's process at SeedPosture, `duration` [s] long.
inline DrillingProcess SeedProcess(double duration) {
  DrillingProcess p;
  p.initial_posture = SeedPosture();
  p.duration = duration;
  return p;
}

/// Largest difference between the link accelerations of Derivative() (its
/// own composite-rigid-body / Newton-Euler pass) and those from KDL's
/// solvers (LinkTerms: ChainDynParam's M, C q' and G), relative to the
/// largest KDL acceleration, over `trials` random states with springs
/// stretched, links and rotors moving, random motor and external torques.
inline double DerivativeVsKdl(FlexibleJointRobot& robot, int trials, unsigned seed) {
  const int n = robot.num_joints();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto rand = [&](double scale) {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v(i) = scale * u(rng);
    return v;
  };
  double worst = 0.0;
  for (int t = 0; t < trials; ++t) {
    FlexibleJointState x;
    x.q = rand(kPi);
    x.qd = rand(3.0);
    x.theta = robot.gear_ratio().cwiseProduct(x.q + rand(1e-3));
    x.thetad = robot.gear_ratio().cwiseProduct(x.qd + rand(0.1));
    const Eigen::VectorXd tau_m = rand(5.0), tau_ext = rand(50.0);
    FlexibleJointState dx;
    robot.Derivative(x, tau_m, tau_ext, &dx);
    Eigen::MatrixXd M;
    Eigen::VectorXd c, g;
    robot.LinkTerms(x.q, x.qd, &M, &c, &g);
    const Eigen::VectorXd tau =
        robot.stiffness().cwiseProduct(x.theta.cwiseQuotient(robot.gear_ratio()) - x.q) +
        robot.damping().cwiseProduct(x.thetad.cwiseQuotient(robot.gear_ratio()) - x.qd);
    const Eigen::VectorXd qdd = M.llt().solve(tau + tau_ext - c - g);
    worst = std::max(worst, (dx.qd - qdd).cwiseAbs().maxCoeff() / qdd.cwiseAbs().maxCoeff());
  }
  return worst;
}

}  // namespace robomach::drilling::testing
