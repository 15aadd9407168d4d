// frf-modes' work (calibration::AnalyseModes, issue #34 §3) against the
// model's own eigen-solution: a KR210 hammer test (xx, yy, xy; 1 % noise
// plus an additive floor, as measured data have) is analysed with common
// poles, and the tool-tip modal table must give the modes of the model's
// generalized eigenproblem K φ = λ M φ (PostureEvaluator, which shares no
// code with the modal fit): frequency, damping, in-plane modal mass and
// shape.

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/modal_analysis.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::calibration {
namespace {

using robomach::testing::SourcePath;

TEST(ModalAnalysis, Kr210HammerTestGivesTheModelsModes) {
  const io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  const auto model = dynamics::RobotModel::Build(cfg.description, cfg.parameters);
  Eigen::VectorXd q(6);
  q << DegToRad(10), DegToRad(-60), DegToRad(90), DegToRad(15), DegToRad(45), DegToRad(-20);
  VirtualHammerOptions o;
  o.directions = {{Axis::kX, Axis::kX}, {Axis::kY, Axis::kY}, {Axis::kX, Axis::kY}};
  o.relative_noise = 0.01;
  o.absolute_noise_m_per_s2_per_N = 2e-4;  // an accelerometer's floor
  o.seed = 3441;
  const dynamics::FrfSet measured = SynthesizeHammerTest(model, {{"P", q}}, o);
  const NoiseModels noise = EstimateNoise(measured);
  const std::vector<PoseModes> poses = AnalyseModes(measured, noise);
  ASSERT_EQ(poses.size(), 1u);
  const PoseModes& pm = poses.front();
  ASSERT_EQ(pm.groups.size(), 1u) << "the three FRFs fitted together";
  ASSERT_EQ(pm.groups[0].fit.status, ModalFitStatus::kOk) << pm.groups[0].fit.message;

  dynamics::PostureEvaluator ev(model);
  const dynamics::PostureDynamics d = ev.Evaluate(q);
  // The modes visible in the xx or yy receptance: peak |p_d|²/(2ζω²) of at
  // least 10 % of the largest such peak.
  double largest = 0.0;
  for (const dynamics::Mode& m : d.modes) {
    const double w = HzToRadPerSec(m.freq_hz);
    for (int a = 0; a < 2; ++a) largest = std::max(largest, m.p_T(a) * m.p_T(a) / (2 * m.damping_ratio * w * w));
  }
  int checked = 0;
  for (const dynamics::Mode& m : d.modes) {
    const double w = HzToRadPerSec(m.freq_hz);
    double peak = 0.0;
    for (int a = 0; a < 2; ++a) peak = std::max(peak, m.p_T(a) * m.p_T(a) / (2 * m.damping_ratio * w * w));
    if (peak < 0.1 * largest) continue;
    ++checked;
    const TipMode* found = nullptr;
    for (const TipMode& t : pm.tip_modes) {
      if (std::abs(t.freq_hz - m.freq_hz) < 0.01 * m.freq_hz) found = &t;
    }
    ASSERT_NE(found, nullptr) << "model mode at " << m.freq_hz << " Hz not found";
    EXPECT_NEAR(found->freq_hz, m.freq_hz, 0.003 * m.freq_hz);
    EXPECT_NEAR(found->damping_ratio, m.damping_ratio, 0.05 * m.damping_ratio) << m.freq_hz << " Hz";
    // In-plane: 1/m_xy = p_x² + p_y², shape (p_x, p_y) / |.|.
    const double inv = m.p_T(0) * m.p_T(0) + m.p_T(1) * m.p_T(1);
    EXPECT_NEAR(found->modal_mass_kg, 1.0 / inv, 0.05 / inv) << m.freq_hz << " Hz";
    const Eigen::Vector2d u_model = m.p_T.head<2>() / std::sqrt(inv);
    const double cosine = std::abs(u_model.dot(found->shape.head<2>()));
    EXPECT_GT(cosine, 0.99) << m.freq_hz << " Hz: shape " << found->shape.transpose() << " vs " << u_model.transpose();
    EXPECT_EQ(found->directions, "xy");
  }
  EXPECT_GE(checked, 2);
  // Misfit at the noise: the noise model's σ is what the fit is judged by.
  for (double ns : pm.groups[0].fit.misfit_in_noise) EXPECT_LT(ns, 1.5);
}

TEST(ModalAnalysis, FrfsOnDifferentGridsAreFittedAloneWithAWarning) {
  const io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  const auto model = dynamics::RobotModel::Build(cfg.description, cfg.parameters);
  Eigen::VectorXd q(6);
  q << 0.2, -1.0, 1.5, 0.2, 0.8, -0.3;
  VirtualHammerOptions a;
  a.relative_noise = 0.01;
  VirtualHammerOptions b = a;
  b.directions = {{Axis::kY, Axis::kY}};
  a.directions = {{Axis::kX, Axis::kX}};
  b.block_samples = 10240;  // 0.5 Hz lines
  dynamics::FrfSet set = SynthesizeHammerTest(model, {{"P", q}}, a);
  set.Merge(SynthesizeHammerTest(model, {{"P", q}}, b));
  const auto poses = AnalyseModes(set, EstimateNoise(set));
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].groups.size(), 2u);
  ASSERT_FALSE(poses[0].warnings.empty());
  EXPECT_NE(poses[0].warnings[0].find("different frequency lines"), std::string::npos) << poses[0].warnings[0];
}

}  // namespace
}  // namespace robomach::calibration
