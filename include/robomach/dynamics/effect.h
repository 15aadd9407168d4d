#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/common/eigen_types.h"
#include "robomach/common/named_registry.h"
#include "robomach/dynamics/parameters.h"

namespace robomach::dynamics {

class RobotModel;
struct RobotDescription;

/// The linear system about a posture, in generalised coordinates
/// z = [q (n joints); extra DOFs of effects]:
/// <pre>
///   M z'' + C z' + K z = Bᵀ F,      x_T = B z,
/// </pre>
/// F the force at the tool tip and x_T its translation, both in B.
/// Without effects M = M_q, K = K_q, B = J_v (the first three rows of J_BT).
/// The damping is C = alpha K + beta M + C_extra: Rayleigh damping of the
/// whole assembled system plus what effects add explicitly (C_extra).
struct AssembledSystem {
  Eigen::MatrixXd M;        // [kg, kg·m, kg·m²]
  Eigen::MatrixXd K;        // [N/m, N, N·m per rad]
  Eigen::MatrixXd C_extra;  // non-proportional damping added by effects
  Eigen::MatrixXd C;        // total damping, set after all effects
  Matrix3Xd B;              // tool-tip translation per generalised coordinate
  /// Twist [v; ω] at T of the body that carries the tool tip, per
  /// generalised coordinate, in B (6×N; J_BT in the joint columns). B is its
  /// top three rows. An effect that puts the tool-carrying part on springs
  /// (base, flange, spindle interface, tool) reads it to find how its
  /// attachment point moves and sets its own DOFs' columns (and B's); see
  /// EffectStage. Effects that only read B (tip_mass) leave it alone.
  Matrix6Xd V_T;
  int num_joints{0};
};

/// What an effect may read about the posture being evaluated.
struct EffectContext {
  const RobotModel& model;
  const Eigen::VectorXd& q;         // [rad]
  const Eigen::Isometry3d& X_BT;    // TCP pose
  const Matrix6Xd& J_BT;            // TCP Jacobian, rows [v; ω]
};

/// Where along the path from the floor to the tool tip an effect acts.
/// RobotModel applies effects in ascending stage (stable within a stage), so
/// that an effect that mounts a body on springs at some point of the robot
/// sees, in AssembledSystem::V_T, every flexibility between the floor and that
/// point (base before flange before spindle interface before tool), and a
/// load at the tool tip (tip_mass) sees all of them.
enum class EffectStage {
  kJointSpace = 0,  // terms on the joint coordinates only (damping, gravity)
  kBase = 1,        // the robot's base on a foundation
  kArm = 2,         // compliance inside the arm (virtual joints between the links)
  kFlange = 3,      // the end effector on the flange
  kSpindle = 4,     // the tool holder in the spindle
  kTool = 5,        // the tool in the holder
  kToolTip = 6,     // loads at the tool tip
};

/// A physical effect added to the base robot model: joint-space terms and/or
/// extra degrees of freedom coupled to the robot. An effect is one small
/// file under src/dynamics/effects/ that ends with
/// `ROBOMACH_REGISTER_EFFECT(file_stem, Class)`; CMake collects the files, so no
/// other edit is needed.
class Effect {
 public:
  virtual ~Effect() = default;
  /// Name used in configs and on the command line, e.g. "tip_mass".
  virtual std::string name() const = 0;
  /// One line: what physical effect this models, and the reference.
  virtual std::string description() const = 0;
  /// Parameters with unprefixed names ("mass_kg"); the model exposes them
  /// as "<effect>.<name>".
  virtual std::vector<ParameterSpec> parameters() const = 0;
  /// Where the effect acts; see EffectStage.
  virtual EffectStage stage() const { return EffectStage::kJointSpace; }
  /// Order within a stage (ascending, then as in the config): a virtual
  /// joint's place along the chain, so that the joints nearer the floor are
  /// applied first (see virtual_joint.cc).
  virtual int stage_order() const { return 0; }
  /// Throws std::invalid_argument when the effect cannot act on the robot
  /// of `description` (a virtual joint after joint 7 of a 6-axis robot, or
  /// one that turns about a joint's own axis). Checked when a description's
  /// parameters are made (DefaultParameters).
  virtual void CheckApplicable(const RobotDescription& /*description*/) const {}
  /// Extra generalised coordinates this effect adds (0 for joint-space terms).
  virtual int num_extra_dofs(std::span<const double> /*values*/) const { return 0; }
  /// Adds the effect's terms to `system`. Extra DOFs occupy indices
  /// [first_extra_dof, first_extra_dof + num_extra_dofs()); the matrices are
  /// already sized for them and zero there.
  virtual void Contribute(const EffectContext& context, std::span<const double> values,
                          int first_extra_dof, AssembledSystem* system) const = 0;
};

/// Registry of the effect library, filled at start-up.
class EffectRegistry {
 public:
  using Factory = std::function<std::shared_ptr<const Effect>()>;
  /// A family of effects named by a pattern (virtual_joint_<place>_<axis>):
  /// returns the effect of `name`, or nullptr when the name is not of the family.
  using FamilyFactory = std::function<std::shared_ptr<const Effect>(std::string_view name)>;
  static EffectRegistry& Instance();
  void Register(Factory factory);
  /// `pattern` is the family's names for people ("virtual_joint_<place>_<axis>
  /// (place: base, link1..linkN; axis: rx, ry, rz, tx, ty, tz)").
  void RegisterFamily(std::string pattern, FamilyFactory factory);
  /// @throws std::invalid_argument "unknown effect 'x': expected a, b or c; or of a
  /// family: <patterns>" (the registry's refusal, named_registry.h).
  std::shared_ptr<const Effect> Create(std::string_view name) const;
  /// The single effects (not the members of families): the audit's default
  /// candidates, Python's available_effects().
  std::vector<std::string> Names() const;
  /// The families' patterns, for messages and --help.
  std::vector<std::string> FamilyPatterns() const;

 private:
  // The single effects by name (the one registry idiom, named_registry.h);
  // the families, which match a name by pattern, stay a list.
  NamedRegistry<Factory> factories_{"unknown effect"};
  std::vector<std::pair<std::string, FamilyFactory>> families_;
};

}  // namespace robomach::dynamics

/// Registers an effect. Use it once per effect file, at global scope, with
/// the file's stem: in src/dynamics/effects/tip_mass.cc,
/// `ROBOMACH_REGISTER_EFFECT(tip_mass, robomach::dynamics::TipMassEffect)`.
/// CMake generates the list of registration calls from the file names, so no
/// other file changes; explicit calls cannot be dropped by the linker the way
/// unused static initialisers in a static library are.
#define ROBOMACH_REGISTER_EFFECT(file_stem, QualifiedClass)                          \
  void RobomachRegisterEffect_##file_stem(::robomach::dynamics::EffectRegistry& r) { \
    r.Register([] { return std::make_shared<const QualifiedClass>(); });             \
  }
