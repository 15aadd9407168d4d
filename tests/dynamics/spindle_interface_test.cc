// The spindle_interface effect: the holder on the condensed taper-contact
// springs at the gauge line, coupled to the robot.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynamics/internal/taper_contact.h"
#include "effect_test_support.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::ExpectValidSystem;
using robomach::testing::Kr210;
using robomach::testing::Kr210With;
using robomach::testing::RandomPosture;

const EndEffectorBody& Body(const RobotModel& m, const std::string& name) {
  for (const auto& b : m.end_effector_bodies()) {
    if (b.name == name) return b;
  }
  throw std::runtime_error("no body " + name);
}

// Second method for the whole mass matrix: the kinetic energy of the links,
// the spindle (rigid with the flange) and the holder (displaced by
// (u_x, u_y, θ_x, θ_y) about the gauge line in the flange axes), from
// finite-differenced poses; it uses neither KDL's inertia matrix nor the
// effect's assembly. Central differences with h = 1e-5: truncation
// ≈ h²·|∂³x| ≈ 1e-10 and round-off ≈ eps·2 m/h ≈ 2e-11 relative to the
// velocities, so the entries agree to ≈ 1e-9 of √(M_ii M_jj); 1e-7 leaves
// margin.
TEST(SpindleInterface, MassMatrixEqualsKineticEnergyOfBodies) {
  const auto model = Kr210With({{"spindle_interface", {}}});
  ASSERT_EQ(model->num_dofs(), 10);
  const Eigen::Vector3d P = model->description().end_effector.p_spindle_nose;
  std::vector<testing::PosedBody> bodies = testing::LinkBodies(*model);
  const RobotModel* m = model.get();
  bodies.push_back({Body(*m, "spindle_and_bracket").inertial,
                    [m](const Eigen::VectorXd& z) { return testing::TipPose(*m, z); }});
  bodies.push_back({Body(*m, "holder_and_tool").inertial, [m, P](const Eigen::VectorXd& z) {
                      return Eigen::Isometry3d(
                          testing::TipPose(*m, z) *
                          testing::SpringDisplacement(P, Eigen::Vector3d(z(6), z(7), 0.0),
                                                      Eigen::Vector3d(z(8), z(9), 0.0)));
                    }});
  std::mt19937 rng(5);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd z = Eigen::VectorXd::Zero(10);
    z.head(6) = RandomPosture(*model, rng);
    const PostureDynamics pd = EvaluatePosture(model, z.head(6));
    ExpectValidSystem(pd.system);
    const Eigen::MatrixXd M_fd = testing::MassFromKineticEnergy(bodies, z, 1e-5);
    EXPECT_LE(testing::MaxScaledDifference(pd.system.M, M_fd), 1e-7) << "trial " << trial;
  }
}

// Static superposition: the interface springs are in series with the joints,
// so H(0) gains exactly G K_i⁻¹ Gᵀ, with G the tool-tip translation per
// interface DOF derived by hand: a tilt about the gauge line moves the tip,
// ℓ = |p_T − p_N| further along the spindle axis z, by
// (ℓ θ_y, −ℓ θ_x, 0) in the flange axes. Rounding: cond(K) ≈ 1e8/1e4 in
// these units, so ~1e4·eps ≈ 2e-12 of |H|; 1e-9 leaves margin.
TEST(SpindleInterface, StaticComplianceAddsInterfaceComplianceAtTheTip) {
  const auto rigid = Kr210();
  const auto model = Kr210With({{"spindle_interface", {{"translational_scale", 2.0}}}});
  const internal::TaperContact tc = internal::ComputeTaperContact({});
  Eigen::Matrix4d K_i = tc.K_master;
  const Eigen::Vector4d D(std::sqrt(2.0), std::sqrt(2.0), 1.0, 1.0);
  K_i = D.asDiagonal() * K_i * D.asDiagonal();
  const double ell = model->p_TN().norm();
  Eigen::Matrix<double, 3, 4> G;
  G << 1, 0, 0, ell, 0, 1, -ell, 0, 0, 0, 0, 0;
  std::mt19937 rng(8);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const PostureDynamics p0 = EvaluatePosture(rigid, q);
    const PostureDynamics p1 = EvaluatePosture(model, q);
    const Eigen::Matrix3d R = p1.X_BT.linear();
    const Eigen::Matrix3d expected =
        p0.static_compliance + R * G * K_i.inverse() * G.transpose() * R.transpose();
    EXPECT_LE((p1.static_compliance - expected).norm(), 1e-9 * expected.norm());
  }
}

// Stiff limit: with both scales s the interface compliance falls as 1/s, so
// the robot's six modes converge to the rigid model's with a shift that
// falls tenfold from s = 10 to s = 100 (first order in 1/s; 0.15 allows for
// the second-order term), and the direct FRF below 300 Hz converges too.
TEST(SpindleInterface, ConvergesToTheRigidModelWhenStiff) {
  const auto rigid = Kr210();
  const auto s10 = Kr210With({{"spindle_interface", {{"translational_scale", 10.0}, {"tilting_scale", 10.0}}}});
  const auto s100 = Kr210With({{"spindle_interface", {{"translational_scale", 100.0}, {"tilting_scale", 100.0}}}});
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.3, -1.2, 1.4, 0.5, 0.9, -0.4).finished();
  const PostureDynamics p0 = EvaluatePosture(rigid, q);
  const PostureDynamics p10 = EvaluatePosture(s10, q);
  const PostureDynamics p100 = EvaluatePosture(s100, q);
  for (int k = 0; k < 6; ++k) {
    const double d10 = p0.modes[k].freq_hz - p10.modes[k].freq_hz;
    const double d100 = p0.modes[k].freq_hz - p100.modes[k].freq_hz;
    EXPECT_GE(d10, -1e-9 * p0.modes[k].freq_hz) << "added compliance cannot raise mode " << k;
    EXPECT_LE(std::abs(d100), 0.15 * std::abs(d10) + 1e-9 * p0.modes[k].freq_hz) << "mode " << k;
  }
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(60, 5.0, 300.0);
  const auto H0 = ReceptanceDirect(p0.system, f);
  const auto H10 = ReceptanceDirect(p10.system, f);
  const auto H100 = ReceptanceDirect(p100.system, f);
  double e10 = 0.0, e100 = 0.0;
  for (int i = 0; i < f.size(); ++i) {
    e10 = std::max(e10, (H10[i] - H0[i]).norm() / H0[i].norm());
    e100 = std::max(e100, (H100[i] - H0[i]).norm() / H0[i].norm());
  }
  EXPECT_LT(e100, 0.15 * e10);
}

// The holder's own modes: at scale 1 the interface adds four DOFs whose
// modes lie far above the robot's (the holder's 0.45 kg on ≈ 8e7 N/m and
// its tilt on ≈ 1e4 N·m/rad: several hundred hertz to kilohertz), and the
// config section's values are used (a changed drawbar force changes K).
TEST(SpindleInterface, AddsHolderModesAndReadsTheConfigSection) {
  const auto model = Kr210With({{"spindle_interface", {}}});
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.0, -1.57, 1.57, 0.0, 0.785, 0.0).finished();
  const PostureDynamics pd = EvaluatePosture(model, q);
  ASSERT_EQ(pd.modes.size(), 10u);
  EXPECT_GT(pd.modes[6].freq_hz, 300.0);
  io::RobotConfig cfg = testing::Kr210Config();
  cfg.description.effects.push_back({"spindle_interface", {}});
  cfg.description.extra_values["spindle_toolholder_interface.drawbar_force_N"] = 20000.0;
  const auto harder = RobotModel::Build(cfg.description, DefaultParameters(cfg.description));
  const PostureDynamics ph = EvaluatePosture(harder, q);
  EXPECT_GT(ph.modes[6].freq_hz, pd.modes[6].freq_hz);  // more pressure, stiffer (β' > 0)
  cfg.description.extra_values["spindle_toolholder_interface.drawbar_force"] = 1.0;
  const auto bad = RobotModel::Build(cfg.description, DefaultParameters(cfg.description));
  EXPECT_THROW(EvaluatePosture(bad, q), std::invalid_argument);
}

// A tip mass listed before the interface in the config still sits on the
// holder: effects apply base-to-tool (EffectStage), so tip_mass sees B with
// the interface columns and adds m BᵀB over all ten coordinates (closed
// form of tip_mass; exact up to rounding, 1e-12 of max|M|).
TEST(SpindleInterface, TipMassRidesOnTheHolder) {
  const auto holder = Kr210With({{"spindle_interface", {}}});
  const auto both = Kr210With({{"tip_mass", {{"mass_kg", 0.05}}}, {"spindle_interface", {}}});
  EXPECT_EQ(both->effects().back().effect->name(), "tip_mass");
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.1, -1.1, 1.3, 0.2, 0.7, 0.1).finished();
  const PostureDynamics p0 = EvaluatePosture(holder, q);
  const PostureDynamics p1 = EvaluatePosture(both, q);
  const Eigen::MatrixXd expected = p0.system.M + 0.05 * p0.system.B.transpose() * p0.system.B;
  EXPECT_LE((p1.system.M - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_GT((0.05 * p0.system.B.rightCols(4).transpose() * p0.system.B.rightCols(4)).norm(), 0.0);
}

}  // namespace
}  // namespace robomach::dynamics
