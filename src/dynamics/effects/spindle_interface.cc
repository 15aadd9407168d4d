// spindle_interface: the tool holder on the contact stiffness of its taper in
// the spindle instead of rigidly fixed to it (the seed's spindle–toolholder
// interface model).
//
// The taper's contact stiffness follows from the drawbar force, the taper
// geometry and Yoshimura's unit-area law, element by element, and is
// condensed (Guyan) onto the holder's gauge line: a 4×4 stiffness on the
// holder's lateral translations and tilts there (dynamics/internal/
// taper_contact.h has the equations and references). Axial translation and
// torsion stay rigid. The end-effector body "holder_and_tool" becomes a body
// of its own on these springs (dynamics/internal/body_on_springs.h), and the
// tool tip moves with it.
//
// The seed's numbers come from the config section
// `spindle_toolholder_interface` (elements, friction_coefficient,
// alpha_prime, beta_prime, tangential_to_normal, drawbar_force_N,
// taper_large_diameter_m, taper_length_m, taper_ratio); a missing key takes
// the HSK-E32 value of config/kr210.yaml. Fittable: separate scale factors on
// the translational and the tilting stiffness, K' = D K D with
// D = diag(√s_t, √s_t, √s_r, √s_r): the diagonal terms scale by s_t and s_r,
// the translation–tilt coupling by √(s_t s_r), and K' stays positive
// definite (a congruence). An HSK face contact, which the taper-only model
// lacks, shows up as s_r > 1.
//
// Magnitudes with the seed's numbers (scales 1): lateral 7.6e7 N/m, tilting
// 9.4e3 N·m/rad about the gauge line (5.0e3 with the lateral DOF free), so
// the holder rocks at ≈ 320 Hz and the static compliance at the tip, 80 mm
// beyond the gauge line, gains ≈ 1.6e-6 m/N across the tool axis: as much as
// the whole robot's. The taper alone is that soft in tilt because its lever arm is
// its 16 mm length and its 12 mm radius; real HSK holders with face contact
// are much stiffer in tilt, so expect a fitted tilting_scale well above 1
// (hence its upper bound 1e4) and treat the default as the seed's taper-only
// model, not a prediction for a given holder.
#include <cmath>
#include <set>
#include <span>
#include <stdexcept>
#include <string>

#include "dynamics/internal/body_on_springs.h"
#include "dynamics/internal/taper_contact.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

class SpindleInterfaceEffect final : public Effect {
 public:
  static constexpr const char* kSection = "spindle_toolholder_interface";
  static constexpr const char* kHolderBody = "holder_and_tool";

  std::string name() const override { return "spindle_interface"; }
  std::string description() const override {
    return "tool holder on the taper contact stiffness of the spindle interface (drawbar "
           "pressure, Yoshimura 1979 unit-area law, Guyan condensation)";
  }
  std::vector<ParameterSpec> parameters() const override {
    return {
        {"translational_scale", "1", 1.0, 0.01, 100.0, true,
         "factor on the interface's lateral (translational) stiffness"},
        {"tilting_scale", "1", 1.0, 0.01, 1e4, true,
         "factor on the interface's tilting stiffness (face contact stiffens it)"},
        // HSK-E32 holders have a bore of about 16 mm behind the taper
        // (assumption of the same order as DIN 69893's HSK-32 drawings).
        {"shank_bore_diameter_m", "m", 0.016, 0.0, 0.02, false,
         "bore of the holder's hollow taper shank"},
        {"shank_modulus_Pa", "Pa", 2.1e11, 1e9, 1e13, false,
         "Young's modulus of the holder shank (steel)"},
        // Contact interfaces of holders show 2–5 % in tap tests of the
        // holder alone (the seed's interface modes are of that order).
        {"damping_ratio", "1", 0.03, 0.001, 0.3, true,
         "damping ratio of the holder's modes on the interface (replaces alpha K there)"},
    };
  }
  EffectStage stage() const override { return EffectStage::kSpindle; }
  int num_extra_dofs(std::span<const double>) const override { return 4; }

  static internal::TaperContactOptions Options(const RobotDescription& d,
                                               std::span<const double> values) {
    internal::TaperContactOptions o;
    const std::string prefix = std::string(kSection) + ".";
    const std::pair<const char*, double*> keys[] = {
        {"friction_coefficient", &o.friction_coefficient},
        {"alpha_prime", &o.alpha_prime},
        {"beta_prime", &o.beta_prime},
        {"tangential_to_normal", &o.tangential_to_normal},
        {"drawbar_force_N", &o.drawbar_force_N},
        {"taper_large_diameter_m", &o.large_diameter_m},
        {"taper_length_m", &o.length_m},
        {"taper_ratio", &o.taper_ratio},
    };
    std::set<std::string> known{"elements"};
    for (const auto& [key, ptr] : keys) known.insert(key);
    for (const auto& [key, value] : d.extra_values) {
      if (key.rfind(prefix, 0) != 0) continue;
      const std::string sub = key.substr(prefix.size());
      if (!known.count(sub)) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        throw std::invalid_argument("spindle_interface: unknown key '" + key + "'; known: " + list);
      }
    }
    for (const auto& [key, ptr] : keys) {
      const auto it = d.extra_values.find(prefix + key);
      if (it != d.extra_values.end()) *ptr = it->second;
    }
    if (const auto it = d.extra_values.find(prefix + "elements"); it != d.extra_values.end()) {
      if (it->second != std::round(it->second)) {
        throw std::invalid_argument(prefix + "elements must be a whole number, got " +
                                    std::to_string(it->second));
      }
      o.elements = static_cast<int>(it->second);
    }
    o.shank_bore_diameter_m = values[2];
    o.shank_modulus_Pa = values[3];
    return o;
  }

  void Contribute(const EffectContext& ctx, std::span<const double> values, int first,
                  AssembledSystem* sys) const override {
    const RobotModel& model = ctx.model;
    const internal::TaperContact tc = internal::ComputeTaperContact(Options(model.description(), values));
    const Eigen::Vector4d D(std::sqrt(values[0]), std::sqrt(values[0]), std::sqrt(values[1]),
                            std::sqrt(values[1]));
    const EndEffectorBody* holder = nullptr;
    for (const auto& b : model.end_effector_bodies()) {
      if (b.name == kHolderBody) holder = &b;
    }
    if (holder == nullptr) {
      throw std::invalid_argument(std::string("spindle_interface: the end effector has no body '") +
                                  kHolderBody + "' to mount on the interface springs");
    }
    // Tip frame (tool0) in B: the TCP frame is the tip frame shifted by p_tcp.
    Eigen::Isometry3d X_B_tip = ctx.X_BT;
    X_B_tip.translation() = ctx.X_BT * (-model.p_tcp());
    internal::SpringMount mount;
    mount.p_BP = ctx.X_BT * model.p_TN();  // gauge line
    mount.R_BS = X_B_tip.linear();         // z along the spindle axis
    mount.components = {0, 1, 3, 4};       // u_x, u_y, θ_x, θ_y
    mount.K_S = D.asDiagonal() * tc.K_master * D.asDiagonal();
    mount.body_B = kinematics::TransformInertial(holder->inertial, X_B_tip);
    mount.carries_tool_tip = true;
    mount.damping_ratio = values[4];
    internal::MountBodyOnSprings(mount, ctx.X_BT.translation(), model.alpha(), first, sys);
  }
};

}  // namespace robomach::dynamics

ROBOMACH_REGISTER_EFFECT(spindle_interface, robomach::dynamics::SpindleInterfaceEffect)
