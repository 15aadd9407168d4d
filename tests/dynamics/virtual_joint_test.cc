// The virtual_joint_<place>_<axis> effects (issue #33): compliance anywhere
// along the chain.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "effect_test_support.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::ExpectValidSystem;
using robomach::testing::Kr210;
using robomach::testing::Kr210With;
using robomach::testing::RandomPosture;

// The tip frame of the segment joint `j` (1-based) moves, by walking the
// chain (not the effect's code path).
Eigen::Isometry3d PlaceFrame(const RobotModel& m, const Eigen::VectorXd& q, int j) {
  if (j == 0) return Eigen::Isometry3d::Identity();
  int seen = 0;
  for (int s = 0; s < m.chain().num_segments(); ++s) {
    if (m.chain().kdl().getSegment(s).getJoint().getType() != KDL::Joint::None && ++seen == j) {
      return kinematics::SegmentPose(m.chain(), q, s);
    }
  }
  ADD_FAILURE() << "no joint " << j;
  return Eigen::Isometry3d::Identity();
}

TEST(VirtualJoint, NamesParseAndBadNamesAreRefused) {
  auto& reg = EffectRegistry::Instance();
  EXPECT_EQ(reg.Create("virtual_joint_base_rx")->name(), "virtual_joint_base_rx");
  EXPECT_EQ(reg.Create("virtual_joint_link3_ty")->name(), "virtual_joint_link3_ty");
  EXPECT_EQ(reg.Create("virtual_joint_link3_rx")->description(),
            "an elastic rotation about link 3's x axis, right after joint 3");
  EXPECT_EQ(reg.Create("virtual_joint_link2_tz")->parameters().at(0).name, "stiffness_N_per_m");
  for (const char* bad : {"virtual_joint_link0_rx", "virtual_joint_link03_rx", "virtual_joint_link3_rw",
                          "virtual_joint_link_rx", "virtual_joint_base", "virtual_joint_", "virtual_joint_link3rx"}) {
    try {
      reg.Create(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("virtual_joint_<place>_<axis>"), std::string::npos) << e.what();
    }
  }
  // Not among the single effects (the audit screens the family its own way).
  for (const auto& n : reg.Names()) EXPECT_EQ(n.find("virtual_joint"), std::string::npos);
  // A place beyond the robot's joints is refused when the model is made.
  io::RobotConfig cfg = robomach::testing::Kr210Config();
  cfg.description.effects.push_back({"virtual_joint_link7_rx", {}});
  EXPECT_THROW(DefaultParameters(cfg.description), std::invalid_argument);
}

// Second method for the whole mass matrix (joints, a base on its
// foundation, a virtual joint in the upper arm and one in the wrist): the
// kinetic energy of every body with the virtual joints' displacements
// applied as conjugated rigid motions of the bodies beyond them,
// X_b(z) = base(z) · C_3(z) · C_5(z) · X_b(q), C_j = X_j(q) D_j X_j(q)⁻¹
// (the pose of a body behind two inserted joints), finite-differenced as
// in base_compliance_test.cc (tolerance 1e-7 of √(M_ii M_jj)).
TEST(VirtualJoint, MassMatrixEqualsKineticEnergyOfBodies) {
  const auto model = Kr210With({{"virtual_joint_link5_ty", {}}, {"base_compliance", {}}, {"virtual_joint_link3_rx", {}}});
  ASSERT_EQ(model->num_dofs(), 14);
  const RobotModel* m = model.get();
  // Applied from the floor outwards whatever the config order: base 6-11, link3 12, link5 13.
  const auto base = [](const Eigen::VectorXd& z) {
    return testing::SpringDisplacement(Eigen::Vector3d::Zero(), z.segment<3>(6), z.segment<3>(9));
  };
  const auto conj = [m](const Eigen::VectorXd& z, int place, const Eigen::Vector3d& u_local,
                        const Eigen::Vector3d& th_local) {
    const Eigen::Isometry3d X = PlaceFrame(*m, z.head(6), place);
    return Eigen::Isometry3d(X * testing::SpringDisplacement(Eigen::Vector3d::Zero(), u_local, th_local) *
                             X.inverse());
  };
  const auto carried = [base, conj](const Eigen::VectorXd& z, int segment_joint) {
    // The displacement of a body moved by joint `segment_joint` (0: fixed to the base).
    Eigen::Isometry3d D = base(z);
    if (segment_joint >= 3) D = D * conj(z, 3, Eigen::Vector3d::Zero(), z(12) * Eigen::Vector3d::UnitX());
    if (segment_joint >= 5) D = D * conj(z, 5, z(13) * Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero());
    return D;
  };
  std::vector<testing::PosedBody> bodies;
  const auto& chain = m->chain();
  int joints_so_far = 0;
  for (int s = 0; s < chain.num_segments(); ++s) {
    if (chain.kdl().getSegment(s).getName() == "end_effector") break;
    joints_so_far += chain.kdl().getSegment(s).getJoint().getType() != KDL::Joint::None;
    testing::PosedBody b;
    b.inertial = chain.segment_inertial(s);
    if (b.inertial.mass == 0.0) continue;
    const int moved_by = joints_so_far;
    b.pose = [&chain, s, moved_by, carried](const Eigen::VectorXd& z) {
      return Eigen::Isometry3d(carried(z, moved_by) * kinematics::SegmentPose(chain, z.head(6), s));
    };
    bodies.push_back(b);
  }
  kinematics::Inertial ee;
  for (const auto& b : m->end_effector_bodies()) ee = kinematics::CombineInertials(ee, b.inertial);
  bodies.push_back({ee, [m, carried](const Eigen::VectorXd& z) {
                      return Eigen::Isometry3d(carried(z, 6) * testing::TipPose(*m, z));
                    }});
  kinematics::Inertial foundation;
  foundation.mass = m->parameters().Get("base_compliance.foundation_mass_kg");
  foundation.inertia_com = m->parameters().Get("base_compliance.foundation_inertia_kgm2") * Eigen::Matrix3d::Identity();
  bodies.push_back({foundation, base});
  std::mt19937 rng(331);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd z = Eigen::VectorXd::Zero(14);
    z.head(6) = RandomPosture(*model, rng);
    const PostureDynamics pd = EvaluatePosture(model, z.head(6));
    ExpectValidSystem(pd.system);
    EXPECT_LE(testing::MaxScaledDifference(pd.system.M, testing::MassFromKineticEnergy(bodies, z, 1e-5)), 1e-7);
  }
}

// Static superposition, derived by hand: the virtual joint is a spring in
// series with the joints, H(0) = J_v K_q⁻¹ J_vᵀ + g gᵀ / k_v, with
// g = a × (p_T − o) for a rotation about the unit axis a through o, and
// g = a for a translation along a. Rounding: cond(K) ≈ 1e3 here; 1e-9.
TEST(VirtualJoint, StaticComplianceIsJointsPlusSpringInSeries) {
  const auto rigid = Kr210();
  std::mt19937 rng(332);
  for (const auto& [name, place, axis, k] : std::vector<std::tuple<std::string, int, int, double>>{
           {"virtual_joint_base_ry", 0, 1, 3e7},
           {"virtual_joint_link2_rx", 2, 0, 5e6},
           {"virtual_joint_link3_tz", 3, 5, 4e7},
           {"virtual_joint_link6_ry", 6, 1, 1e6}}) {
    const std::string param = axis < 3 ? "stiffness_Nm_per_rad" : "stiffness_N_per_m";
    const auto model = Kr210With({{name, {{param, k}}}});
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const PostureDynamics p0 = EvaluatePosture(rigid, q);
    const PostureDynamics p1 = EvaluatePosture(model, q);
    const Eigen::Isometry3d X = PlaceFrame(*model, q, place);
    const Eigen::Vector3d a = X.linear().col(axis % 3);
    const Eigen::Vector3d g = axis < 3 ? Eigen::Vector3d(a.cross(p1.X_BT.translation() - X.translation())) : a;
    const Eigen::Matrix3d expected = p0.static_compliance + g * g.transpose() / k;
    EXPECT_LE((p1.static_compliance - expected).norm(), 1e-9 * expected.norm()) << name;
    EXPECT_GT((p1.static_compliance - p0.static_compliance).norm(), 1e-3 * p0.static_compliance.norm()) << name;
  }
}

// A virtual joint about a joint's own axis at that joint moves the same
// bodies with the same twist as the joint: its spring is the joint's in
// series (1/k = 1/kq + 1/kv) and the mass matrix is singular. It is refused
// with the parameter to fit instead (the URDF's joints turn about their
// link frame's z; joint 1's axis passes through the base origin along z).
TEST(VirtualJoint, RotationAboutTheJointsOwnAxisIsRefusedWithTheParameterToFit) {
  for (int j = 1; j <= 6; ++j) {
    io::RobotConfig cfg = robomach::testing::Kr210Config();
    cfg.description.effects.push_back({"virtual_joint_link" + std::to_string(j) + "_rz", {}});
    try {
      DefaultParameters(cfg.description);
      ADD_FAILURE() << "link" << j << "_rz accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("kq" + std::to_string(j) + "_Nm_per_rad"), std::string::npos) << e.what();
    }
    // The other axes there are legal.
    cfg.description.effects.back().name = "virtual_joint_link" + std::to_string(j) + "_rx";
    EXPECT_NO_THROW(DefaultParameters(cfg.description));
  }
  io::RobotConfig cfg = robomach::testing::Kr210Config();
  cfg.description.effects.push_back({"virtual_joint_base_rz", {}});
  EXPECT_THROW(DefaultParameters(cfg.description), std::invalid_argument);
}

// Stiff limit: ×100 on the stiffness, the tip FRF converges to the rigid
// model's (relative change below 1 % of the default's change).
TEST(VirtualJoint, ConvergesToTheRigidChainWhenStiff) {
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.3, -1.2, 1.4, 0.5, 0.9, -0.4).finished();
  const PostureDynamics p0 = EvaluatePosture(Kr210(), q);
  const PostureDynamics p1 = EvaluatePosture(Kr210With({{"virtual_joint_link2_ry", {{"stiffness_Nm_per_rad", 1e7}}}}), q);
  const PostureDynamics p100 =
      EvaluatePosture(Kr210With({{"virtual_joint_link2_ry", {{"stiffness_Nm_per_rad", 1e9}}}}), q);
  for (int k = 0; k < 6; ++k) {
    const double d1 = std::abs(p1.modes[k].freq_hz - p0.modes[k].freq_hz);
    const double d100 = std::abs(p100.modes[k].freq_hz - p0.modes[k].freq_hz);
    EXPECT_LE(d100, 0.02 * d1 + 1e-9 * p0.modes[k].freq_hz) << k;
  }
}

}  // namespace
}  // namespace robomach::dynamics
