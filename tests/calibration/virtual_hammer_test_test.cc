// The virtual hammer test: grid, noise statistics, coherence and seeding,
// against the model's own receptance (dynamics::Receptance).
#include <gtest/gtest.h>

#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::calibration {
namespace {

TEST(VirtualHammerTest, DefaultGridIsTheDocumentedHammerGrid) {
  // 5120 Hz / 20480 samples = 0.25 Hz; 0.25..500 Hz is 2000 lines.
  const Eigen::VectorXd f = HammerTestGrid({});
  ASSERT_EQ(f.size(), 2000);
  EXPECT_EQ(f(0), 0.25);
  EXPECT_EQ(f(1999), 500.0);
  EXPECT_EQ(f(1) - f(0), 0.25);
  VirtualHammerOptions bad;
  bad.fmax_hz = 3000.0;
  EXPECT_THROW(bad.Validate(), OptionError);  // above Nyquist (2560 Hz)
}

// Noise-free output equals the model's receptance up to the 13-digit
// rounding (5e-13 relative). With relative noise r the relative deviation
// n = H_noisy/H − 1 is complex normal with E|n|² = r²: over M = 4000 lines
// the sample mean of |n|² has relative standard deviation 1/√M ≈ 1.6 %, so
// the sample rms is within 0.8 % (1σ) of r; 5σ gives 4 %. The mean of n is
// ~r/√M ≈ 3e-4 per part; 5σ: 1.6e-3.
TEST(VirtualHammerTest, NoiseHasTheRequestedRmsAndIsSeeded) {
  const auto cfg = io::LoadRobotConfig(robomach::testing::SourcePath("config/kr210.yaml"));
  const auto model = cfg.Build();
  Eigen::VectorXd q(6);
  q << 0, DegToRad(-90), DegToRad(90), 0, DegToRad(45), 0;
  const std::vector<NamedPosture> p1 = {{"P1", q}};
  VirtualHammerOptions clean;
  const dynamics::FrfSet c = SynthesizeHammerTest(model, p1, clean);
  const auto H = dynamics::Receptance(dynamics::EvaluatePosture(model, q), HammerTestGrid(clean));
  const dynamics::Frf& cxx = c.at({"P1", Axis::kX, Axis::kX});
  for (int i = 0; i < cxx.size(); ++i) {
    EXPECT_LE(std::abs(cxx.receptance()(i) - H[i](0, 0)), 5e-13 * std::abs(H[i](0, 0)));
  }
  VirtualHammerOptions noisy;
  noisy.relative_noise = 0.02;
  noisy.seed = 3;
  noisy.coherence = true;
  const dynamics::FrfSet n1 = SynthesizeHammerTest(model, p1, noisy);
  const dynamics::FrfSet n2 = SynthesizeHammerTest(model, p1, noisy);
  double s2 = 0.0;
  std::complex<double> mean = 0.0;
  int m = 0;
  for (const auto& [key, frf] : n1) {
    EXPECT_EQ(frf.receptance(), n2.at(key).receptance());  // same seed, same data
    const dynamics::Frf& ref = c.at(key);
    for (int i = 0; i < frf.size(); ++i) {
      const std::complex<double> d = frf.receptance()(i) / ref.receptance()(i) - 1.0;
      s2 += std::norm(d);
      mean += d;
      ++m;
      // γ² = 1 / (1 + (n − 1) r²) for relative noise only, n = 5 averages.
      EXPECT_NEAR((*frf.coherence())(i), 1.0 / (1.0 + 4 * 0.02 * 0.02), 1e-12);
    }
  }
  ASSERT_EQ(m, 4000);
  EXPECT_NEAR(std::sqrt(s2 / m), 0.02, 0.04 * 0.02);
  EXPECT_LT(std::abs(mean.real() / m), 1.6e-3);
  EXPECT_LT(std::abs(mean.imag() / m), 1.6e-3);
}

}  // namespace
}  // namespace robomach::calibration
