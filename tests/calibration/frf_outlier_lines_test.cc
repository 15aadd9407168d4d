// Isolated outlier lines in measured FRFs (issue #33 item 4: mains hum and
// single-line spikes), on data made here and not by the library's
// synthesiser: an analytic two-mode receptance (modal sum written below),
// measured as accelerance −ω²H with 1 % relative noise and an additive noise
// that is flat in acceleration and rises where the hammer's force spectrum
// rolls off (near 1.2 kHz), converted back to receptance as the readers do;
// mains hum at 50, 100 and 150 Hz and a single-line spike are added to the
// accelerance at known lines with known sizes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <complex>
#include <map>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/common/units.h"

namespace robomach::calibration {
namespace {

using cd = std::complex<double>;

constexpr double kDf = 0.625;   // line spacing [Hz]
constexpr int kLines = 4000;    // 0.625 .. 2500 Hz
constexpr double kRel = 0.01;   // relative noise
constexpr double kAccelFloor = 3e-4;  // additive noise in acceleration [(m/s²)/N]
// Modes: 130 Hz with ζ = 0.01 (half-power band 2ζf = 2.6 Hz: 4.2 lines on
// this grid) and 420 Hz with ζ = 0.03; modal stiffnesses [N/m].
constexpr double kFn[2] = {130.0, 420.0}, kZeta[2] = {0.01, 0.03}, kK[2] = {2e7, 5e7};

cd Receptance(double f_hz) {
  const double w = HzToRadPerSec(f_hz);
  cd h = 0.0;
  for (int r = 0; r < 2; ++r) {
    const double wn = HzToRadPerSec(kFn[r]);
    h += wn * wn / kK[r] / (wn * wn - w * w + cd(0.0, 2.0 * kZeta[r] * wn * w));
  }
  return h;
}

// The additive noise of the accelerance, rising as the hammer's force falls
// off above about 1.2 kHz (8th-order roll-off).
double AccelFloor(double f_hz) { return kAccelFloor * std::sqrt(1.0 + std::pow(f_hz / 1200.0, 16)); }

struct Injected {
  double freq_hz;
  double size;  // in units of the line's true σ
  bool mains;
};
// Hum at 50, 100, 150 Hz (150 Hz on the flank of the 130 Hz mode) and a
// spike at 777.5 Hz, 30 to 100 x the noise.
const std::vector<Injected> kInjected = {{50.0, 40.0, true}, {100.0, 80.0, true}, {150.0, 30.0, true},
                                         {777.5, 60.0, false}};

int LineOf(double f_hz) { return static_cast<int>(std::lround(f_hz / kDf)) - 1; }

struct Measured {
  dynamics::Frf frf;
  Eigen::VectorXd sigma;  // true σ per line in receptance [m/N]
  Eigen::VectorXcd truth;
};

// One measurement; `spikes` adds kInjected (random phase) to the same noise.
Measured Measure(unsigned seed, bool spikes, int lines = kLines, double df = kDf) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));  // E|g + i g|² = 1
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  Eigen::VectorXd f(lines), sigma(lines);
  Eigen::VectorXcd h(lines), truth(lines);
  for (int i = 0; i < lines; ++i) {
    f(i) = df * (i + 1);
    const double w2 = std::pow(HzToRadPerSec(f(i)), 2);
    truth(i) = Receptance(f(i));
    const cd accel = -w2 * truth(i);
    const double sa = std::hypot(kRel * std::abs(accel), AccelFloor(f(i)));
    const cd measured = accel * (1.0 + kRel * cd(g(rng), g(rng))) + AccelFloor(f(i)) * cd(g(rng), g(rng));
    h(i) = measured / -w2;
    sigma(i) = sa / w2;
  }
  if (spikes) {
    for (const Injected& s : kInjected) {
      const int i = LineOf(s.freq_hz);
      h(i) += s.size * sigma(i) * std::polar(1.0, phase(rng));
    }
  }
  return {dynamics::Frf::FromSamples(f, h), sigma, truth};
}

TEST(FrfOutlierLines, HumAndASpikeAreFoundAtTheirLinesWithTheirSize) {
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    const Measured m = Measure(seed, true);
    const FrfNoise n = EstimateFrfNoise(m.frf);
    ASSERT_EQ(n.excluded_lines.size(), kInjected.size()) << "seed " << seed << ": " << n.description;
    for (size_t k = 0; k < kInjected.size(); ++k) {
      const Injected& s = kInjected[k];
      const ExcludedLine& e = n.excluded_lines[k];
      const int i = LineOf(s.freq_hz);
      EXPECT_EQ(e.line, i) << s.freq_hz << " Hz, seed " << seed;
      EXPECT_DOUBLE_EQ(e.freq_hz, m.frf.freq_hz()(i));
      EXPECT_EQ(e.mains_hz, s.mains ? s.freq_hz : 0.0) << s.freq_hz << " Hz";
      // The departure from the smooth curve is the injected line plus the
      // line's own noise and the local fit's prediction error, a complex
      // Gaussian of variance σ²(1 + v) with v ≤ 0.5 for this window
      // (measured 0.1-0.3): |excess/σ − size| ≤ 4 fails with probability
      // exp(−16/1.5) ≈ 2e-5 per line.
      EXPECT_NEAR(e.excess_m_per_N / m.sigma(i), s.size, 4.0) << s.freq_hz << " Hz, seed " << seed;
      // The ratio is in units of the *estimated* σ, whose floor is within
      // 25 % and rel within 25 % (frf_noise_test): the ratio within 30 % of
      // the true size (and the 4 above).
      EXPECT_NEAR(e.ratio, s.size, 0.3 * s.size + 4.0) << s.freq_hz << " Hz, seed " << seed;
      EXPECT_FALSE(n.usable[i]);
      std::printf("seed %u: %s (injected %.0f; excess %.1f true sigma)\n", seed, DescribeExcludedLine(e).c_str(),
                  s.size, e.excess_m_per_N / m.sigma(i));
    }
    // The lines are named in the description that the tools print.
    EXPECT_NE(n.description.find("4 isolated lines left out"), std::string::npos) << n.description;
    EXPECT_NE(n.description.find("50 Hz: "), std::string::npos) << n.description;
    EXPECT_NE(n.description.find("(mains hum: 3 x 50 Hz)"), std::string::npos) << n.description;
    // Every line of the 130 Hz mode's peak (ζ = 0.01, 4 lines in its
    // half-power band) stays usable.
    for (int i = LineOf(125.0); i <= LineOf(135.0); ++i) EXPECT_TRUE(n.usable[i]) << m.frf.freq_hz()(i) << " Hz";
  }
}

TEST(FrfOutlierLines, DescriptionOfOneLine) {
  EXPECT_EQ(DescribeExcludedLine({79, 50.0, 38.2, 1e-9, 50.0}), "50 Hz: 38 x the noise (mains hum: 1 x 50 Hz)");
  EXPECT_EQ(DescribeExcludedLine({479, 300.0, 250.4, 1e-9, 300.0}),
            "300 Hz: 250 x the noise (mains hum: 6 x 50 Hz or 5 x 60 Hz)");
  EXPECT_EQ(DescribeExcludedLine({1243, 777.5, 7.26, 1e-9, 0.0}), "777.5 Hz: 7.3 x the noise");
}

// False alarms: for noise alone |H − Ĥ|²/(σ² + var Ĥ) is Exp(1), so a line
// passes z = 6 with probability e⁻³⁶ ≈ 2e-16; even with σ underestimated
// by 25 % (the noise model's accuracy) the effective threshold is 4.5 and
// the probability e⁻²⁰·²⁵ ≈ 1.6e-9 per line, 1.3e-4 expected in the
// 80,000 lines below. Any flag is therefore a failure of the method (a
// peak taken for a spike), not bad luck.
TEST(FrfOutlierLines, CleanDataGetNoFlags) {
  int flags = 0, lines = 0;
  for (unsigned seed = 100; seed < 120; ++seed) {
    const Measured m = Measure(seed, false);
    const FrfNoise n = EstimateFrfNoise(m.frf);
    EXPECT_TRUE(n.excluded_lines.empty()) << "seed " << seed << ": " << n.description;
    flags += static_cast<int>(n.excluded_lines.size());
    lines += m.frf.size();
  }
  EXPECT_EQ(flags, 0) << "in " << lines << " lines";
}

// The lightly damped mode on a coarser grid: 1.0 Hz lines leave 2.6 lines
// in the 130 Hz mode's half-power band (1.25 Hz: 2.1); the local rational
// fit follows the peak from its flanks.
TEST(FrfOutlierLines, ALightlyDampedPeakWithFewLinesIsNotFlagged) {
  for (double df : {1.0, 1.25}) {
    for (unsigned seed = 200; seed < 205; ++seed) {
      const Measured m = Measure(seed, false, 2500, df);
      const FrfNoise n = EstimateFrfNoise(m.frf);
      EXPECT_TRUE(n.excluded_lines.empty()) << df << " Hz lines, seed " << seed << ": " << n.description;
    }
  }
}

// The same on noise-free data: the noise model's smallest relative noise
// (1e-6) is then the yardstick, and the local fit's model error must stay
// below 6e-6 of |H| for a clean curve to stay clean. Noise-free data are
// what frf-synth writes; a false flag there would be a visible nuisance.
TEST(FrfOutlierLines, NoiseFreeDataGetNoFlagsEither) {
  Eigen::VectorXd f(kLines);
  Eigen::VectorXcd h(kLines);
  for (int i = 0; i < kLines; ++i) {
    f(i) = kDf * (i + 1);
    h(i) = Receptance(f(i));
  }
  const FrfNoise n = EstimateFrfNoise(dynamics::Frf::FromSamples(f, h));
  EXPECT_TRUE(n.excluded_lines.empty()) << n.description;
}

TEST(FrfOutlierLines, OptionsAndTheSwitch) {
  NoiseOptions o;
  o.outlier_threshold = 2.0;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = {};
  o.outlier_threshold_off_mains = 5.0;  // below outlier_threshold
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = {};
  o.outlier_window_lines = 2;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  o = {};
  o.exclude_outlier_lines = false;
  const FrfNoise n = EstimateFrfNoise(Measure(1, true).frf, o);
  EXPECT_TRUE(n.excluded_lines.empty());
  for (const Injected& s : kInjected) EXPECT_TRUE(n.usable[LineOf(s.freq_hz)]) << s.freq_hz;
}

// Distance of the fitted mode nearest fn [Hz] and its damping ratio.
const FittedMode* Nearest(const ModalFitResult& fit, double fn) {
  const FittedMode* best = nullptr;
  for (const FittedMode& m : fit.modes) {
    if (!best || std::abs(m.freq_hz - fn) < std::abs(best->freq_hz - fn)) best = &m;
  }
  return best;
}

ModalFitResult FitUsable(const dynamics::Frf& frf, const NoiseOptions& o = {}) {
  dynamics::FrfSet set;
  set.Insert({"P1", Axis::kX, Axis::kX}, frf);
  NoiseModels noise;
  noise.emplace(set.begin()->first, EstimateFrfNoise(frf, o));
  return FitModes(UsableData(set, noise).begin()->second);
}

// A fit with the hum lines left out lands where the fit of the same
// measurement without hum lands; with them in, the modal fit takes the hum
// for structure.
TEST(FrfOutlierLines, TheFitWithoutTheHumLinesLandsWhereTheHumFreeFitLands) {
  int extra_modes = 0;
  for (unsigned seed : {1u, 2u, 3u}) {
    const ModalFitResult clean = FitUsable(Measure(seed, false).frf);
    const ModalFitResult hum = FitUsable(Measure(seed, true).frf);
    NoiseOptions off;
    off.exclude_outlier_lines = false;
    const ModalFitResult kept = FitUsable(Measure(seed, true).frf, off);
    ASSERT_EQ(clean.status, SolverStatus::kConverged) << clean.message;
    ASSERT_EQ(hum.status, SolverStatus::kConverged) << hum.message;
    ASSERT_EQ(clean.modes.size(), 2u) << clean.message;
    EXPECT_EQ(hum.modes.size(), 2u) << hum.message;
    for (int r = 0; r < 2; ++r) {
      const FittedMode* a = Nearest(clean, kFn[r]);
      const FittedMode* b = Nearest(hum, kFn[r]);
      // Both against the truth: the statistical error of a mode fitted on
      // ~3500 lines at 1 % noise is far below these (measured: frequency
      // 1e-5, damping 1e-3 relative).
      EXPECT_NEAR(a->freq_hz / kFn[r], 1.0, 1e-3);
      EXPECT_NEAR(b->freq_hz / kFn[r], 1.0, 1e-3);
      EXPECT_NEAR(a->damping_ratio / kZeta[r], 1.0, 0.03);
      EXPECT_NEAR(b->damping_ratio / kZeta[r], 1.0, 0.03);
      // And against each other: the two data sets differ only in the four
      // lines (none in a half-power band) and in the noise model fitted to
      // them. Measured on seeds 1-3: frequency within 7e-7 relative and
      // damping within 2e-4 relative of each other, while the fits of the
      // three seeds scatter by 1.5e-5 (frequency) and 2e-3 (damping) about
      // their mean: the bounds below are about an eighth and a half of
      // that scatter, so leaving the hum out costs nothing measurable.
      EXPECT_NEAR(b->freq_hz / a->freq_hz, 1.0, 2e-6) << "mode " << r << ", seed " << seed;
      EXPECT_NEAR(b->damping_ratio / a->damping_ratio, 1.0, 1e-3) << "mode " << r << ", seed " << seed;
    }
    extra_modes += static_cast<int>(kept.modes.size()) - 2;
  }
  // With the hum kept the modal fit takes it for structure: spurious modes
  // (measured: 2 and 1 extra on seeds 2 and 3).
  EXPECT_GT(extra_modes, 0);
}

// The statistic behind the threshold: for noise alone z² = |H − Ĥ|²/(σ² +
// var Ĥ) is Exp(1), so at the smallest threshold allowed, 3, a line passes
// with probability e⁻⁹ = 1.23e-4: about 9.6 of the ~78,000 candidate lines
// of 20 clean seeds. The noise model's σ is a few per cent off (rel 4.5 %
// low, the floor within 25 %), which moves that rate by a factor of about 2
// either way (e⁻⁹ᐟ¹·⁰⁸ to e⁻⁹·¹·⁰⁸); asserted: between a quarter and four
// times the Gaussian expectation. A statistic that were not Exp(1) (a
// missing var Ĥ, a peak's model error) would fall outside by far.
TEST(FrfOutlierLines, TheStatisticHasTheGaussianTailAtALowThreshold) {
  NoiseOptions o;
  o.outlier_threshold = 3.0;
  o.outlier_threshold_off_mains = 3.0;  // the statistic on every line, not only at mains multiples
  int flags = 0, candidates = 0;
  for (unsigned seed = 100; seed < 120; ++seed) {
    const Measured m = Measure(seed, false);
    NoiseOptions estimate;
    estimate.exclude_outlier_lines = false;
    const FrfNoise n = EstimateFrfNoise(m.frf, estimate);
    flags += static_cast<int>(FindOutlierLines(m.frf, n.sigma_m_per_N, n.usable, o).size());
    candidates += n.usable_lines;
  }
  const double expected = candidates * std::exp(-9.0);
  std::printf("z > 3 on %d of %d clean lines, %.1f expected for Exp(1)\n", flags, candidates, expected);
  EXPECT_GT(flags, 0.25 * expected);
  EXPECT_LT(flags, 4.0 * expected);
}

}  // namespace
}  // namespace robomach::calibration
