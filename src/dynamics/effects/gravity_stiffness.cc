// gravity_stiffness: the pose-dependent stiffness that gravity loads add to
// the joints.
//
// With elastic joints held by position-controlled motors, the links obey
// M q'' + K_q (q − θ_m) + G(q) = 0 with G = ∂V/∂q the gravity torque of the
// potential V(q) = −Σ_i m_i gᵀ c_i(q). Linearised about the static posture,
// the stiffness is K_q + ∂G/∂q, and ∂G/∂q = ∂²V/∂q² is the symmetric
// Hessian of the potential (the "geometric stiffness" of the gravity load)
// [Dumas, Caro et al. 2011 on pose-dependent robot stiffness; Alici & Shirinzadeh
// 2005 on the load-dependent term J_θᵀ F]. For revolute joints with unit
// axes a_j through points o_j (in B), ∂c/∂q_j = a_j × (c − o_j) for bodies
// beyond joint j, so for j ≤ k (k nearer the tip)
//   ∂²V/∂q_j∂q_k = −gᵀ [a_j × (a_k × (h_k − m_k o_k))],                 (1)
// with m_k and h_k = Σ m_i c_i the mass and first moment of everything beyond
// joint k (the chain's links and end effector as built with m6 and d6). For
// a pendulum hanging down, (1) is m g l_c cos(angle from the vertical) > 0:
// gravity stiffens a hanging link and softens an upright one.
//
// Gravity is (0, 0, −9.80665 m/s²)·gravity_scale in the base frame B (a floor-
// mounted robot with base z up, as the KR210 URDF has). The effect acts on
// the joint block only: the geometric stiffness of other effects' DOFs
// (base rocking: m g h ≈ 1e4 N·m/rad against ≈ 1e7–1e8; the spindle on the
// flange: ≈ 20 N·m/rad against ≈ 1e6) is below 0.1 % and left out, and so is
// the mass of tip_mass.
//
// - [Alici & Shirinzadeh 2005] G. Alici, B. Shirinzadeh, Enhanced stiffness
//   modeling, identification and characterization for robot manipulators,
//   IEEE Trans. Robotics 21(4):554–564, 2005.
// - [Dumas, Caro et al. 2011] C. Dumas, S. Caro, S. Garnier, B. Furet, Joint
//   stiffness identification of six-revolute industrial serial robots,
//   Robotics and Computer-Integrated Manufacturing 27(4):881–888, 2011.
#include <span>

#include <kdl/frames.hpp>

#include "robomach/common/units.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

class GravityStiffnessEffect final : public Effect {
 public:

  std::string name() const override { return "gravity_stiffness"; }
  std::string description() const override {
    return "pose-dependent joint stiffness from gravity loads, K += d2V/dq2 (Alici & "
           "Shirinzadeh 2005)";
  }
  std::vector<ParameterSpec> parameters() const override {
    return {{"gravity_scale", "1", 1.0, 0.0, 2.0, true,
             "gravity as a multiple of 9.80665 m/s² along −z of the base (1 = floor-mounted)"}};
  }

  void Contribute(const EffectContext& ctx, std::span<const double> values, int,
                  AssembledSystem* sys) const override {
    const Eigen::Vector3d g(0.0, 0.0, -kStandardGravity * values[0]);
    const KDL::Chain& chain = ctx.model.chain().kdl();
    const int S = static_cast<int>(chain.getNrOfSegments());
    const int n = ctx.model.num_joints();
    // Joint axes and origins, and each segment's mass and first moment, in B.
    std::vector<Eigen::Vector3d> axis(n), origin(n);
    std::vector<int> joint_segment(n);
    std::vector<double> m(S);
    std::vector<Eigen::Vector3d> h(S);
    KDL::Frame F = KDL::Frame::Identity();
    int j = 0;
    for (int s = 0; s < S; ++s) {
      const KDL::Segment& seg = chain.getSegment(s);
      const KDL::Joint& joint = seg.getJoint();
      double qs = 0.0;
      if (joint.getType() != KDL::Joint::None) {
        const KDL::Vector a = F.M * joint.JointAxis();
        const KDL::Vector o = F * joint.JointOrigin();
        axis[j] = Eigen::Vector3d(a.x(), a.y(), a.z()).normalized();
        origin[j] = Eigen::Vector3d(o.x(), o.y(), o.z());
        joint_segment[j] = s;
        qs = ctx.q(j);
        ++j;
      }
      F = F * seg.pose(qs);
      const KDL::RigidBodyInertia& I = seg.getInertia();
      const KDL::Vector c = F * I.getCOG();
      m[s] = I.getMass();
      h[s] = m[s] * Eigen::Vector3d(c.x(), c.y(), c.z());
    }
    // Mass and first moment beyond each joint (suffix sums over segments).
    std::vector<double> m_out(n);
    std::vector<Eigen::Vector3d> h_out(n);
    for (int k = 0; k < n; ++k) {
      m_out[k] = 0.0;
      h_out[k].setZero();
      for (int s = joint_segment[k]; s < S; ++s) {
        m_out[k] += m[s];
        h_out[k] += h[s];
      }
    }
    // Eq. (1).
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d w = axis[k].cross(h_out[k] - m_out[k] * origin[k]);
      for (int i = 0; i <= k; ++i) {
        const double v = -g.dot(axis[i].cross(w));
        sys->K(i, k) += v;
        if (i != k) sys->K(k, i) += v;
      }
    }
  }
};

}  // namespace robomach::dynamics

ROBOMACH_REGISTER_EFFECT(gravity_stiffness, robomach::dynamics::GravityStiffnessEffect)
