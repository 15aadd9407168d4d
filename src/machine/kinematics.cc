#include "robomach/machine/kinematics.h"

#include <cmath>
#include <limits>

#include "robomach/common/units.h"

namespace robomach::machine {

InverseResult MachineKinematics::Inverse(const ToolPose& pose, const Eigen::VectorXd& q_previous) const {
  InverseResult r;
  const std::vector<Eigen::VectorXd> sols = InverseSolutions(pose, q_previous);
  if (sols.empty()) {
    r.status = InverseStatus::kUnreachableAxis;
    r.message = "the tool axis cannot be reached by the rotary axes";
    return r;
  }
  const std::vector<bool> rot = rotary();
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::VectorXd q : sols) {
    // Unwrap each rotary axis by whole turns towards the previous sample.
    for (int a = 0; a < q.size(); ++a) {
      if (rot[a]) q(a) += 2.0 * kPi * std::round((q_previous(a) - q(a)) / (2.0 * kPi));
    }
    // Distance in rotary axes decides (the linear ones follow from them).
    double d = 0.0;
    for (int a = 0; a < q.size(); ++a) {
      if (rot[a]) d += (q(a) - q_previous(a)) * (q(a) - q_previous(a));
    }
    if (d < best) {
      best = d;
      r.q = q;
    }
  }
  return r;
}

}  // namespace robomach::machine
