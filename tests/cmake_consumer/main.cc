// Loads the default robot through the installed package and prints the first
// natural frequency at posture P1 (10.505871 Hz in kr210_reference.yaml).
#include <cstdio>

#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/io/robot_config.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const auto model = robomach::io::LoadRobotConfig(argv[1]).Build();
  Eigen::VectorXd q(6);
  q << 0, robomach::DegToRad(-90), robomach::DegToRad(90), 0, robomach::DegToRad(45), 0;
  const auto d = robomach::dynamics::EvaluatePosture(model, q);
  std::printf("%.6f\n", d.modes[0].freq_hz);
  return 0;
}
