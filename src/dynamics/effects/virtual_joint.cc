// virtual_joint_<place>_<axis>: an elastic virtual joint at a named place of
// the chain, the virtual-joint method of robot stiffness modelling
// [Pashkevich 2009; Klimchik 2013]: the compliance of a link, of a gearbox
// housing or of a bearing seat, lumped into one spring about (or along) one
// axis at one place, between rigid links.
//
// Places: `base` (between the floor and joint 1, at the base frame B) and
// `link<j>` (right after joint j, at the origin of link j's frame: the
// frame of the segment that joint j moves, whose origin lies on joint j's
// axis; for the KR210's URDF, the child link of joint_j). A virtual joint at
// link j moves link j and everything beyond it, as joint j does. Axes: `rx`,
// `ry`, `rz` (an elastic rotation about that axis of the place's frame) and
// `tx`, `ty`, `tz` (an elastic translation along it). So
// virtual_joint_link3_rx is "an elastic rotation about link 3's x axis
// between joints 3 and 4". A rotation about a joint's own axis at that
// joint moves the same bodies as the joint: it is the joint's stiffness in
// series (1/k = 1/kq + 1/kv) with a singular mass matrix, and is refused
// with the joint stiffness parameter to fit instead.
//
// One extra DOF θ_v with unit twist at the origin ξ_v = [o × a; a] (rotation
// about the unit axis a through o) or [a; 0] (translation along a). By the
// composite-rigid-body algorithm [Featherstone 2008, §6.2] generalised to
// any joint of a tree, the mass-matrix entries between two DOFs are
// ξ_xᵀ Φ^C ξ_y with Φ^C the composite spatial inertia of the bodies both
// move (dynamics/internal/composite_inertia.h):
//   M_vv = ξ_vᵀ Φ_v ξ_v,                       Φ_v = Φ^C after the place;
//   M_vk = ξ_vᵀ Φ_v ξ_k        for a joint k before the place (it moves all of Φ_v),
//   M_vk = ξ_vᵀ Φ_k^C ξ_k      for a joint k after it,
//   M_vx = ξ_vᵀ Φ_v ξ_x        for an extra DOF x applied earlier (the base on its
//                              foundation, a virtual joint nearer the floor: each moves
//                              every body the virtual joint moves, rigidly; ξ_x is its
//                              column of V_T shifted from T to the origin).
// Virtual joints are applied from the floor outwards (stage kArm, ordered by
// place), so every earlier extra DOF is one of those. K_vv = k_v; the damping
// is the model's Rayleigh α K + β M. The tool tip moves by ξ_v shifted to T:
// V_T gains [a × (p_T − o); a] (rotation) or [a; 0], B its top rows.
//
// Defaults: 2e7 N·m/rad (about 5 times the KR210's main joints, so a
// default virtual joint adds 10-20 % to the compliance of the joint it sits
// next to, the share link and housing compliance has in stiffness
// identifications of heavy robots [Klimchik 2013]) and 2e8 N/m. Engineering
// assumptions, not measurements.
//
// - [Pashkevich 2009] A. Pashkevich, D. Chablat, P. Wenger, "Stiffness
//   analysis of overconstrained parallel manipulators", Mechanism and
//   Machine Theory 44 (2009) 966-982 (the virtual joint method, VJM).
// - [Klimchik 2013] A. Klimchik, A. Pashkevich, D. Chablat, "CAD-based
//   approach for identification of elasto-static parameters of robotic
//   manipulators", Finite Elements in Analysis and Design 75 (2013) 19-30.
// - [Featherstone 2008] R. Featherstone, Rigid Body Dynamics Algorithms,
//   Springer, 2008.
#include <algorithm>
#include <charconv>
#include <span>
#include <stdexcept>
#include <string>

#include "dynamics/internal/body_on_springs.h"
#include "dynamics/internal/composite_inertia.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

class VirtualJointEffect final : public Effect {
 public:
  /// place 0: the base; j >= 1: right after joint j. axis 0-2: rotation about
  /// x, y, z; 3-5: translation along x, y, z.
  VirtualJointEffect(int place, int axis) : place_(place), axis_(axis) {}

  std::string name() const override {
    static const char* kAxes[] = {"rx", "ry", "rz", "tx", "ty", "tz"};
    return "virtual_joint_" + (place_ == 0 ? std::string("base") : "link" + std::to_string(place_)) + "_" +
           kAxes[axis_];
  }
  std::string description() const override {
    static const char* kXyz[] = {"x", "y", "z"};
    const std::string what = rotation() ? "an elastic rotation about " : "an elastic translation along ";
    if (place_ == 0) return what + "the base frame's " + kXyz[axis_ % 3] + " axis, between the floor and joint 1";
    return what + "link " + std::to_string(place_) + "'s " + kXyz[axis_ % 3] + " axis, right after joint " +
           std::to_string(place_);
  }
  std::vector<ParameterSpec> parameters() const override {
    if (rotation()) {
      return {{"stiffness_Nm_per_rad", "N·m/rad", 2e7, 1e3, 1e11, true, "stiffness of the virtual joint"}};
    }
    return {{"stiffness_N_per_m", "N/m", 2e8, 1e5, 1e12, true, "stiffness of the virtual joint"}};
  }
  EffectStage stage() const override { return EffectStage::kArm; }
  int stage_order() const override { return place_; }
  int num_extra_dofs(std::span<const double>) const override { return 1; }
  void CheckApplicable(const RobotDescription& d) const override {
    const int num_joints = d.arm.num_joints();
    if (place_ > num_joints) {
      throw std::invalid_argument("effect '" + name() + "': the robot has " + std::to_string(num_joints) +
                                  " joints, so the places are base and link1..link" + std::to_string(num_joints));
    }
    // A rotation about the line of the joint at the place (joint 1 for the
    // base) moves the same bodies as that joint: the joint's spring in
    // series, and a singular mass matrix. The line of a joint is fixed in
    // the frame of the place, so q = 0 decides for every posture.
    if (!rotation() || num_joints == 0) return;
    const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(num_joints);
    const internal::CompositeInertia ci = internal::ComputeCompositeInertia(d.arm.kdl(), q0);
    const int joint = std::max(place_, 1) - 1;
    const Vector6d xi = Twist(PlaceFrame(d.arm, q0)).normalized();
    const Vector6d xj = ci.joint_twist[joint].normalized();
    if ((xi - xj).norm() < 1e-9 || (xi + xj).norm() < 1e-9) {
      const std::string kq = "kq" + std::to_string(joint + 1) + "_Nm_per_rad";
      throw std::invalid_argument("effect '" + name() + "' turns about joint " + std::to_string(joint + 1) +
                                  "'s own axis: it is that joint's stiffness in series; free " + kq +
                                  " instead (frf-calibrate --free " + kq + ")");
    }
  }

  void Contribute(const EffectContext& ctx, std::span<const double> v, int first,
                  AssembledSystem* sys) const override {
    const RobotModel& model = ctx.model;
    const KDL::Chain& chain = model.chain().kdl();
    const int n = model.num_joints();
    const internal::CompositeInertia ci = internal::ComputeCompositeInertia(chain, ctx.q);
    const Vector6d xi = Twist(PlaceFrame(model.chain(), ctx.q));
    const Matrix6d& Phi = place_ == 0 ? ci.total : ci.composite[place_ - 1];
    const Vector6d Phi_xi = Phi * xi;
    sys->M(first, first) += xi.dot(Phi_xi);
    for (int k = 0; k < n; ++k) {
      // Joint k (0-based) is joint k + 1: before the place if k + 1 <= place_.
      const double c = k + 1 <= place_ ? Phi_xi.dot(ci.joint_twist[k])
                                        : xi.dot(ci.composite[k] * ci.joint_twist[k]);
      sys->M(first, k) += c;
      sys->M(k, first) += c;
    }
    const Matrix6d to_origin = internal::ShiftTwist(-ctx.X_BT.translation());
    for (int x = n; x < first; ++x) {
      const double c = Phi_xi.dot(to_origin * sys->V_T.col(x));
      sys->M(first, x) += c;
      sys->M(x, first) += c;
    }
    sys->K(first, first) += v[0];
    sys->V_T.col(first) = internal::ShiftTwist(ctx.X_BT.translation()) * xi;
    sys->B.col(first) = sys->V_T.col(first).head<3>();
  }

 private:
  bool rotation() const { return axis_ < 3; }
  // The frame of the place: B, or the tip frame of the segment joint
  // `place_` moves (link `place_`'s frame, its origin on the joint's axis).
  Eigen::Isometry3d PlaceFrame(const kinematics::SerialChain& chain, const Eigen::VectorXd& q) const {
    if (place_ == 0) return Eigen::Isometry3d::Identity();
    int seen = 0;
    for (int s = 0; s < chain.num_segments(); ++s) {
      if (chain.kdl().getSegment(s).getJoint().getType() != KDL::Joint::None && ++seen == place_) {
        return kinematics::SegmentPose(chain, q, s);
      }
    }
    throw std::logic_error("virtual joint place beyond the chain");  // CheckApplicable refuses it first
  }
  // The unit twist at the origin of B: [o × a; a] or [a; 0].
  Vector6d Twist(const Eigen::Isometry3d& X) const {
    const Eigen::Vector3d a = X.linear().col(axis_ % 3);
    Vector6d xi;
    if (rotation()) {
      xi << X.translation().cross(a), a;
    } else {
      xi << a, Eigen::Vector3d::Zero();
    }
    return xi;
  }
  int place_;
  int axis_;
};

/// The effect of `name` if it is virtual_joint_<place>_<axis>, else nullptr.
std::shared_ptr<const Effect> ParseVirtualJoint(std::string_view name) {
  constexpr std::string_view kPrefix = "virtual_joint_";
  if (name.substr(0, kPrefix.size()) != kPrefix) return nullptr;
  std::string_view rest = name.substr(kPrefix.size());
  const size_t us = rest.rfind('_');
  if (us == std::string_view::npos) return nullptr;
  const std::string_view place = rest.substr(0, us), axis = rest.substr(us + 1);
  static constexpr std::string_view kAxes[] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  int a = -1;
  for (int i = 0; i < 6; ++i) {
    if (axis == kAxes[i]) a = i;
  }
  if (a < 0) return nullptr;
  int p = -1;
  if (place == "base") {
    p = 0;
  } else if (place.substr(0, 4) == "link" && place.size() > 4) {
    const std::string_view digits = place.substr(4);
    int j = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), j);
    if (ec == std::errc() && end == digits.data() + digits.size() && j >= 1 && j <= 99 && digits[0] != '0') p = j;
  }
  if (p < 0) return nullptr;
  return std::make_shared<const VirtualJointEffect>(p, a);
}

}  // namespace robomach::dynamics

void RobomachRegisterEffect_virtual_joint(::robomach::dynamics::EffectRegistry& r) {
  r.RegisterFamily("virtual_joint_<place>_<axis> (place: base, link1..linkN; axis: rx, ry, rz, tx, ty, tz)",
                   robomach::dynamics::ParseVirtualJoint);
}
