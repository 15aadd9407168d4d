// The effect library as a whole: registration, parameter conventions, and
// all effects switched on together.
#include <random>
#include <regex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "effect_test_support.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::ExpectValidSystem;
using robomach::testing::Kr210With;
using robomach::testing::RandomPosture;

TEST(EffectLibrary, RegistersEveryEffectOfTheIssue) {
  EXPECT_THAT(EffectRegistry::Instance().Names(),
              ::testing::IsSupersetOf({"tip_mass", "joint_damping", "gravity_stiffness",
                                       "base_compliance", "flange_compliance", "spindle_interface",
                                       "tool_flexibility"}));
}

// Names carry their unit (style §2.4) unless the quantity is a ratio or a
// count; defaults lie inside the bounds; every parameter is described.
TEST(EffectLibrary, ParametersFollowTheNamingAndBoundsConventions) {
  const std::regex with_unit(
      ".*_(kg|m|Pa|N_per_m|Nm_per_rad|Nms_per_rad|kgm2|kg_per_m3)$|.*_scale$|^damping_ratio$|^modes$");
  for (const std::string& name : EffectRegistry::Instance().Names()) {
    const auto effect = EffectRegistry::Instance().Create(name);
    EXPECT_FALSE(effect->description().empty()) << name;
    for (const ParameterSpec& p : effect->parameters()) {
      EXPECT_TRUE(std::regex_match(p.name, with_unit)) << name << "." << p.name;
      EXPECT_FALSE(p.unit.empty()) << name << "." << p.name;
      EXPECT_FALSE(p.description.empty()) << name << "." << p.name;
      EXPECT_LE(p.lower, p.default_value) << name << "." << p.name;
      EXPECT_LE(p.default_value, p.upper) << name << "." << p.name;
    }
  }
}

// Base, flange and interface together: the links ride on the base, the
// spindle on the flange springs, the holder on the interface springs, all
// nested. The kinetic energy of these bodies from finite-differenced poses
// checks all 22 coordinates' coupling (tolerance as in
// spindle_interface_test.cc: 1e-7 of √(M_ii M_jj)), and the tool tip's
// columns of B against finite differences of the tip (1e-6 of the tip
// speed per unit coordinate rate, h = 1e-6: round-off ≈ eps·2 m/h ≈ 4e-10).
TEST(EffectLibrary, NestedBaseFlangeAndInterfaceMatchKineticEnergy) {
  const auto model =
      Kr210With({{"spindle_interface", {}}, {"base_compliance", {}}, {"flange_compliance", {}}});
  ASSERT_EQ(model->num_dofs(), 22);
  const RobotModel* m = model.get();
  const Eigen::Vector3d P = m->description().end_effector.p_spindle_nose;
  // Coordinates: q (0–5), base (6–11), flange (12–17), interface (18–21).
  auto base = [](const Eigen::VectorXd& z) {
    return testing::SpringDisplacement(Eigen::Vector3d::Zero(), z.segment<3>(6), z.segment<3>(9));
  };
  auto spindle = [m, base](const Eigen::VectorXd& z) {
    return Eigen::Isometry3d(base(z) * testing::TipPose(*m, z) *
                             testing::SpringDisplacement(Eigen::Vector3d::Zero(), z.segment<3>(12),
                                                         z.segment<3>(15)));
  };
  auto holder = [spindle, P](const Eigen::VectorXd& z) {
    return Eigen::Isometry3d(spindle(z) *
                             testing::SpringDisplacement(P, Eigen::Vector3d(z(18), z(19), 0.0),
                                                         Eigen::Vector3d(z(20), z(21), 0.0)));
  };
  std::vector<testing::PosedBody> bodies = testing::LinkBodies(*m, base);
  for (const auto& b : m->end_effector_bodies()) {
    if (b.name == "holder_and_tool") bodies.push_back({b.inertial, holder});
    else bodies.push_back({b.inertial, spindle});
  }
  kinematics::Inertial foundation;
  foundation.mass = m->parameters().Get("base_compliance.foundation_mass_kg");
  foundation.inertia_com =
      m->parameters().Get("base_compliance.foundation_inertia_kgm2") * Eigen::Matrix3d::Identity();
  bodies.push_back({foundation, base});
  std::mt19937 rng(77);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(22);
  z.head(6) = RandomPosture(*m, rng);
  const PostureDynamics pd = EvaluatePosture(model, z.head(6));
  ExpectValidSystem(pd.system);
  EXPECT_LE(testing::MaxScaledDifference(pd.system.M, testing::MassFromKineticEnergy(bodies, z, 1e-5)),
            1e-7);
  const Eigen::Vector3d p_tcp = m->p_tcp();
  for (int i = 0; i < 22; ++i) {
    const double h = 1e-6;
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(22, i);
    const Eigen::Vector3d fd = (holder(z + h * e) * p_tcp - holder(z - h * e) * p_tcp) / (2 * h);
    EXPECT_LE((pd.system.B.col(i) - fd).norm(), 1e-6 * std::max(1.0, fd.norm())) << "column " << i;
  }
}

// Every effect at once (tool and tip mass on top): M SPD, K symmetric, the
// static compliance finite and larger than the rigid model's in every
// direction (each added spring is in series; gravity's small change aside,
// which is why the comparison allows 1 %), at random postures.
TEST(EffectLibrary, AllEffectsTogetherGiveAValidSystem) {
  const auto rigid = robomach::testing::Kr210();
  const auto model = Kr210With({{"tip_mass", {}}, {"tool_flexibility", {}}, {"spindle_interface", {}},
                                {"flange_compliance", {}}, {"base_compliance", {}},
                                {"gravity_stiffness", {}}, {"joint_damping", {}}});
  ASSERT_EQ(model->num_dofs(), 6 + 6 + 6 + 4 + 4);
  std::mt19937 rng(78);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const PostureDynamics pd = EvaluatePosture(model, q);
    ExpectValidSystem(pd.system);
    const PostureDynamics p0 = EvaluatePosture(rigid, q);
    for (int a = 0; a < 3; ++a) {
      EXPECT_GT(pd.static_compliance(a, a), 0.99 * p0.static_compliance(a, a));
    }
    for (const Mode& mode : pd.modes) {
      EXPECT_TRUE(std::isfinite(mode.freq_hz));
      EXPECT_GT(mode.damping_ratio, 0.0);
    }
  }
}

}  // namespace
}  // namespace robomach::dynamics
