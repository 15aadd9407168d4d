#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/dynamics/parameters.h"
#include "robomach/kinematics/serial_chain.h"

namespace robomach::dynamics {

class Effect;

/// One rigid body of the end effector, fixed to the robot's tip frame.
struct EndEffectorBody {
  std::string name;
  kinematics::Inertial inertial;  // in the arm's tip frame (tool0 for the KR210)
};

/// The end effector (spindle, holder, tool) as rigid bodies fixed to the
/// flange, with the tool centre point.
///
/// The seed's calibration parameters are defined on it:
/// - m6: mass of the last link plus the rigid end effector [kg];
/// - d6: distance along the last joint's axis from the wrist centre (the
///   origin of the last joint) to the tool tip [m].
///
/// Rule when m6 and d6 differ from their reference values m6_ref, d6_ref
/// (which the geometry below defines):
/// 1. every body of the last link and of the end effector has its mass and
///    inertia tensor multiplied by s = m6 / m6_ref; centres of mass stay (a
///    uniform density change: the mass distribution keeps its shape);
/// 2. the TCP moves by Δd6 = d6 − d6_ref along the last joint's axis, away
///    from the wrist, and every end-effector body's COM moves along that axis
///    by Δd6 · h_b / h_T, where h_b and h_T are the distances of the body's
///    COM and of the TCP from the flange face along the axis (a uniform
///    stretch of the end effector between flange and tip); the link itself
///    and the inertia tensors about the COMs do not change.
struct EndEffector {
  std::vector<EndEffectorBody> bodies;
  Eigen::Vector3d p_tcp{Eigen::Vector3d::Zero()};           // [m], in the tip frame
  Eigen::Vector3d p_spindle_nose{Eigen::Vector3d::Zero()};  // [m], gauge line, in the tip frame
};

/// One enabled effect with parameter values given in the config, by the
/// effect's own (unprefixed) parameter names.
struct EffectConfig {
  std::string name;
  std::map<std::string, double> values;
};

/// What the user described: the arm, its joint stiffness, the end effector,
/// damping and the enabled effects. RobotModel::Build turns it and a
/// ParameterSet into an evaluable model.
struct RobotDescription {
  kinematics::SerialChain arm;          // base to the arm's tip frame (flange/tool0), no end effector
  Eigen::VectorXd joint_stiffness;      // diag K_q defaults [N·m/rad]
  double alpha{0.0};                    // C = alpha K + beta M [s]
  double beta{0.0};                     // [1/s]
  EndEffector end_effector;
  std::vector<EffectConfig> effects;    // in the order they are applied
  /// Raw numeric sections kept for effects (e.g. "spindle_toolholder_interface.elements").
  std::map<std::string, double> extra_values;
  std::string source;                   // file it came from, for messages
};

/// Reference m6 [kg] and d6 [m] of a description (see EndEffector).
double ReferenceM6(const RobotDescription& d);
double ReferenceD6(const RobotDescription& d);
/// Unit vector of the last joint's axis in the arm's tip frame, pointing from
/// the wrist centre towards the TCP.
Eigen::Vector3d ToolAxisInTip(const RobotDescription& d);

/// The named parameters of a description with their defaults:
/// kq1_Nm_per_rad … kqn_Nm_per_rad, m6_kg, d6_m, alpha_s, beta_per_s, then
/// each enabled effect's parameters as "effect.param" (config values applied).
/// @throws std::invalid_argument for an unknown effect or effect parameter.
ParameterSet DefaultParameters(const RobotDescription& d);

/// The description with `effect` switched on and parameters for it: the
/// values of `base` kept, the new effect's at their defaults (the tools'
/// `--add`, the audit's candidates, Python's `add`).
/// @throws std::invalid_argument for an unknown effect.
std::pair<RobotDescription, ParameterSet> WithEffect(const RobotDescription& description, const ParameterSet& base,
                                                     const std::string& effect);

/// An effect bound to its parameter values and to its extra degrees of
/// freedom in the assembled system.
struct BoundEffect {
  std::shared_ptr<const Effect> effect;
  std::vector<double> values;  // in the order of effect->parameters()
  int first_extra_dof{0};      // index in the assembled system
};

/// An evaluable robot model: the chain with the end effector and TCP built
/// in for given m6 and d6, joint stiffness, damping and bound effects.
/// Immutable; safe to share between threads.
class RobotModel {
 public:
  /// @throws std::invalid_argument if the parameters do not belong to the
  ///   description or are outside their bounds.
  static std::shared_ptr<const RobotModel> Build(const RobotDescription& description,
                                                 const ParameterSet& parameters);
  static std::shared_ptr<const RobotModel> Build(const RobotDescription& description) {
    return Build(description, DefaultParameters(description));
  }

  const RobotDescription& description() const { return description_; }
  const ParameterSet& parameters() const { return parameters_; }
  /// The chain from base to TCP, last link and end effector included.
  const kinematics::SerialChain& chain() const { return chain_; }
  int num_joints() const { return chain_.num_joints(); }
  /// Joints plus the extra degrees of freedom of effects.
  int num_dofs() const { return num_dofs_; }
  const Eigen::VectorXd& joint_stiffness() const { return joint_stiffness_; }  // [N·m/rad]
  double alpha() const { return alpha_; }  // [s]
  double beta() const { return beta_; }    // [1/s]
  /// In the order they are applied: by EffectStage, then as in the config
  /// (so not necessarily description().effects' order).
  const std::vector<BoundEffect>& effects() const { return effects_; }
  /// Position of the spindle nose (gauge line) in the TCP frame [m].
  const Eigen::Vector3d& p_TN() const { return p_TN_; }
  /// The end-effector bodies as built (m6/d6 rule applied), in the arm's tip
  /// frame; the chain's "end_effector" segment is their sum.
  const std::vector<EndEffectorBody>& end_effector_bodies() const { return end_effector_bodies_; }
  /// Position of the TCP in the arm's tip frame as built (d6 applied) [m].
  const Eigen::Vector3d& p_tcp() const { return p_tcp_; }

 private:
  RobotModel() = default;
  RobotDescription description_;
  ParameterSet parameters_;
  kinematics::SerialChain chain_;
  Eigen::VectorXd joint_stiffness_;
  double alpha_{0.0};
  double beta_{0.0};
  std::vector<BoundEffect> effects_;
  int num_dofs_{0};
  Eigen::Vector3d p_TN_{Eigen::Vector3d::Zero()};
  std::vector<EndEffectorBody> end_effector_bodies_;
  Eigen::Vector3d p_tcp_{Eigen::Vector3d::Zero()};
};

}  // namespace robomach::dynamics
