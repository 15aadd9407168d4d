// The effect mechanism and the tip-mass effect.
#include <gtest/gtest.h>
#include <gmock/gmock.h>

#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "test_models.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::CaptureError;
using robomach::testing::Kr210Config;
using robomach::testing::RandomPosture;
using ::testing::HasSubstr;

TEST(EffectRegistry, ListsTheTipMassAndNamesAlternativesForUnknownEffects) {
  const auto names = EffectRegistry::Instance().Names();
  EXPECT_THAT(names, ::testing::Contains("tip_mass"));
  EXPECT_THAT(CaptureError([] { EffectRegistry::Instance().Create("tip_mas"); }),
              ::testing::AllOf(HasSubstr("unknown effect 'tip_mas': expected "), HasSubstr("tip_mass"),
                               HasSubstr("; or of a family: "),
                               HasSubstr("virtual_joint_<place>_<axis> (place: base, link1..linkN"),
                               HasSubstr("load_stiffness_j<joint> (joint: 1..N)")));
}

TEST(EffectParameters, AreExposedWithThePrefixAndChecked) {
  io::RobotConfig cfg = Kr210Config();
  cfg.description.effects.push_back({"tip_mass", {{"mass_kg", 0.05}}});
  const ParameterSet p = DefaultParameters(cfg.description);
  EXPECT_DOUBLE_EQ(p.Get("tip_mass.mass_kg"), 0.05);
  ParameterSet q = p;
  EXPECT_THAT(CaptureError([&] { q.Set("tip_mass.mass_kg", -1.0); }),
              HasSubstr("tip_mass.mass_kg': -1 kg is outside its bounds [0, 5]"));
  cfg.description.effects.back().values = {{"mass_g", 5.0}};
  EXPECT_THAT(CaptureError([&] { DefaultParameters(cfg.description); }),
              HasSubstr("effect 'tip_mass' has no parameter 'mass_g'; its parameters: mass_kg"));
}

// Closed form: a point mass m at the tool tip adds m J_vᵀ J_v to M_q.
// Second method: the same mass as a rigid body of the chain at the TCP, so
// that KDL's composite-rigid-body algorithm includes it. Both agree to
// rounding (1e-10 relative of M_q).
TEST(TipMass, MatchesClosedFormAndAPointMassBodyInTheChain) {
  constexpr double kMass = 0.25;  // [kg], a heavy triaxial accelerometer with cable
  io::RobotConfig with_effect = Kr210Config();
  with_effect.description.effects.push_back({"tip_mass", {{"mass_kg", kMass}}});
  io::RobotConfig with_body = Kr210Config();
  EndEffectorBody point;
  point.name = "accelerometer";
  point.inertial.mass = kMass;
  point.inertial.com = with_body.description.end_effector.p_tcp;
  with_body.description.end_effector.bodies.push_back(point);
  const auto base = Kr210Config().Build();
  const auto a = RobotModel::Build(with_effect.description, DefaultParameters(with_effect.description));
  const auto b = RobotModel::Build(with_body.description, DefaultParameters(with_body.description));
  std::mt19937 rng(31);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*base, rng);
    const PostureDynamics d0 = EvaluatePosture(base, q);
    const PostureDynamics da = EvaluatePosture(a, q);
    const PostureDynamics db = EvaluatePosture(b, q);
    const Eigen::MatrixXd Jv = d0.J_BT.topRows<3>();
    const Eigen::MatrixXd closed = d0.M_q() + kMass * Jv.transpose() * Jv;
    const double scale = d0.M_q().cwiseAbs().maxCoeff();
    EXPECT_LE((da.M_q() - closed).cwiseAbs().maxCoeff(), 1e-10 * scale);
    EXPECT_LE((db.M_q() - closed).cwiseAbs().maxCoeff(), 1e-10 * scale);
    // Added mass lowers every natural frequency (Rayleigh's monotonicity).
    for (size_t k = 0; k < d0.modes.size(); ++k) EXPECT_LT(da.modes[k].freq_hz, d0.modes[k].freq_hz);
  }
}

}  // namespace
}  // namespace robomach::dynamics
