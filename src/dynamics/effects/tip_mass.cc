// tip_mass: a point mass at the tool tip, as an accelerometer adds in a
// hammer test. Its kinetic energy ½ m |x_T'|² = ½ z'ᵀ (m Bᵀ B) z' adds
//   ΔM = m Bᵀ B
// to the assembled mass matrix, B the tool-tip translation map (J_v without
// other effects) [Ewins 2000, §3.6 on mass loading by transducers].
#include <span>

#include "robomach/dynamics/effect.h"

namespace robomach::dynamics {

class TipMassEffect final : public Effect {
 public:
  std::string name() const override { return "tip_mass"; }
  std::string description() const override {
    return "point mass at the tool tip (accelerometer mass loading)";
  }
  std::vector<ParameterSpec> parameters() const override {
    return {{"mass_kg", "kg", 0.01, 0.0, 5.0, true, "mass at the tool tip"}};
  }
  // After every flexibility between the floor and the tool tip, so that the
  // mass moves with all of them (B includes their columns then).
  EffectStage stage() const override { return EffectStage::kToolTip; }
  void Contribute(const EffectContext&, std::span<const double> values, int,
                  AssembledSystem* sys) const override {
    sys->M += values[0] * sys->B.transpose() * sys->B;
  }
};

}  // namespace robomach::dynamics

ROBOMACH_REGISTER_EFFECT(tip_mass, robomach::dynamics::TipMassEffect)
