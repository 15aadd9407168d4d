#include "robomach/identification/load_case.h"

#include <sstream>
#include <stdexcept>

#include "robomach/common/units.h"

namespace robomach::identification {

Eigen::Vector3d RopeForce(double mass_kg, const Eigen::Vector3d& p_A, const Eigen::Vector3d& p_B) {
  if (!std::isfinite(mass_kg) || !p_A.allFinite() || !p_B.allFinite()) {
    throw std::invalid_argument("RopeForce: non-finite mass or rope point");
  }
  if (mass_kg < 0.0) {
    std::ostringstream s;
    s << "RopeForce: expected a mass >= 0 kg, got " << mass_kg;
    throw std::invalid_argument(s.str());
  }
  const Eigen::Vector3d AB = p_B - p_A;
  // 1e-9 m is far below any tracker resolution (~1e-6 m): below it the
  // direction is numerically meaningless, not merely inaccurate.
  if (AB.norm() < 1e-9) {
    throw std::invalid_argument(
        "RopeForce: rope points A and B coincide, so the rope direction is undefined");
  }
  return mass_kg * kStandardGravity * AB.normalized();
}

LoadCase ToLoadCase(const TrackerMeasurement& m) {
  LoadCase c;
  c.case_id = m.case_id;
  c.pose_id = m.pose_id;
  c.q = m.q;
  c.force = m.force ? *m.force : RopeForce(m.mass_kg, m.rope_A, m.rope_B);
  c.displacement = m.p1 - m.p0;
  c.p_load_tip = m.p_load_tip;
  c.p_target_tip = m.p_target_tip;
  c.line = m.line;
  return c;
}

std::vector<LoadCase> ToLoadCases(const std::vector<TrackerMeasurement>& m) {
  std::vector<LoadCase> out;
  out.reserve(m.size());
  for (const auto& x : m) out.push_back(ToLoadCase(x));
  return out;
}

}  // namespace robomach::identification
