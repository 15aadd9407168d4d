// Named parameters and the m6/d6 rule of EndEffector.
#include <gtest/gtest.h>
#include <gmock/gmock.h>

#include "robomach/dynamics/posture_dynamics.h"
#include "test_models.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::CaptureError;
using robomach::testing::Kr210Config;
using ::testing::HasSubstr;

TEST(Parameters, DefaultNamesCarryUnitsAndComeFromTheConfig) {
  const io::RobotConfig cfg = Kr210Config();
  const ParameterSet& p = cfg.parameters;
  EXPECT_EQ(p.NameList(),
            "kq1_Nm_per_rad, kq2_Nm_per_rad, kq3_Nm_per_rad, kq4_Nm_per_rad, kq5_Nm_per_rad, "
            "kq6_Nm_per_rad, m6_kg, d6_m, alpha_s, beta_per_s");
  EXPECT_DOUBLE_EQ(p.Get("kq2_Nm_per_rad"), 3.1318e6);
  EXPECT_DOUBLE_EQ(p.Get("alpha_s"), 1e-4);
  EXPECT_DOUBLE_EQ(p.Get("beta_per_s"), 5.0);
  // The reference values the geometry defines (kr210_reference.yaml: 6.6 +
  // 22.0 + 0.45 kg and 0.215 + 0.335 m).
  EXPECT_NEAR(p.Get("m6_kg"), 29.05, 1e-12);
  EXPECT_NEAR(p.Get("d6_m"), 0.550, 1e-12);
}

TEST(Parameters, UnknownNamesAndOutOfBoundValuesAreRejectedWithTheReason) {
  ParameterSet p = Kr210Config().parameters;
  EXPECT_THAT(CaptureError([&] { p.Get("m7_kg"); }),
              HasSubstr("unknown parameter 'm7_kg'; known: kq1_Nm_per_rad"));
  EXPECT_THAT(CaptureError([&] { p.Set("m6_kg", -3.0); }),
              HasSubstr("parameter 'm6_kg': -3 kg is outside its bounds [2.905, 290.5]"));
  EXPECT_THAT(CaptureError([&] { p.Set("alpha_s", NAN); }), HasSubstr("alpha_s"));
}

// The m6 rule: the last link and end-effector masses scale with m6, so the
// total mass of the segments from joint 6 outwards equals m6; inertias about
// COMs scale by the same factor and COMs stay.
TEST(M6D6Rule, MassScalesTheLastLinkAndEndEffector) {
  io::RobotConfig cfg = Kr210Config();
  cfg.parameters.Set("m6_kg", 35.0);
  const auto model = cfg.Build();
  const auto& chain = model->chain();
  double m = 0.0;
  for (int s = chain.last_moving_segment(); s < chain.num_segments(); ++s) {
    m += chain.segment_inertial(s).mass;
  }
  EXPECT_NEAR(m, 35.0, 1e-12);
  const auto ref = Kr210Config().Build();
  const int ee = chain.num_segments() - 2;  // the end_effector segment
  const auto a = chain.segment_inertial(ee), b = ref->chain().segment_inertial(ee);
  EXPECT_NEAR(a.mass / b.mass, 35.0 / 29.05, 1e-12);
  EXPECT_LE((a.com - b.com).norm(), 1e-12);
  EXPECT_LE((a.inertia_com - b.inertia_com * (35.0 / 29.05)).norm(), 1e-12);
}

// The d6 rule: the TCP moves by Δd6 along the joint-6 axis (away from the
// wrist), so at any posture p_BT(d6 + Δ) − p_BT(d6) = Δ · (joint-6 axis in B);
// the end-effector COM moves by Δ · h_com / h_tcp.
TEST(M6D6Rule, LengthMovesTheTipAlongTheLastJointAxis) {
  io::RobotConfig cfg = Kr210Config();
  constexpr double kDelta = 0.04;  // [m]
  cfg.parameters.Set("d6_m", 0.55 + kDelta);
  const auto longer = cfg.Build();
  const auto ref = Kr210Config().Build();
  Eigen::VectorXd q(6);
  q << 0.3, -1.2, 1.4, 0.5, 0.8, -0.4;
  const auto d_long = EvaluatePosture(longer, q);
  const auto d_ref = EvaluatePosture(ref, q);
  const Eigen::Vector3d axis_B = d_ref.X_BT.linear() * ToolAxisInTip(cfg.description);
  EXPECT_LE((d_long.X_BT.translation() - d_ref.X_BT.translation() - kDelta * axis_B).norm(), 1e-12);
  // tool0's z is the tool axis; the end-effector COM (22.45 kg composite at
  // z = (22·0.110 + 0.45·0.290)/22.45) stretches with the TCP (h_tcp = 0.335 m).
  const int ee = longer->chain().num_segments() - 2;
  const double z_ref = (22.0 * 0.110 + 0.45 * 0.290) / 22.45;
  EXPECT_NEAR(longer->chain().segment_inertial(ee).com.z(), z_ref * (0.335 + kDelta) / 0.335, 1e-12);
  // A longer lever: lower static stiffness at the tip.
  EXPECT_GT(d_long.static_compliance.trace(), d_ref.static_compliance.trace());
}

}  // namespace
}  // namespace robomach::dynamics
