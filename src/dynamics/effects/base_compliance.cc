// base_compliance: the robot's base on a compliant foundation (anchor bolts,
// base plate, concrete), with translational, rocking and torsional springs.
//
// Six extra DOFs β = [u_b; θ_b]: a small translation and rotation of the
// base frame B about its origin (the base plate's centre on the floor), in B
// axes. The whole robot moves with the base: a body with COM c_i and twist
// A_i q' gets v_i = A_i^v q' + u_b' + θ_b' × c_i and ω_i = A_i^ω q' + θ_b'.
// The kinetic energy Σ ½ [v_i; ω_i]ᵀ Λ_i [v_i; ω_i] then gives, with Φ the
// spatial inertias at the origin and ξ_k the joint twists
// (dynamics/internal/composite_inertia.h),
//   M_ββ = Φ_total + M_foundation,   M_βq(:, k) = Φ_k^C ξ_k,             (1)
// and the joint block stays KDL's M_q [Featherstone 2008, §9.2 on floating
// bases]. K_ββ = diag(k_xy, k_xy, k_z, k_rock, k_rock, k_torsion); the tool
// tip moves by u_b + θ_b × p_T, so B gains [I  −[p_T]×]. The foundation mass
// (pedestal or base plate, and the base casting, which the URDF's chain
// does not carry because KDL's root has no inertia) moves with the base,
// with an isotropic rotational inertia about the origin.
//
// Defaults: a KR210 anchored on a concrete floor with a steel base plate.
// Rocking stiffness 5e7 N·m/rad (≈ 15× the stiffest joint, so the base adds
// 5–10 % to the static compliance at the tip at the demo postures, and puts
// rocking modes of the robot on its base near 130–180 Hz), translation 5e8 N/m laterally and 1e9 N/m
// vertically, torsion 5e7 N·m/rad; 400 kg and 40 kg·m² for the base
// casting and plate. Engineering assumptions, not measurements.
//
// Gravity's destabilising m g h ≈ 1e4 N·m/rad on rocking is ignored
// (gravity_stiffness covers the joints only).
//
// - [Featherstone 2008] R. Featherstone, Rigid Body Dynamics Algorithms,
//   Springer, 2008.
#include <span>

#include "dynamics/internal/body_on_springs.h"
#include "dynamics/internal/composite_inertia.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

class BaseComplianceEffect final : public Effect {
 public:
  std::string name() const override { return "base_compliance"; }
  std::string description() const override {
    return "robot base on a compliant foundation: translational, rocking and torsional springs";
  }
  std::vector<ParameterSpec> parameters() const override {
    return {
        {"lateral_stiffness_N_per_m", "N/m", 5e8, 1e6, 1e12, true,
         "foundation stiffness along base x and y"},
        {"vertical_stiffness_N_per_m", "N/m", 1e9, 1e6, 1e12, true,
         "foundation stiffness along base z"},
        {"rocking_stiffness_Nm_per_rad", "N·m/rad", 5e7, 1e4, 1e11, true,
         "foundation stiffness about base x and y"},
        {"torsional_stiffness_Nm_per_rad", "N·m/rad", 5e7, 1e4, 1e11, true,
         "foundation stiffness about base z"},
        {"foundation_mass_kg", "kg", 400.0, 0.0, 1e5, false,
         "mass moving with the base besides the chain's links (base casting, plate)"},
        {"foundation_inertia_kgm2", "kg·m²", 40.0, 0.0, 1e5, false,
         "rotational inertia of that mass about the base origin (isotropic)"},
        // Anchored bases on concrete: ≈ 5 % (grout and floor losses).
        {"damping_ratio", "1", 0.05, 0.001, 0.3, true,
         "damping ratio of the robot's rigid-body modes on the foundation (replaces alpha K there)"},
    };
  }
  EffectStage stage() const override { return EffectStage::kBase; }
  int num_extra_dofs(std::span<const double>) const override { return 6; }

  void Contribute(const EffectContext& ctx, std::span<const double> v, int b,
                  AssembledSystem* sys) const override {
    const int n = ctx.model.num_joints();
    const internal::CompositeInertia ci =
        internal::ComputeCompositeInertia(ctx.model.chain().kdl(), ctx.q);
    Matrix6d M_bb = ci.total;
    M_bb.topLeftCorner<3, 3>() += v[4] * Eigen::Matrix3d::Identity();
    M_bb.bottomRightCorner<3, 3>() += v[5] * Eigen::Matrix3d::Identity();
    sys->M.block<6, 6>(b, b) += M_bb;
    for (int k = 0; k < n; ++k) {
      const Vector6d c = ci.composite[k] * ci.joint_twist[k];
      sys->M.block<6, 1>(b, k) += c;
      sys->M.block<1, 6>(k, b) += c.transpose();
    }
    Vector6d k;
    k << v[0], v[0], v[1], v[2], v[2], v[3];
    sys->K.block<6, 6>(b, b) += k.asDiagonal();
    // Damping of the foundation's own modes, as for a mounted body
    // (dynamics/internal/body_on_springs.h): the robot held rigid on its
    // springs has six modes of ratio ζ, instead of α K's α ω/2.
    const Matrix6d K_bb = k.asDiagonal();
    sys->C_extra.block<6, 6>(b, b) +=
        internal::ModalDampingMatrix(M_bb, K_bb, v[6]) - ctx.model.alpha() * K_bb;
    // The tool-carrying body moves with the base: its twist at T per base DOF.
    sys->V_T.middleCols<6>(b) = internal::ShiftTwist(ctx.X_BT.translation());
    sys->B = sys->V_T.topRows<3>();
  }
};

}  // namespace robomach::dynamics

ROBOMACH_REGISTER_EFFECT(base_compliance, robomach::dynamics::BaseComplianceEffect)
