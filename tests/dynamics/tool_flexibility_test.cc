// The tool_flexibility effect: clamped–free Euler–Bernoulli modes of the tool.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "effect_test_support.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::ExpectValidSystem;
using robomach::testing::Kr210Config;
using robomach::testing::Kr210With;
using robomach::testing::RandomPosture;

constexpr double kBetaL[4] = {1.875104068711961, 4.694091132974175, 7.854757438237613,
                              10.99554073487547};

struct Tool {
  double d = 0.010, L = 0.040, E = 6.0e11, rho = 14500.0;
  double EI() const { return E * kPi * std::pow(d, 4) / 64.0; }
  double rhoA() const { return rho * kPi * d * d / 4.0; }
  // Closed form [Blevins 1979, Table 8-1]: f_n = (β_n L)²/(2π) √(EI/(ρA L⁴)).
  double freq_hz(int n) const {
    return kBetaL[n] * kBetaL[n] / (2 * kPi) * std::sqrt(EI() / (rhoA() * std::pow(L, 4)));
  }
};

// A robot made rigid: every joint 1e15 N·m/rad puts its lowest mode near
// 170 kHz (10 Hz·√(1e15/3e6)), five times above the tool's second mode, and
// its tip compliance (≈ 1e-15 m/N) 1e-8 of the tool's, so the holder is a
// clamped base to ≈ 1e-8. (Stiffer joints would cost eigen-solver accuracy:
// the error in λ is ≈ eps·λ_max, with λ_max ∝ the joint stiffness.)
std::shared_ptr<const RobotModel> RigidRobotWithTool(int modes) {
  io::RobotConfig cfg = Kr210Config();
  cfg.description.joint_stiffness = Eigen::VectorXd::Constant(6, 1e15);
  if (modes > 0) {
    cfg.description.effects.push_back({"tool_flexibility", {{"modes", static_cast<double>(modes)}}});
  }
  return RobotModel::Build(cfg.description, DefaultParameters(cfg.description));
}

// Closed-form cantilever frequencies: the first four modes of the rigid
// robot with a two-mode tool come in x/y pairs at f_1, f_2. What is left of
// the robot is a spring in series with the tool, of compliance
// C_R = |H_robot(0)| ≈ (2.5 m)²/1e15 ≈ 6e-15 m/N; by Rayleigh's quotient it
// lowers mode n by ≈ ½ k_n C_R relative, k_n = (β_n L)⁴/4 · EI/L³ the
// modal stiffness (≈ 4e-8 for mode 1, 2e-6 for mode 2). The tolerance is
// k_n C_R (twice the estimate) plus 1e-8 for the quadrature (≈ 1e-13) and
// the eigen-solver (eps·λ_max/λ_1 ≈ 2e-16·1.3e16/1.2e9 ≈ 2e-9).
TEST(ToolFlexibility, RigidRobotGivesClosedFormCantileverFrequencies) {
  const Tool t;
  const auto model = RigidRobotWithTool(2);
  ASSERT_EQ(model->num_dofs(), 10);
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.2, -1.2, 1.5, 0.3, 0.8, -0.5).finished();
  const PostureDynamics pd = EvaluatePosture(model, q);
  ExpectValidSystem(pd.system);
  const double C_R = EvaluatePosture(RigidRobotWithTool(0), q).static_compliance.norm();
  for (int n = 0; n < 2; ++n) {
    const double k_n = std::pow(kBetaL[n], 4) / 4.0 * t.EI() / std::pow(t.L, 3);
    const double tol = k_n * C_R + 1e-8;
    for (int k : {2 * n, 2 * n + 1}) {
      EXPECT_NEAR(pd.modes[k].freq_hz, t.freq_hz(n), tol * t.freq_hz(n)) << "mode " << n;
      EXPECT_LE(pd.modes[k].freq_hz, t.freq_hz(n) * (1 + 1e-8)) << "a series spring lowers it";
    }
  }
  // The default tool, by hand: EI = 6e11·π·1e-8/64 = 294.5 N·m²,
  // ρA = 14500·π·1e-4/4 = 1.1388 kg/m, L⁴ = 2.56e-6 m⁴:
  // f_1 = 3.5160/(2π)·√(294.5/(1.1388·2.56e-6)) = 5624.4 Hz (5 digits).
  EXPECT_NEAR(t.freq_hz(0), 5624.4, 0.1);
}

// Static tip compliance added to the rigid robot's (K is block diagonal, so
// the springs are in series): the n-mode sum Σ 4/(β_k L)⁴ · L³/(EI) in each
// lateral direction exactly (1e-9: quadrature and rounding), and the
// cantilever's L³/(3EI) to within the tail of the modal series, which with
// β_k L ≈ (2k − 1)π/2 is bounded by Σ_{k>n} 4/((2k − 1)π/2)⁴ · L³/(EI).
TEST(ToolFlexibility, StaticTipComplianceConvergesToCantileverFormula) {
  const Tool t;
  const double unit = std::pow(t.L, 3) / t.EI();
  for (int modes = 1; modes <= 4; ++modes) {
    const auto model = RigidRobotWithTool(modes);
    const Eigen::VectorXd q = (Eigen::VectorXd(6) << -0.4, -1.0, 1.2, 0.1, 1.1, 0.7).finished();
    const PostureDynamics pd = EvaluatePosture(model, q);
    const PostureDynamics p0 = EvaluatePosture(RigidRobotWithTool(0), q);
    const Eigen::Matrix3d R = pd.X_BT.linear();
    const Eigen::Matrix3d H =
        R.transpose() * (pd.static_compliance - p0.static_compliance) * R;  // flange axes
    double sum = 0.0;
    for (int k = 0; k < modes; ++k) sum += 4.0 / std::pow(kBetaL[k], 4);
    double tail = 0.0;
    for (int k = modes + 1; k < 10000; ++k) tail += 4.0 / std::pow((2 * k - 1) * kPi / 2, 4);
    for (int a = 0; a < 2; ++a) {
      EXPECT_NEAR(H(a, a), sum * unit, 1e-9 * unit) << modes;
      EXPECT_NEAR(H(a, a), unit / 3.0, 1.05 * tail * unit + 1e-9 * unit) << modes;
    }
    EXPECT_LT(std::abs(H(2, 2)), 1e-6 * unit);  // axially the tool stays rigid
  }
}

// The modal mass of a tip-normalised clamped–free mode is ρA L/4
// [Blevins 1979]; the effect's quadrature must reproduce it. The mode
// shapes lose ≈ log10(cosh 11) ≈ 4.5 digits to the cancellation
// cosh − σ sinh at β₄L ≈ 11 (≈ 3e-12 relative), so 1e-10.
TEST(ToolFlexibility, ModalMassIsQuarterOfToolMass) {
  const Tool t;
  const auto model = RigidRobotWithTool(4);
  const PostureDynamics pd = EvaluatePosture(model, Eigen::VectorXd::Constant(6, 0.5));
  for (int i = 6; i < 14; ++i) {
    EXPECT_NEAR(pd.system.M(i, i), t.rhoA() * t.L / 4.0, 1e-10 * t.rhoA() * t.L) << i;
  }
}

// On the real robot the tool modes couple to the robot's: M stays SPD, the
// robot's low modes barely move (the tool's 0.05 kg against the arm), and
// the tool tip receptance gains the tool's compliance at low frequency.
TEST(ToolFlexibility, CouplesToTheRobotConsistently) {
  const auto base = robomach::testing::Kr210();
  const auto model = Kr210With({{"tool_flexibility", {}}});
  std::mt19937 rng(40);
  const Tool t;
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const PostureDynamics p0 = EvaluatePosture(base, q);
    const PostureDynamics p1 = EvaluatePosture(model, q);
    ExpectValidSystem(p1.system);
    // Series springs: the static compliance adds exactly the two-mode tool
    // compliance in the lateral directions (K is block diagonal); 1e-9.
    const Eigen::Matrix3d R = p1.X_BT.linear();
    const double c2 = (4.0 / std::pow(kBetaL[0], 4) + 4.0 / std::pow(kBetaL[1], 4)) *
                      std::pow(t.L, 3) / t.EI();
    const Eigen::Matrix3d expected =
        p0.static_compliance + c2 * R * Eigen::Vector3d(1, 1, 0).asDiagonal() * R.transpose();
    EXPECT_LE((p1.static_compliance - expected).norm(), 1e-9 * expected.norm());
    // Adding compliance and mass lowers every robot mode, by < 1 % here.
    for (int k = 0; k < 6; ++k) {
      EXPECT_LE(p1.modes[k].freq_hz, p0.modes[k].freq_hz * (1 + 1e-9));
      EXPECT_GT(p1.modes[k].freq_hz, 0.99 * p0.modes[k].freq_hz);
    }
  }
}

}  // namespace
}  // namespace robomach::dynamics
