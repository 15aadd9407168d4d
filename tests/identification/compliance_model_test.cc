#include "robomach/identification/compliance_model.h"

#include <cmath>

#include <gmock/gmock.h>
#include <yaml-cpp/yaml.h>
#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/identification/load_case.h"
#include "robomach/kinematics/serial_chain.h"
#include "test_campaign.h"

namespace robomach::identification {
namespace {

using testing::CaptureError;
using testing::Kr210;
using ::testing::HasSubstr;

Eigen::VectorXd Deg(std::initializer_list<double> d) {
  Eigen::VectorXd q(static_cast<int>(d.size()));
  int i = 0;
  for (double v : d) q(i++) = DegToRad(v);
  return q;
}

// Three non-singular test postures (θ5 away from 0, elbow bent).
std::vector<Eigen::VectorXd> Postures() {
  return {Deg({0, -90, 90, 0, 45, 0}), Deg({30, -60, 100, 10, -40, 20}),
          Deg({-25, -110, 70, 60, 80, -120})};
}

// ShiftJacobian against KDL: the Jacobian of a fixed segment appended at
// r (SerialChain::WithFixedSegment), an independent computation of the same
// point's velocity. Both are one chain of frame products; the difference is
// rounding, ~1e2·eps·|J| ≈ 1e-13 m/rad for |J| ≈ 3 m/rad; 1e-11 leaves margin.
TEST(ComplianceModel, ShiftJacobianMatchesKdlFixedSegment) {
  const auto model = Kr210();
  const auto& arm = model->description().arm;
  const Eigen::Vector3d p_tip(0.15, -0.07, 0.2);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = p_tip;
  const auto longer = arm.WithFixedSegment("probe", X, kinematics::Inertial{});
  for (const auto& q : Postures()) {
    const Eigen::Isometry3d X_B_tip = kinematics::ForwardKinematics(arm, q);
    const Matrix6Xd J = ShiftJacobian(kinematics::Jacobian(arm, q), X_B_tip.linear() * p_tip);
    const Matrix6Xd J_ref = kinematics::Jacobian(longer, q);
    EXPECT_LT((J - J_ref).cwiseAbs().maxCoeff(), 1e-11) << q.transpose();
  }
}

// Translational Jacobians of the load point and target against central
// differences of their positions: error h²·R/6 + δ/h with R ≈ 3 m and
// δ ≈ 1e-13 m, minimal near h = 5e-5 rad at ~2e-9 m/rad; 1e-7 keeps 50×.
TEST(ComplianceModel, PointJacobiansMatchFiniteDifferences) {
  const auto model = Kr210();
  LoadCase c;
  c.p_load_tip = Eigen::Vector3d(0.15, 0.0, 0.1);
  c.p_target_tip = Eigen::Vector3d(0.0, 0.12, 0.05);
  const double h = 5e-5;
  for (const auto& q : Postures()) {
    c.q = q;
    const CaseKinematics k = EvaluateCaseKinematics(*model, c);
    for (int j = 0; j < 6; ++j) {
      LoadCase cp = c, cm = c;
      cp.q(j) += h;
      cm.q(j) -= h;
      const CaseKinematics kp = EvaluateCaseKinematics(*model, cp);
      const CaseKinematics km = EvaluateCaseKinematics(*model, cm);
      EXPECT_LT(((kp.p_BL - km.p_BL) / (2 * h) - k.Jv_L.col(j)).norm(), 1e-7) << "joint " << j + 1;
      EXPECT_LT(((kp.p_BT - km.p_BT) / (2 * h) - k.Jv_T.col(j)).norm(), 1e-7) << "joint " << j + 1;
    }
  }
}

// With load point = target = TCP the model is the translational block of the
// Cartesian compliance J K⁻¹ Jᵀ, which the dynamics module computes by a
// different route (H_T(0) = B K⁻¹ Bᵀ from the assembled system, LDLT solve).
// Both are exact; the difference is rounding relative to |D| (cond(K) ≈ 20
// times eps, ~1e-14); 1e-10 relative leaves margin.
TEST(ComplianceModel, TcpModelMatchesDynamicsStaticCompliance) {
  const auto model = Kr210();
  dynamics::PostureEvaluator ev(model);
  const Eigen::Vector3d F(120.0, -80.0, -250.0);
  for (const auto& q : Postures()) {
    LoadCase c;
    c.q = q;
    c.force = F;
    const Eigen::Vector3d D = PredictDisplacement(*model, c, model->joint_stiffness());
    const Eigen::Vector3d D_ref = ev.Evaluate(q).static_compliance * F;
    EXPECT_LT((D - D_ref).norm(), 1e-10 * D_ref.norm()) << q.transpose();
  }
}

// Published check values (tests/data/kr210_reference.yaml, `check_values`,
// computed with Pinocchio from exactly this model; 7 significant digits, so
// 1e-6 relative rounding): the diagonal static compliance at the TCP. With
// load point = target = TCP and a unit force along axis a, D_a is that entry.
TEST(ComplianceModel, TcpModelMatchesPublishedStaticCompliance) {
  const auto model = Kr210();
  const YAML::Node root = YAML::LoadFile(testing::SourcePath("tests/data/kr210_reference.yaml"));
  int checked = 0;
  for (const auto& kv : root["check_values"]) {
    const auto deg = root["postures_deg"][kv.first.as<std::string>()].as<std::vector<double>>();
    const auto ref = kv.second["static_compliance_xx_yy_zz_m_per_N"].as<std::vector<double>>();
    LoadCase c;
    c.q.resize(6);
    for (int j = 0; j < 6; ++j) c.q(j) = DegToRad(deg[j]);
    for (int a = 0; a < 3; ++a) {
      c.force = Eigen::Vector3d::Unit(a);
      const Eigen::Vector3d D = PredictDisplacement(*model, c, model->joint_stiffness());
      EXPECT_NEAR(D(a), ref[a], 2e-6 * ref[a]) << kv.first << " axis " << a;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 15);
}

// The linear model (1) against the large-displacement static equilibrium
// (second method). Their difference is second order: the Jacobians change by
// ~|Δq|·R per radian over the deflection, so |D_lin − D_eq| ≲ |Δq|²·R with
// R ≈ 3.5 m (the KR210's largest distance from any axis to the target).
// Halving the load must therefore quarter the difference relative to |D|'s
// halving: the ratio of the relative errors is 2 (we allow 1.6..2.4 for the
// third-order term).
TEST(ComplianceModel, LinearModelMatchesStaticEquilibriumToSecondOrder) {
  const auto model = Kr210();
  const Eigen::VectorXd kq = model->joint_stiffness();
  for (const auto& q : Postures()) {
    LoadCase c;
    c.q = q;
    c.p_load_tip = Eigen::Vector3d(0.15, 0.0, 0.1);
    c.p_target_tip = Eigen::Vector3d(0.0, 0.12, 0.05);
    c.force = RopeForce(30.0, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, 0.4, -1.0));
    const CaseKinematics k = EvaluateCaseKinematics(*model, c);
    const Eigen::VectorXd dq = (k.Jv_L.transpose() * c.force).cwiseQuotient(kq);
    const Eigen::Vector3d D_lin = PredictDisplacement(*model, c, kq);
    const Eigen::Vector3d D_eq = SolveStaticDeflection(*model, c, kq);
    const double err = (D_lin - D_eq).norm();
    EXPECT_LT(err, dq.squaredNorm() * 3.5) << q.transpose();
    EXPECT_GT(D_lin.norm(), 1e-5);  // the check is not vacuous: D ≈ 0.1 mm and more
    LoadCase half = c;
    half.force *= 0.5;
    const double err_half =
        (PredictDisplacement(*model, half, kq) - SolveStaticDeflection(*model, half, kq)).norm();
    const double ratio = (err / D_lin.norm()) / (err_half / (0.5 * D_lin.norm()));
    EXPECT_GT(ratio, 1.6);
    EXPECT_LT(ratio, 2.4);
  }
}

// D is linear in the compliances: D(k) = A c exactly (the identification's
// start relies on it). Checked by superposition against PredictDisplacement
// with one joint at a time made compliant: the sum of the six single-joint
// displacements is the full one, to rounding (1e-12 relative).
TEST(ComplianceModel, DisplacementIsLinearInCompliances) {
  const auto model = Kr210();
  LoadCase c;
  c.q = Postures()[1];
  c.p_load_tip = Eigen::Vector3d(0.15, 0.0, 0.1);
  c.p_target_tip = Eigen::Vector3d(0.0, 0.12, 0.05);
  c.force = Eigen::Vector3d(50, 60, -200);
  const Eigen::VectorXd kq = model->joint_stiffness();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int j = 0; j < 6; ++j) {
    Eigen::VectorXd k1 = Eigen::VectorXd::Constant(6, 1e300);  // other joints rigid
    k1(j) = kq(j);
    sum += PredictDisplacement(*model, c, k1);
  }
  const Eigen::Vector3d full = PredictDisplacement(*model, c, kq);
  EXPECT_LT((sum - full).norm(), 1e-12 * full.norm());
}

// formats.md §2: F = mass_kg · 9.80665 N along the unit vector from A to B.
// A 3-4-5 triangle makes the unit vector exact: (0.6, 0, −0.8).
TEST(RopeForce, MassTimesStandardGravityAlongAToB) {
  const Eigen::Vector3d F = RopeForce(20.0, Eigen::Vector3d(1.0, 2.0, 3.0),
                                      Eigen::Vector3d(1.3, 2.0, 2.6));
  const Eigen::Vector3d expected = 20.0 * 9.80665 * Eigen::Vector3d(0.6, 0.0, -0.8);
  EXPECT_LT((F - expected).norm(), 1e-12 * expected.norm());
  // The sense is A -> B: swapping the points flips the force.
  EXPECT_LT((RopeForce(20.0, Eigen::Vector3d(1.3, 2.0, 2.6), Eigen::Vector3d(1.0, 2.0, 3.0)) + expected).norm(),
            1e-12 * expected.norm());
}

TEST(RopeForce, ZeroRopeVectorIsAnError) {
  EXPECT_THAT(CaptureError([] { RopeForce(10.0, Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1)); }),
              HasSubstr("rope points A and B coincide"));
}

TEST(RopeForce, ToLoadCaseUsesRopeFormAndDisplacement) {
  TrackerMeasurement m;
  m.case_id = "C1";
  m.q = Eigen::VectorXd::Zero(6);
  m.p0 = Eigen::Vector3d(1.0, 0.0, 1.0);
  m.p1 = Eigen::Vector3d(1.0, 0.0, 0.9995);
  m.mass_kg = 10.0;
  m.rope_A = Eigen::Vector3d(1.0, 0.0, 0.9);
  m.rope_B = Eigen::Vector3d(1.0, 0.0, 0.4);
  const LoadCase c = ToLoadCase(m);
  EXPECT_NEAR(c.force.z(), -98.0665, 1e-12);
  EXPECT_NEAR(c.displacement.z(), -0.0005, 1e-15);
}

}  // namespace
}  // namespace robomach::identification
