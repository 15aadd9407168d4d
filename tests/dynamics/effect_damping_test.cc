// The damping of the effects' own modes: a mounted body (holder, end
// effector, the robot on its foundation) or the tool's bending modes get the
// effect's damping ratio ζ, not the model's Rayleigh α ω/2.
#include <cmath>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "effect_test_support.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::Kr210Config;

struct Case {
  const char* effect;
  int num_dofs;  // the effect's extra DOFs, the last of the system
};

// With the robot held (its coordinates fixed), the effect's DOFs r form the
// system (M_rr, C_rr, K_rr). The effect makes its damping classical there:
// with the mass-normalised modes Φ of (K_rr, M_rr),
//   Φᵀ C_rr Φ = diag(2 ζ ω_i + β)
// (ζ from the effect's own M Φ diag(2ζω) Φᵀ M [Chopra 2012, §11.4], β from
// the model's β M; the model's α K_rr is cancelled), so each mode has the
// ratio ζ + β/(2ω_i). The products round at ≈ 1e-14 of the largest
// diagonal term; 1e-9 relative per entry of Φᵀ C Φ.
TEST(EffectDamping, OwnModesHaveTheEffectsDampingRatioWithTheRobotHeld) {
  for (const Case c : {Case{"spindle_interface", 4}, Case{"flange_compliance", 6},
                       Case{"base_compliance", 6}, Case{"tool_flexibility", 4}}) {
    constexpr double kZeta = 0.037;
    const auto model = testing::Kr210With({{c.effect, {{"damping_ratio", kZeta}}}});
    const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.2, -1.2, 1.5, 0.3, 0.8, -0.5).finished();
    const PostureDynamics pd = EvaluatePosture(model, q);
    testing::ExpectValidSystem(pd.system);
    EXPECT_FALSE(pd.proportional_damping);
    const int k = c.num_dofs, N = model->num_dofs();
    ASSERT_EQ(N, 6 + k);
    const Eigen::MatrixXd M = pd.system.M.bottomRightCorner(k, k);
    const Eigen::MatrixXd K = pd.system.K.bottomRightCorner(k, k);
    const Eigen::MatrixXd C = pd.system.C.bottomRightCorner(k, k);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(K, M);
    const Eigen::MatrixXd Phi = ges.eigenvectors();
    const Eigen::MatrixXd modal = Phi.transpose() * C * Phi;
    const double beta = model->beta();
    for (int i = 0; i < k; ++i) {
      const double w = std::sqrt(ges.eigenvalues()(i));
      const double expected = 2.0 * kZeta * w + beta;
      for (int j = 0; j < k; ++j) {
        EXPECT_NEAR(modal(i, j), i == j ? expected : 0.0, 1e-9 * expected)
            << c.effect << " mode " << i << ", " << j << " at " << w / (2 * 3.14159265) << " Hz";
      }
    }
  }
}

// With the model's Rayleigh damping on, the effect cancels α K on its own
// springs, so its damping matrix C stays positive semi-definite (the sum of
// β M, α K_q and the modal term) and the effect's high modes are not
// overdamped: on the real KR210 the tool's first mode (≈ 5.6 kHz, where
// α ω/2 ≈ 1.8) keeps a ratio near its ζ = 2 %: within 0.5 % absolute
// (β/(2ω) ≈ 1e-4 and the robot's participation, < 1 % of the mode's energy
// at 5.6 kHz, far above the arm's modes).
TEST(EffectDamping, RayleighAlphaIsReplacedOnTheEffectsSprings) {
  const auto model = testing::Kr210With({{"tool_flexibility", {}}});
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.2, -1.2, 1.5, 0.3, 0.8, -0.5).finished();
  const PostureDynamics pd = EvaluatePosture(model, q);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(pd.system.C);
  EXPECT_GE(es.eigenvalues().minCoeff(), -1e-12 * es.eigenvalues().maxCoeff());
  ASSERT_EQ(pd.modes.size(), 10u);
  EXPECT_NEAR(pd.modes[6].freq_hz, 5630.0, 100.0);
  EXPECT_NEAR(pd.modes[6].damping_ratio, 0.02, 0.005);
  EXPECT_NEAR(pd.modes[7].damping_ratio, 0.02, 0.005);
}

}  // namespace
}  // namespace robomach::dynamics
