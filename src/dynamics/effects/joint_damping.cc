// joint_damping: viscous damping at the joints, C_extra += diag(c_1 … c_n),
// which is neither proportional to M nor to K (gearbox and motor losses act
// at each joint; their ratio to the joint's stiffness differs from joint to
// joint). With it the system is non-proportionally damped and the modes are
// complex [Ewins 2000, §2.4]; the FRF is exact by the direct solve or the
// state-space modes (tool_tip_frf.h).
//
// Defaults: c_j = 2 ζ √(k_j I_j) with ζ = 3 %, k_j the seed's joint
// stiffness and I_j = M_q(j, j) of the default robot at the demo posture P1
// (0, −90°, 90°, 0, 45°, 0): each joint alone, the others held, would
// have 3 % damping. That gives 1.3–2.8e3 N·m·s/rad for the main axes and
// 7–80 for the wrist (c_j/k_j from 5e-4 s down to 4e-5 s, so clearly not
// proportional to K_q), the order reported for joint damping of heavy
// industrial robots. They add to the Rayleigh damping of the base model;
// fit them with alpha and beta held.
//
// - [Ewins 2000] D. J. Ewins, Modal Testing: Theory, Practice and
//   Application, 2nd ed., Research Studies Press, 2000.
#include <span>
#include <stdexcept>
#include <string>

#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

class JointDampingEffect final : public Effect {
 public:
  // One parameter per joint of a six-axis arm; a robot with fewer joints
  // uses the first n, more joints are an error at evaluation.
  static constexpr int kMaxJoints = 6;
  std::string name() const override { return "joint_damping"; }
  std::string description() const override {
    return "viscous damping at each joint, not proportional to M or K (Ewins 2000, §2.4)";
  }
  std::vector<ParameterSpec> parameters() const override {
    // 2 · 0.03 · √(k_j M_q(j, j)) at P1, rounded (see the header comment).
    const double c[kMaxJoints] = {1700.0, 2800.0, 1300.0, 40.0, 80.0, 7.0};
    std::vector<ParameterSpec> p;
    for (int j = 0; j < kMaxJoints; ++j) {
      const std::string i = std::to_string(j + 1);
      p.push_back({"c" + i + "_Nms_per_rad", "N·m·s/rad", c[j], 0.0, 1e6, true,
                   "viscous damping of joint " + i});
    }
    return p;
  }
  void Contribute(const EffectContext& ctx, std::span<const double> values, int,
                  AssembledSystem* sys) const override {
    const int n = ctx.model.num_joints();
    if (n > kMaxJoints) {
      throw std::invalid_argument("joint_damping has parameters for " + std::to_string(kMaxJoints) +
                                  " joints; the robot has " + std::to_string(n));
    }
    for (int j = 0; j < n; ++j) sys->C_extra(j, j) += values[j];
  }
};

}  // namespace robomach::dynamics

ROBOMACH_REGISTER_EFFECT(joint_damping, robomach::dynamics::JointDampingEffect)
