// load_stiffness_j<j>: a joint stiffness that varies with the gravity load
// on the joint (issue #33 scope 3), a posture-dependent joint stiffness.
//
// A gear train's stiffness grows with the torque it transmits (the tooth
// contacts and the bearing preload stiffen: a hardening spring), and a
// counterbalance on joint 2 changes the load the gear carries from one
// posture to another; both make the joint's stiffness depend on the static
// torque of the robot's own weight, G_j(q) (dynamics/gravity_torque.h)
// [Dumas, Caro et al. 2011 find the KUKA KR240's kq2 and kq3 posture
// dependent; Alici & Shirinzadeh 2005 on load-dependent stiffness]. The
// first-order form
//     k_j(q) = kq_j (1 + s |G_j(q)| / 1 kN·m)
// with the stiffening s [per kN·m] fitted (the audit frees kq_j with it).
// K(j, j) += kq_j s |G_j(q)| / 1000 N·m; nothing else changes.
//
// Bounds: s from −0.09 (a softening of at most 90 % at 10 kN·m, more than a
// KR210's joint 2 carries, so k_j stays positive) to 2 per kN·m (a factor
// of 3 per kN·m). Default 0.1 per kN·m (10 % per kN·m). Engineering
// assumptions, not measurements.
//
// - [Alici & Shirinzadeh 2005] G. Alici, B. Shirinzadeh, Enhanced stiffness
//   modeling, identification and characterization for robot manipulators,
//   IEEE Trans. Robotics 21(4):554–564, 2005.
// - [Dumas, Caro et al. 2011] C. Dumas, S. Caro, S. Garnier, B. Furet, Joint
//   stiffness identification of six-revolute industrial serial robots,
//   Robotics and Computer-Integrated Manufacturing 27(4):881–888, 2011.
#include <charconv>
#include <cmath>
#include <span>
#include <stdexcept>
#include <string>

#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/gravity_torque.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

class LoadStiffnessEffect final : public Effect {
 public:
  explicit LoadStiffnessEffect(int joint) : joint_(joint) {}
  std::string name() const override { return "load_stiffness_j" + std::to_string(joint_); }
  std::string description() const override {
    return "joint " + std::to_string(joint_) + "'s stiffness varying with the gravity torque on it, kq" +
           std::to_string(joint_) + " (1 + s |G" + std::to_string(joint_) + "| / kN·m)";
  }
  std::vector<ParameterSpec> parameters() const override {
    return {{"stiffening_per_kNm", "1/(kN·m)", 0.1, -0.09, 2.0, true,
             "relative change of the joint's stiffness per kN·m of gravity torque on it"}};
  }
  void CheckApplicable(const RobotDescription& d) const override {
    if (joint_ > d.arm.num_joints()) {
      throw std::invalid_argument("effect '" + name() + "': the robot has " + std::to_string(d.arm.num_joints()) +
                                  " joints");
    }
  }
  void Contribute(const EffectContext& ctx, std::span<const double> v, int /*first*/,
                  AssembledSystem* sys) const override {
    const int j = joint_ - 1;
    const double g = std::abs(GravityTorque(ctx.model, ctx.q)(j));
    sys->K(j, j) += ctx.model.joint_stiffness()(j) * v[0] * g / 1000.0;
  }

 private:
  int joint_;
};

std::shared_ptr<const Effect> ParseLoadStiffness(std::string_view name) {
  constexpr std::string_view kPrefix = "load_stiffness_j";
  if (name.substr(0, kPrefix.size()) != kPrefix) return nullptr;
  const std::string_view digits = name.substr(kPrefix.size());
  int j = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), j);
  if (ec != std::errc() || end != digits.data() + digits.size() || j < 1 || j > 99 || digits[0] == '0') return nullptr;
  return std::make_shared<const LoadStiffnessEffect>(j);
}

}  // namespace robomach::dynamics

void RobomachRegisterEffect_load_stiffness(::robomach::dynamics::EffectRegistry& r) {
  r.RegisterFamily("load_stiffness_j<joint> (joint: 1..N)", robomach::dynamics::ParseLoadStiffness);
}
