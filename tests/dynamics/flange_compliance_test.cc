// The flange_compliance effect: the whole end effector on six springs at the
// flange, and its combination with the spindle interface.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "effect_test_support.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::ExpectValidSystem;
using robomach::testing::Kr210;
using robomach::testing::Kr210With;
using robomach::testing::RandomPosture;

kinematics::Inertial EndEffectorInertial(const RobotModel& m, const std::string& only = "") {
  kinematics::Inertial ee;
  for (const auto& b : m.end_effector_bodies()) {
    if (only.empty() || b.name == only) ee = kinematics::CombineInertials(ee, b.inertial);
  }
  return ee;
}

// Second method for M: kinetic energy of the links and of the end effector
// displaced by (u, θ) about the flange centre, by finite differences (see
// spindle_interface_test.cc for the tolerance: 1e-7 of √(M_ii M_jj)).
TEST(FlangeCompliance, MassMatrixEqualsKineticEnergyOfBodies) {
  const auto model = Kr210With({{"flange_compliance", {}}});
  ASSERT_EQ(model->num_dofs(), 12);
  std::vector<testing::PosedBody> bodies = testing::LinkBodies(*model);
  const RobotModel* m = model.get();
  bodies.push_back({EndEffectorInertial(*m), [m](const Eigen::VectorXd& z) {
                      return Eigen::Isometry3d(testing::TipPose(*m, z) *
                                               testing::SpringDisplacement(Eigen::Vector3d::Zero(),
                                                                           z.segment<3>(6),
                                                                           z.segment<3>(9)));
                    }});
  std::mt19937 rng(6);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd z = Eigen::VectorXd::Zero(12);
    z.head(6) = RandomPosture(*model, rng);
    const PostureDynamics pd = EvaluatePosture(model, z.head(6));
    ExpectValidSystem(pd.system);
    EXPECT_LE(testing::MaxScaledDifference(pd.system.M, testing::MassFromKineticEnergy(bodies, z, 1e-5)), 1e-7);
  }
}

// Flange and spindle interface together, listed in the "wrong" order in the
// config: the model applies them base-to-tool (EffectStage), so the holder
// rides on the interface springs, which ride on the flange springs. The
// kinetic energy of the nested bodies (spindle displaced at the flange,
// holder displaced again at the gauge line) checks the coupling of all 16
// coordinates (tolerance as above).
TEST(FlangeCompliance, NestsWithTheSpindleInterfaceInPhysicalOrder) {
  const auto model = Kr210With({{"spindle_interface", {}}, {"flange_compliance", {}}});
  ASSERT_EQ(model->num_dofs(), 16);
  EXPECT_EQ(model->effects()[0].effect->name(), "flange_compliance");
  const Eigen::Vector3d P = model->description().end_effector.p_spindle_nose;
  const RobotModel* m = model.get();
  auto flange = [m](const Eigen::VectorXd& z) {
    return Eigen::Isometry3d(testing::TipPose(*m, z) *
                             testing::SpringDisplacement(Eigen::Vector3d::Zero(), z.segment<3>(6),
                                                         z.segment<3>(9)));
  };
  std::vector<testing::PosedBody> bodies = testing::LinkBodies(*model);
  bodies.push_back({EndEffectorInertial(*m, "spindle_and_bracket"), flange});
  bodies.push_back({EndEffectorInertial(*m, "holder_and_tool"), [flange, P](const Eigen::VectorXd& z) {
                      return Eigen::Isometry3d(
                          flange(z) * testing::SpringDisplacement(P, Eigen::Vector3d(z(12), z(13), 0.0),
                                                                  Eigen::Vector3d(z(14), z(15), 0.0)));
                    }});
  std::mt19937 rng(7);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(16);
  z.head(6) = RandomPosture(*model, rng);
  const PostureDynamics pd = EvaluatePosture(model, z.head(6));
  ExpectValidSystem(pd.system);
  EXPECT_LE(testing::MaxScaledDifference(pd.system.M, testing::MassFromKineticEnergy(bodies, z, 1e-5)), 1e-7);
  // The tool tip moves with the holder: B's interface columns are the
  // holder's, its flange columns the end effector's (finite differences of
  // the TCP, same step and tolerance argument, relative to the tip speed).
  const Eigen::Vector3d p_tcp_tip = m->p_tcp();
  for (int i = 0; i < 16; ++i) {
    const double h = 1e-6;
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(16, i);
    auto tip = [&](const Eigen::VectorXd& zz) { return Eigen::Vector3d(bodies.back().pose(zz) * p_tcp_tip); };
    const Eigen::Vector3d fd = (tip(z + h * e) - tip(z - h * e)) / (2 * h);
    EXPECT_LE((pd.system.B.col(i) - fd).norm(), 1e-6 * std::max(1.0, fd.norm())) << "column " << i;
  }
}

// Static superposition at the tip: H(0) = J Kq⁻¹ Jᵀ + G K_f⁻¹ Gᵀ with G the
// hand-derived tip translation per flange DOF in the flange axes,
// [I₃  −[p_tcp]×] (a rotation θ about the flange centre moves the tip at
// p_tcp by θ × p_tcp). Rounding as in the interface test: 1e-9.
TEST(FlangeCompliance, StaticComplianceIsJointPlusFlangeSeries) {
  const auto rigid = Kr210();
  const auto model = Kr210With({{"flange_compliance", {}}});
  const Eigen::VectorXd kf = (Eigen::VectorXd(6) << 5e8, 5e8, 1e9, 2e6, 2e6, 2e6).finished();
  const Eigen::Vector3d p = model->p_tcp();
  Eigen::Matrix<double, 3, 6> G;
  G << 1, 0, 0, 0, p.z(), -p.y(),
       0, 1, 0, -p.z(), 0, p.x(),
       0, 0, 1, p.y(), -p.x(), 0;
  std::mt19937 rng(9);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const PostureDynamics p0 = EvaluatePosture(rigid, q);
    const PostureDynamics p1 = EvaluatePosture(model, q);
    const Eigen::Matrix3d R = p1.X_BT.linear();
    const Eigen::Matrix3d expected =
        p0.static_compliance + R * G * kf.cwiseInverse().asDiagonal() * G.transpose() * R.transpose();
    EXPECT_LE((p1.static_compliance - expected).norm(), 1e-9 * expected.norm());
  }
}

// Momentum consistency: a rigid translation of the whole end effector on its
// springs carries the end effector's total mass, M[u,u] = m_ee I, and a
// rigid rotation about the flange its inertia about the flange centre
// (parallel-axis theorem), both expressed in the flange axes. Exact up to
// rounding (1e-12).
TEST(FlangeCompliance, ExtraBlockIsTheEndEffectorsSpatialInertia) {
  const auto model = Kr210With({{"flange_compliance", {}}});
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.2, -1.0, 1.2, 0.3, 0.8, -0.2).finished();
  const PostureDynamics pd = EvaluatePosture(model, q);
  const kinematics::Inertial ee = EndEffectorInertial(*model);
  const Eigen::MatrixXd Mr = pd.system.M.bottomRightCorner(6, 6);
  EXPECT_LE((Mr.topLeftCorner<3, 3>() - ee.mass * Eigen::Matrix3d::Identity()).norm(), 1e-12 * ee.mass);
  const Eigen::Vector3d c = ee.com;
  const Eigen::Matrix3d I_flange =
      ee.inertia_com + ee.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  EXPECT_LE((Mr.bottomRightCorner<3, 3>() - I_flange).norm(), 1e-12 * I_flange.norm());
}

// Stiff limit: with all flange stiffnesses ×10 and ×100 the robot's modes
// converge to the rigid model's, the shift falling ≈ tenfold (0.15 allows
// for the second-order term).
TEST(FlangeCompliance, ConvergesToTheRigidModelWhenStiff) {
  auto scaled = [](double s) {
    return Kr210With({{"flange_compliance",
                       {{"lateral_stiffness_N_per_m", 5e8 * s}, {"axial_stiffness_N_per_m", 1e9 * s},
                        {"bending_stiffness_Nm_per_rad", 2e6 * s},
                        {"torsional_stiffness_Nm_per_rad", 2e6 * s}}}});
  };
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.3, -1.2, 1.4, 0.5, 0.9, -0.4).finished();
  const PostureDynamics p0 = EvaluatePosture(Kr210(), q);
  const PostureDynamics p10 = EvaluatePosture(scaled(10.0), q);
  const PostureDynamics p100 = EvaluatePosture(scaled(100.0), q);
  for (int k = 0; k < 6; ++k) {
    const double d10 = p0.modes[k].freq_hz - p10.modes[k].freq_hz;
    const double d100 = p0.modes[k].freq_hz - p100.modes[k].freq_hz;
    EXPECT_GE(d10, -1e-9 * p0.modes[k].freq_hz);
    EXPECT_LE(std::abs(d100), 0.15 * std::abs(d10) + 1e-9 * p0.modes[k].freq_hz) << "mode " << k;
  }
}

}  // namespace
}  // namespace robomach::dynamics
