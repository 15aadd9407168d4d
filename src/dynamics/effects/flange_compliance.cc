// flange_compliance: the end effector on springs at the robot flange instead
// of rigidly fixed to it (the bolted flange/bracket joint between the wrist
// and the spindle).
//
// All end-effector bodies (spindle with bracket, holder and tool, as built
// with m6 and d6) form one rigid body on six springs at the flange centre
// (origin of the tip frame tool0), with the flange axes as spring axes
// (z along the spindle axis): translational stiffness k_xy laterally and
// k_z axially, bending stiffness k_θxy about the lateral axes and torsional
// stiffness k_θz. The body's six relative DOFs couple to the robot through
// its inertia (dynamics/internal/body_on_springs.h); the tool tip moves
// with it. A bolted flange joint acts as a set of contact springs whose
// stiffness is a property of the joint, not of either body
// [Ito 2008, ch. 3 on bolted joints in machine structures].
//
// Defaults: a stiff bolted ISO 9409-1-160 flange with a cast spindle
// bracket, chosen so that the flange adds a few per cent to the static
// compliance at the tool tip and puts the spindle's rocking mode on the
// flange at a few hundred hertz (22 kg, 0.5 kg·m² about the flange,
// k_θ = 2e6 N·m/rad: ≈ 300 Hz), the range where hammer tests on milling
// robots show end-effector modes. Engineering assumptions, not measurements.
//
// - [Ito 2008] Y. Ito, Modular Design for Machine Tools, McGraw-Hill, 2008.
#include <span>

#include "dynamics/internal/body_on_springs.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

class FlangeComplianceEffect final : public Effect {
 public:
  std::string name() const override { return "flange_compliance"; }
  std::string description() const override {
    return "end effector on translational and bending/torsional springs at the flange";
  }
  std::vector<ParameterSpec> parameters() const override {
    return {
        {"lateral_stiffness_N_per_m", "N/m", 5e8, 1e6, 1e12, true,
         "flange joint stiffness across the spindle axis"},
        {"axial_stiffness_N_per_m", "N/m", 1e9, 1e6, 1e12, true,
         "flange joint stiffness along the spindle axis"},
        {"bending_stiffness_Nm_per_rad", "N·m/rad", 2e6, 1e3, 1e10, true,
         "flange joint stiffness about the axes across the spindle axis"},
        {"torsional_stiffness_Nm_per_rad", "N·m/rad", 2e6, 1e3, 1e10, true,
         "flange joint stiffness about the spindle axis"},
        // Bolted joints dissipate by micro-slip: 2–5 % is the usual range.
        {"damping_ratio", "1", 0.03, 0.001, 0.3, true,
         "damping ratio of the end effector's modes on the flange (replaces alpha K there)"},
    };
  }
  EffectStage stage() const override { return EffectStage::kFlange; }
  int num_extra_dofs(std::span<const double>) const override { return 6; }

  void Contribute(const EffectContext& ctx, std::span<const double> v, int first,
                  AssembledSystem* sys) const override {
    const RobotModel& model = ctx.model;
    Eigen::Isometry3d X_B_tip = ctx.X_BT;
    X_B_tip.translation() = ctx.X_BT * (-model.p_tcp());
    kinematics::Inertial ee;
    for (const auto& b : model.end_effector_bodies()) ee = kinematics::CombineInertials(ee, b.inertial);
    internal::SpringMount mount;
    mount.p_BP = X_B_tip.translation();
    mount.R_BS = X_B_tip.linear();
    mount.components = {0, 1, 2, 3, 4, 5};
    mount.K_S = Eigen::VectorXd((Eigen::VectorXd(6) << v[0], v[0], v[1], v[2], v[2], v[3]).finished())
                    .asDiagonal();
    mount.body_B = kinematics::TransformInertial(ee, X_B_tip);
    mount.carries_tool_tip = true;
    mount.damping_ratio = v[4];
    internal::MountBodyOnSprings(mount, ctx.X_BT.translation(), model.alpha(), first, sys);
  }
};

}  // namespace robomach::dynamics

ROBOMACH_REGISTER_EFFECT(flange_compliance, robomach::dynamics::FlangeComplianceEffect)
