// Example: from a robot config to a chatter-free depth of cut.
//
// The posture-dependent dynamics of a milling robot in four steps:
//   1. load a robot config (kinematics, joint stiffness, damping, end effector)
//      and build the immutable model;
//   2. evaluate one posture: Jacobian, mass and stiffness matrices, modes;
//   3. the tool-tip receptance H_T(f) [m/N] from those modes;
//   4. the regenerative stability lobes of a cut at that posture (zero-order
//      approximation, Altintas & Budak 1995) and their lowest point: below
//      that axial depth the cut does not chatter at any spindle speed.
//
// Usage: predict_posture_and_lobes [robot.yaml [cut.yaml]]
// (defaults: config/kr210.yaml and config/cut_demo.yaml of the source tree).
// The stability-lobes tool does the same for many postures, with plots and
// the semi-discretization as a second method (docs/stability.md).
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/units.h"
#include "robomach/dynamics/joint_plausibility.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/stability/tip_dynamics.h"
#include "robomach/stability/zoa_lobes.h"

namespace rm = robomach;

int main(int argc, char** argv) try {
  const std::string robot_path = argc > 1 ? argv[1] : ROBOMACH_SOURCE_DIR "/config/kr210.yaml";
  const std::string cut_path = argc > 2 ? argv[2] : ROBOMACH_SOURCE_DIR "/config/cut_demo.yaml";

  // 1. The config file speaks the user's units (mm, deg, rpm in the key
  // names); the library sees SI and radians only. LoadRobotConfig checks
  // every key (file:line:col errors) and lists values that look like unit
  // mistakes in `implausible` instead of refusing them. The model's own
  // sense checks (joint frequencies, sag under the robot's weight, damping
  // ratio) are dynamics::JointPlausibilityFindings; the tools read a config
  // with both (workflows::LoadRobotConfigChecked).
  const rm::io::RobotConfig config = rm::io::LoadRobotConfig(robot_path);
  for (const std::string& w : config.implausible) std::printf("warning: %s\n", w.c_str());
  for (const std::string& w :
       rm::dynamics::JointPlausibilityFindings(config.description, config.parameters, config.joint_value_locations)) {
    std::printf("warning: %s\n", w.c_str());
  }
  // The model is immutable and shared (std::shared_ptr<const RobotModel>);
  // everything that depends on the posture lives in PostureDynamics.
  const auto model = config.Build();

  // 2. One posture, q in radians: posture P1 of config/postures_demo.csv.
  const double q_deg[6] = {0, -90, 90, 0, 45, 0};
  Eigen::VectorXd q(6);
  for (int j = 0; j < 6; ++j) q(j) = rm::DegToRad(q_deg[j]);
  // An evaluator keeps buffers for loops over many postures; one per thread.
  rm::dynamics::PostureEvaluator evaluator(model);
  const rm::dynamics::PostureDynamics d = evaluator.Evaluate(q);
  std::printf("posture P1: Jacobian condition %.1f, %zu modes\n", d.jacobian_condition, d.modes.size());
  std::printf("  mode  freq [Hz]  damping [%%]  modal mass [kg]  tip direction (B)\n");
  for (std::size_t k = 0; k < d.modes.size(); ++k) {
    const rm::dynamics::Mode& m = d.modes[k];
    std::printf("  %4zu  %9.2f  %11.2f  %15.3g  (%+.2f %+.2f %+.2f)\n", k + 1, m.freq_hz, 100.0 * m.damping_ratio,
                m.modal_mass_kg, m.shape_T.x(), m.shape_T.y(), m.shape_T.z());
  }

  // 3. The tool-tip receptance: one 3x3 complex matrix per line, in the
  // base frame B. Receptance() sums the modes (or uses complex modes when
  // the damping is not proportional).
  const Eigen::VectorXd freq_hz = Eigen::VectorXd::LinSpaced(2000, 0.25, 500.0);
  const std::vector<Eigen::Matrix3cd> H = rm::dynamics::Receptance(d, freq_hz);
  for (int axis = 0; axis < 2; ++axis) {
    int peak = 0;
    for (int i = 1; i < freq_hz.size(); ++i) {
      if (std::abs(H[i](axis, axis)) > std::abs(H[peak](axis, axis))) peak = i;
    }
    std::printf("|H%c%c| peaks at %.2f Hz: %.3g m/N (static compliance %.3g m/N)\n", "xy"[axis], "xy"[axis],
                freq_hz(peak), std::abs(H[peak](axis, axis)), d.static_compliance(axis, axis));
  }

  // 4. The cut: tool, immersion, cutting coefficients and speed range.
  const rm::io::CutSpec cut = rm::io::ReadCutFile(cut_path);
  // The tool tip in the cutting frame C (x along the feed, z along the tool
  // axis): the 2x2 oriented FRF Phi_C on a fine log grid that reaches the
  // chatter frequencies of the fastest speed.
  const rm::stability::TipDynamics tip = rm::stability::TipFromPosture(
      "P1", d, cut.feed_direction_B, cut.process.teeth, cut.spindle_speed_max_rad_s);
  rm::stability::ZoaOptions zoa;
  zoa.min_spindle_speed_rad_s = cut.spindle_speed_min_rad_s;  // skip lobes that cannot reach the range
  const rm::stability::ZoaLobes lobes = rm::stability::ComputeZoaLobes(tip.freq_hz, tip.Phi_C, cut.process, zoa);
  // The lowest boundary over all lobes, sampled at the cut's speeds.
  // stability::ComputeLobes (lobes_workflow.h) wraps this for many tips,
  // adds the semi-discretization and its checks, and SummarizeLobes finds
  // the extremes: what the stability-lobes tool calls.
  const std::vector<rm::stability::LobePoint> points = lobes.At(cut.SpeedGrid());
  const rm::stability::LobePoint* lowest = nullptr;
  for (const rm::stability::LobePoint& p : points) {
    if (p.status != rm::stability::LobeStatus::kOk) continue;  // no lobe reaches this speed
    if (!lowest || p.critical_depth < lowest->critical_depth) lowest = &p;
  }
  if (!lowest) {
    std::printf("no stability boundary in the speed range\n");
    return 1;
  }
  const double rpm = rm::RadPerSecToRpm(lowest->spindle_speed_rad_s);
  std::printf("%d-tooth cutter, a_e/D = %.2f, %zu speeds from %.0f to %.0f rpm\n", cut.process.teeth,
              cut.process.radial_immersion, points.size(), rm::RadPerSecToRpm(cut.spindle_speed_min_rad_s),
              rm::RadPerSecToRpm(cut.spindle_speed_max_rad_s));
  std::printf("smallest critical depth: %.3f mm at %.0f rpm (chatter at %.1f Hz, lobe %d)\n",
              1e3 * lowest->critical_depth, rpm, lowest->chatter_freq_hz, lowest->lobe_index);
  return 0;
} catch (const std::exception& e) {
  // Bad input is an exception whose message says where (file:line:col).
  std::fprintf(stderr, "predict_posture_and_lobes: %s\n", e.what());
  return 1;
}
