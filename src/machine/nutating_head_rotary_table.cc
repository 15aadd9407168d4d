#include "robomach/machine/nutating_head_rotary_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "robomach/common/units.h"

namespace robomach::machine {
namespace {

// Rodrigues' rotation of v about the unit axis u by angle a (right-handed).
Eigen::Vector3d Rotate(const Eigen::Vector3d& u, double a, const Eigen::Vector3d& v) {
  const double c = std::cos(a), s = std::sin(a);
  return c * v + s * u.cross(v) + (1.0 - c) * u.dot(v) * u;
}

Eigen::Vector3d RotZ(double a, const Eigen::Vector3d& v) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()};
}

}  // namespace

void CheckValid(const NutatingHeadGeometry& g) {
  if (!(g.nutation > 0.0 && g.nutation <= 0.5 * kPi)) {
    throw std::invalid_argument("NutatingHeadGeometry::nutation: expected an angle in (0, 90] deg, got " +
                                std::to_string(RadToDeg(g.nutation)) + " deg");
  }
  const double all[] = {g.pivot_length, g.tool_length, g.c_centre[0], g.c_centre[1], g.zero_offset[0],
                        g.zero_offset[1], g.zero_offset[2], g.b_eccentricity[0], g.b_eccentricity[1],
                        g.pivot_length_error, g.c_eccentricity[0], g.c_eccentricity[1]};
  for (double v : all) {
    if (!std::isfinite(v)) throw std::invalid_argument("NutatingHeadGeometry: every length must be finite");
  }
}

NutatingHeadRotaryTable::NutatingHeadRotaryTable(const NutatingHeadGeometry& geometry) : g_(geometry) {
  CheckValid(g_);
  u_B_ = Eigen::Vector3d(0.0, std::sin(g_.nutation), std::cos(g_.nutation));
}

ToolPose NutatingHeadRotaryTable::Forward(const Eigen::VectorXd& q) const {
  const double B = q(3), C = q(4);
  const double L = g_.pivot_length, t1 = g_.tool_length, dL = g_.pivot_length_error;
  // Tool tip and axis in machine coordinates [formats.md §8.3; seed eqs. (6), (7), (11)].
  const Eigen::Vector3d p_m = Eigen::Vector3d(q(0), q(1), q(2)) +
                              Eigen::Vector3d(g_.b_eccentricity[0], g_.b_eccentricity[1], L + t1) +
                              Rotate(u_B_, B, Eigen::Vector3d(0.0, 0.0, -(L + dL + t1)));
  const Eigen::Vector3d k_m = Rotate(u_B_, B, Eigen::Vector3d::UnitZ());
  // Into the workpiece through the C table [seed eqs. (8), (9), (12)].
  const Eigen::Vector3d c(g_.c_centre[0] + g_.c_eccentricity[0], g_.c_centre[1] + g_.c_eccentricity[1], 0.0);
  const Eigen::Vector3d o(g_.zero_offset[0], g_.zero_offset[1], g_.zero_offset[2]);
  ToolPose pose;
  pose.p_W = RotZ(-C, p_m - c) + c - o;
  pose.k_W = RotZ(-C, k_m);
  return pose;
}

std::vector<Eigen::VectorXd> NutatingHeadRotaryTable::InverseSolutions(const ToolPose& pose,
                                                                        const Eigen::VectorXd& q_previous) const {
  std::vector<Eigen::VectorXd> out;
  const Eigen::Vector3d k = pose.k_W.normalized();
  const double sn = std::sin(g_.nutation), cn = std::cos(g_.nutation);
  // k_m = R(u_B, B) e_z = (sn sin B, cn sn (1 - cos B), cn^2 + sn^2 cos B); a
  // turn about Z keeps the z component, so cos B = (k_z - cn^2) / sn^2.
  double cos_b = (k.z() - cn * cn) / (sn * sn);
  // The tool axis's z is known to a few ulps only: allow that much outside [-1, 1].
  constexpr double kSlack = 1e-12;
  if (cos_b > 1.0 + kSlack || cos_b < -1.0 - kSlack) return out;
  cos_b = std::clamp(cos_b, -1.0, 1.0);
  const double b_abs = std::acos(cos_b);
  const Eigen::Vector3d c(g_.c_centre[0] + g_.c_eccentricity[0], g_.c_centre[1] + g_.c_eccentricity[1], 0.0);
  const Eigen::Vector3d o(g_.zero_offset[0], g_.zero_offset[1], g_.zero_offset[2]);
  const double L = g_.pivot_length, t1 = g_.tool_length, dL = g_.pivot_length_error;
  for (double B : {b_abs, -b_abs}) {
    const Eigen::Vector3d k_m = Rotate(u_B_, B, Eigen::Vector3d::UnitZ());
    const double r_m = std::hypot(k_m.x(), k_m.y()), r_w = std::hypot(k.x(), k.y());
    double C;
    if (r_m < 1e-12 || r_w < 1e-12) {
      C = q_previous(4);  // tool axis along Z: C is free, keep it
    } else {
      // k_m = Rz(C) k_W in the xy plane.
      C = std::atan2(k_m.y(), k_m.x()) - std::atan2(k.y(), k.x());
      C = std::remainder(C, 2.0 * kPi);
    }
    const Eigen::Vector3d p_m = RotZ(C, pose.p_W + o - c) + c;
    const Eigen::Vector3d xyz = p_m - Eigen::Vector3d(g_.b_eccentricity[0], g_.b_eccentricity[1], L + t1) -
                                Rotate(u_B_, B, Eigen::Vector3d(0.0, 0.0, -(L + dL + t1)));
    Eigen::VectorXd q(5);
    q << xyz, B, C;
    out.push_back(q);
    if (b_abs == 0.0) break;  // one solution only
  }
  return out;
}

std::unique_ptr<MachineKinematics> NutatingHeadRotaryTable::WithoutErrors() const {
  NutatingHeadGeometry g = g_;
  g.b_eccentricity = {0.0, 0.0};
  g.pivot_length_error = 0.0;
  g.c_eccentricity = {0.0, 0.0};
  return std::make_unique<NutatingHeadRotaryTable>(g);
}

}  // namespace robomach::machine
