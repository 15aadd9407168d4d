#include "robomach/machine/kinematics_kinds.h"

namespace robomach::machine {

const NamedRegistry<KinematicsFactory>& KinematicsKinds() {
  static const NamedRegistry<KinematicsFactory> registry = [] {
    NamedRegistry<KinematicsFactory> r("unknown kinematics type");
    r.Add("nutating_head_rotary_table", [](const NutatingHeadGeometry& g) -> std::shared_ptr<const MachineKinematics> {
      return std::make_shared<const NutatingHeadRotaryTable>(g);
    });
    return r;
  }();
  return registry;
}

}  // namespace robomach::machine
