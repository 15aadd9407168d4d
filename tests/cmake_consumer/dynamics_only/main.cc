// One joint about base z carrying a link (mass m, COM at l_c, I_zz) on a
// torsional spring k: a 1-DOF oscillator, f_n = sqrt(k / (m l_c^2 + I_zz)) / 2 pi.
// Prints the model's natural frequency and the closed form.
#include <cmath>
#include <cstdio>

#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/kinematics/modified_dh.h"

int main() {
  constexpr double m = 8.0, lc = 0.4, l = 0.9, Izz = 0.3, k = 2e4;
  robomach::kinematics::ModifiedDhRow r;
  r.joint_name = "j1";
  r.inertial.mass = m;
  r.inertial.com = Eigen::Vector3d(lc, 0.0, 0.0);
  r.inertial.inertia_com = Eigen::Vector3d(0.05, Izz, Izz).asDiagonal();
  Eigen::Isometry3d X_nT = Eigen::Isometry3d::Identity();
  X_nT.translation() = Eigen::Vector3d(l, 0.0, 0.0);
  robomach::dynamics::RobotDescription d;
  d.arm = robomach::kinematics::BuildModifiedDhChain({r}, Eigen::Isometry3d::Identity(), X_nT);
  d.joint_stiffness = Eigen::VectorXd::Constant(1, k);
  const auto model = robomach::dynamics::RobotModel::Build(d);
  const auto pd = robomach::dynamics::EvaluatePosture(model, Eigen::VectorXd::Constant(1, 0.6));
  std::printf("%.9f %.9f\n", pd.modes[0].freq_hz, std::sqrt(k / (m * lc * lc + Izz)) / (2.0 * M_PI));
  return 0;
}
