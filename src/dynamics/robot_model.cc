#include "robomach/dynamics/robot_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "robomach/dynamics/effect.h"

namespace robomach::dynamics {
namespace {

using kinematics::Inertial;

struct WristGeometry {
  Eigen::Vector3d p_wc;  // wrist centre (origin of the last joint) in the tip frame
  Eigen::Vector3d axis;  // last joint axis in the tip frame, towards the TCP
};

WristGeometry ComputeWristGeometry(const RobotDescription& d) {
  const kinematics::SerialChain& arm = d.arm;
  const int last = arm.last_moving_segment();
  if (last < 0) throw std::invalid_argument("the robot chain has no movable joint");
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(arm.num_joints());
  const Eigen::Isometry3d X_Bprev =
      last == 0 ? Eigen::Isometry3d::Identity() : kinematics::SegmentPose(arm, q0, last - 1);
  const KDL::Joint& joint = arm.kdl().getSegment(last).getJoint();
  const KDL::Vector o = joint.JointOrigin();
  const KDL::Vector a = joint.JointAxis();
  const Eigen::Vector3d p_wc_B = X_Bprev * Eigen::Vector3d(o.x(), o.y(), o.z());
  const Eigen::Vector3d axis_B = X_Bprev.linear() * Eigen::Vector3d(a.x(), a.y(), a.z()).normalized();
  const Eigen::Isometry3d X_Btip = kinematics::ForwardKinematics(arm, q0);
  WristGeometry g;
  g.p_wc = X_Btip.inverse() * p_wc_B;
  g.axis = X_Btip.linear().transpose() * axis_B;
  if (g.axis.dot(d.end_effector.p_tcp - g.p_wc) < 0.0) g.axis = -g.axis;
  return g;
}

}  // namespace

double ReferenceM6(const RobotDescription& d) {
  double m = 0.0;
  for (int s = d.arm.last_moving_segment(); s < d.arm.num_segments(); ++s) {
    m += d.arm.segment_inertial(s).mass;
  }
  for (const auto& b : d.end_effector.bodies) m += b.inertial.mass;
  return m;
}

double ReferenceD6(const RobotDescription& d) {
  const WristGeometry g = ComputeWristGeometry(d);
  return (d.end_effector.p_tcp - g.p_wc).dot(g.axis);
}

Eigen::Vector3d ToolAxisInTip(const RobotDescription& d) { return ComputeWristGeometry(d).axis; }

ParameterSet DefaultParameters(const RobotDescription& d) {
  ParameterSet p;
  const int n = d.arm.num_joints();
  if (d.joint_stiffness.size() != n) {
    throw std::invalid_argument("joint stiffness has " + std::to_string(d.joint_stiffness.size()) +
                                " entries, the robot has " + std::to_string(n) + " joints");
  }
  for (int j = 0; j < n; ++j) {
    const double k = d.joint_stiffness(j);
    if (!(k > 0.0) || !std::isfinite(k)) {
      throw std::invalid_argument("joint stiffness " + std::to_string(j + 1) +
                                  " must be > 0, got " + std::to_string(k));
    }
    // Three decades either way: a fit that leaves them has found no stiffness.
    p.Add({"kq" + std::to_string(j + 1) + "_Nm_per_rad", "N·m/rad", k, k * 1e-3, k * 1e3, true,
           "stiffness of joint " + std::to_string(j + 1)});
  }
  const double m6 = ReferenceM6(d);
  const double d6 = ReferenceD6(d);
  p.Add({"m6_kg", "kg", m6, 0.1 * m6, 10.0 * m6, true,
         "mass of the last link plus the rigid end effector"});
  p.Add({"d6_m", "m", d6, std::max(0.0, d6 - 0.5), d6 + 1.0, true,
         "distance along the last joint axis from the wrist centre to the tool tip"});
  p.Add({"alpha_s", "s", d.alpha, 0.0, 0.1, true, "stiffness-proportional Rayleigh damping"});
  p.Add({"beta_per_s", "1/s", d.beta, 0.0, 1e3, true, "mass-proportional Rayleigh damping"});
  for (const EffectConfig& ec : d.effects) {
    const auto effect = EffectRegistry::Instance().Create(ec.name);
    effect->CheckApplicable(d);
    const auto specs = effect->parameters();
    for (ParameterSpec spec : specs) {
      spec.name = ec.name + "." + spec.name;
      p.Add(spec);
    }
    for (const auto& [key, value] : ec.values) {
      const std::string full = ec.name + "." + key;
      if (!p.Has(full)) {
        std::string known;
        for (const auto& s : specs) known += (known.empty() ? "" : ", ") + s.name;
        throw std::invalid_argument("effect '" + ec.name + "' has no parameter '" + key +
                                    "'; its parameters: " + known);
      }
      p.Set(full, value);
    }
  }
  return p;
}

std::pair<RobotDescription, ParameterSet> WithEffect(const RobotDescription& description, const ParameterSet& base,
                                                     const std::string& effect) {
  RobotDescription d = description;
  d.effects.push_back({effect, {}});
  ParameterSet p = DefaultParameters(d);
  for (const auto& s : base.specs()) p.Set(s.name, base.Get(s.name));
  return {std::move(d), std::move(p)};
}

std::shared_ptr<const RobotModel> RobotModel::Build(const RobotDescription& d,
                                                    const ParameterSet& parameters) {
  const ParameterSet defaults = DefaultParameters(d);
  if (defaults.NameList() != parameters.NameList()) {
    throw std::invalid_argument("the parameter set does not belong to this robot description; "
                                "expected: " + defaults.NameList());
  }
  ParameterSet checked = defaults;  // re-checks every bound
  for (const auto& s : parameters.specs()) checked.Set(s.name, parameters.Get(s.name));

  std::shared_ptr<RobotModel> m(new RobotModel());
  m->description_ = d;
  m->parameters_ = checked;
  const int n = d.arm.num_joints();
  m->joint_stiffness_.resize(n);
  for (int j = 0; j < n; ++j) {
    m->joint_stiffness_(j) = checked.Get("kq" + std::to_string(j + 1) + "_Nm_per_rad");
  }
  m->alpha_ = checked.Get("alpha_s");
  m->beta_ = checked.Get("beta_per_s");

  // The m6/d6 rule of EndEffector.
  const double scale = checked.Get("m6_kg") / ReferenceM6(d);
  const double delta_d6 = checked.Get("d6_m") - ReferenceD6(d);
  const WristGeometry g = ComputeWristGeometry(d);
  kinematics::SerialChain chain = d.arm;
  for (int s = d.arm.last_moving_segment(); s < d.arm.num_segments(); ++s) {
    Inertial b = d.arm.segment_inertial(s);
    b.mass *= scale;
    b.inertia_com *= scale;
    chain = chain.WithSegmentInertial(s, b);
  }
  const Eigen::Vector3d p_tcp = d.end_effector.p_tcp + delta_d6 * g.axis;
  const double h_tcp = d.end_effector.p_tcp.dot(g.axis);
  Inertial ee;
  for (const EndEffectorBody& body : d.end_effector.bodies) {
    Inertial b = body.inertial;
    b.mass *= scale;
    b.inertia_com *= scale;
    if (h_tcp > 0.0) b.com += delta_d6 * (b.com.dot(g.axis) / h_tcp) * g.axis;
    ee = CombineInertials(ee, b);
    m->end_effector_bodies_.push_back({body.name, b});
  }
  chain = chain.WithFixedSegment("end_effector", Eigen::Isometry3d::Identity(), ee);
  Eigen::Isometry3d X_tip_tcp = Eigen::Isometry3d::Identity();
  X_tip_tcp.translation() = p_tcp;
  chain = chain.WithFixedSegment("tcp", X_tip_tcp, Inertial{});
  m->chain_ = chain;
  m->p_TN_ = d.end_effector.p_spindle_nose - p_tcp;
  m->p_tcp_ = p_tcp;

  for (const EffectConfig& ec : d.effects) {
    BoundEffect be;
    be.effect = EffectRegistry::Instance().Create(ec.name);
    for (const auto& spec : be.effect->parameters()) {
      be.values.push_back(checked.Get(ec.name + "." + spec.name));
    }
    m->effects_.push_back(std::move(be));
  }
  // Apply (and number the extra DOFs of) effects from the floor to the tool
  // tip, whatever their order in the config (EffectStage).
  std::stable_sort(m->effects_.begin(), m->effects_.end(),
                   [](const BoundEffect& a, const BoundEffect& b) {
                     if (a.effect->stage() != b.effect->stage()) return a.effect->stage() < b.effect->stage();
                     return a.effect->stage_order() < b.effect->stage_order();
                   });
  int next_dof = n;
  for (BoundEffect& be : m->effects_) {
    be.first_extra_dof = next_dof;
    next_dof += be.effect->num_extra_dofs(be.values);
  }
  m->num_dofs_ = next_dof;
  return m;
}

}  // namespace robomach::dynamics
