// The noise model of measured FRFs (issue #10), on data made here, not by
// the virtual hammer test: an analytic three-mode receptance with 2 %
// relative noise and an additive floor that is flat in acceleration at the
// low end, flat in receptance in the middle and rises where a hammer's force
// spectrum rolls off; and simulated impacts for the coherence.
#include "robomach/calibration/frf_noise.h"

#include <cmath>
#include <complex>
#include <array>
#include <random>

#include <gtest/gtest.h>

#include "robomach/calibration/modal_fit.h"
#include "robomach/common/units.h"

namespace robomach::calibration {
namespace {

using cd = std::complex<double>;

struct Truth {
  Eigen::VectorXd f;
  Eigen::VectorXcd h;
  Eigen::VectorXd floor;
};

// Modes at 12, 45 and 180 Hz; static compliance about 5e-7 m/N.
cd ThreeModes(double f_hz) {
  const double w = HzToRadPerSec(f_hz);
  const double fn[3] = {12.0, 45.0, 180.0}, z[3] = {0.04, 0.03, 0.02}, k[3] = {3e6, 8e6, 2e7};
  cd h = 0.0;
  for (int r = 0; r < 3; ++r) {
    const double wn = HzToRadPerSec(fn[r]);
    h += wn * wn / k[r] / (wn * wn - w * w + cd(0.0, 2.0 * z[r] * wn * w));
  }
  return h;
}

double Floor(double f_hz) {
  const double w = HzToRadPerSec(f_hz);
  const double a_r = 4e-9, a_a = 1e-4, fc = 800.0;  // [m/N], [(m/s²)/N], [Hz]
  return std::sqrt((a_r * a_r + std::pow(a_a / (w * w), 2)) * (1.0 + std::pow(f_hz / fc, 4)));
}

Truth MakeTruth() {
  Truth t;
  const int n = 4096;
  t.f.resize(n);
  t.h.resize(n);
  t.floor.resize(n);
  for (int i = 0; i < n; ++i) {
    t.f(i) = 0.625 * (i + 1);
    t.h(i) = ThreeModes(t.f(i));
    t.floor(i) = Floor(t.f(i));
  }
  return t;
}

dynamics::Frf Noisy(const Truth& t, double rel, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));
  Eigen::VectorXcd h(t.f.size());
  for (int i = 0; i < t.f.size(); ++i) {
    h(i) = t.h(i) * (1.0 + rel * cd(g(rng), g(rng))) + t.floor(i) * cd(g(rng), g(rng));
  }
  return dynamics::Frf::FromSamples(t.f, h);
}

TEST(FrfNoise, ScatterEstimateRecoversRelativeNoiseAndShapedFloor) {
  const Truth t = MakeTruth();
  // rel over 8 seeds: measured mean 0.0191 (4.5 % low: the modal fit of
  // the second pass absorbs a little more of the noise at the peaks, where
  // its leverage is highest, than the global p/2N allows for), scatter 7.5 %
  // per seed. Asserted: the mean within 8 %, each seed within 25 % (3σ).
  double rel_sum = 0.0;
  const std::vector<unsigned> seeds = {1, 2, 3, 4, 5, 6, 7, 8};
  for (unsigned seed : seeds) {
    const dynamics::Frf frf = Noisy(t, 0.02, seed);
    const FrfNoise n = EstimateFrfNoise(frf);
    EXPECT_EQ(n.source, NoiseSource::kScatter);
    EXPECT_EQ(n.status, SolverStatus::kConverged);
    EXPECT_TRUE(n.modal_refined);
    EXPECT_NEAR(n.relative, 0.02, 0.25 * 0.02) << "seed " << seed;
    rel_sum += n.relative;
    // Where the floor is not hidden under the relative noise it is
    // determined by the data: within 25 % everywhere there, the median
    // ratio within 8 %.
    std::vector<double> ratio;
    int outside = 0;
    for (int i = 0; i < frf.size(); ++i) {
      if (t.floor(i) < 0.2 * 0.02 * std::abs(t.h(i))) continue;
      const double r = n.floor_m_per_N(i) / t.floor(i);
      ratio.push_back(r);
      outside += r < 0.75 || r > 1.33;
    }
    ASSERT_GT(ratio.size(), 2000u);
    std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
    EXPECT_NEAR(ratio[ratio.size() / 2], 1.0, 0.08) << "seed " << seed;
    EXPECT_LT(outside, static_cast<int>(0.02 * ratio.size())) << "seed " << seed;
    // The usable lines are those whose true SNR reaches 3, but for a few
    // near the crossings.
    int disagree = 0;
    for (int i = 0; i < frf.size(); ++i) {
      const bool truly = std::abs(t.h(i)) >= 3.0 * t.floor(i);
      disagree += truly != static_cast<bool>(n.usable[i]);
    }
    EXPECT_LT(disagree, 0.02 * frf.size()) << "seed " << seed;
    // The floor crosses the signal near the lowest lines (about 4 Hz) and
    // above 300 Hz. At the usable band's ends the true SNR is 3 within the
    // floor's accuracy (25 %, above): in [2.25, 4].
    ASSERT_FALSE(n.usable_bands.empty());
    // (At the low end the SNR changes by 36 % from one line to the next,
    // so the edge line or a neighbour must be in the interval.)
    for (double edge : {n.usable_bands.front().first, n.usable_bands.back().second}) {
      const int i = static_cast<int>(std::lround(edge / 0.625)) - 1;
      bool near = false;
      for (int k = std::max(0, i - 1); k <= std::min<int>(frf.size() - 1, i + 1); ++k) {
        const double snr = std::abs(t.h(k)) / t.floor(k);
        near |= snr > 2.25 && snr < 4.0;
      }
      EXPECT_TRUE(near) << "edge " << edge << " Hz, seed " << seed;
    }
    EXPECT_LT(n.usable_bands.front().first, 6.0);
    EXPECT_GT(n.usable_bands.back().second, 300.0);
  }
  EXPECT_NEAR(rel_sum / seeds.size(), 0.02, 0.08 * 0.02);
}

// n impacts of equal force amplitude and random phase, output noise of
// standard deviation s per impact: the H1 estimate and its coherence, as an
// analyser computes them. The σ of the averaged estimate is s/√n.
TEST(FrfNoise, CoherenceOfSimulatedImpactsGivesTheScatterOfTheAverage) {
  const int n_avg = 5, lines = 4000;
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));
  std::uniform_real_distribution<double> phase(0.0, 2.0 * kPi);
  Eigen::VectorXd f(lines), coh(lines), sigma_true(lines);
  Eigen::VectorXcd h1(lines);
  for (int i = 0; i < lines; ++i) {
    f(i) = 1.0 + 0.5 * i;
    const cd h = ThreeModes(f(i));
    const double s = 0.05 * std::abs(h) + 2e-9;  // per impact
    cd sxf = 0.0;
    double sff = 0.0, sxx = 0.0;
    for (int k = 0; k < n_avg; ++k) {
      const cd F = std::polar(100.0, phase(rng));   // 100 N
      const cd X = h * F + 100.0 * s * cd(g(rng), g(rng));
      sxf += X * std::conj(F);
      sff += std::norm(F);
      sxx += std::norm(X);
    }
    h1(i) = sxf / sff;
    coh(i) = std::norm(sxf) / (sff * sxx);
    sigma_true(i) = s / std::sqrt(static_cast<double>(n_avg));
  }
  const dynamics::Frf frf = dynamics::Frf::FromSamples(f, h1, coh);
  NoiseOptions o;
  o.averages = n_avg;
  const FrfNoise n = EstimateFrfNoise(frf, o);
  EXPECT_EQ(n.source, NoiseSource::kCoherence);
  // Each σ̂² is a scaled χ² with 2(n − 1) = 8 degrees of freedom: the mean
  // ratio over 4000 lines scatters by 0.5/√4000 ≈ 0.008. With n instead of
  // n − 1 in the estimate it would be 0.8.
  double mean_ratio = 0.0;
  for (int i = 0; i < lines; ++i) mean_ratio += std::pow(n.sigma_m_per_N(i) / sigma_true(i), 2);
  mean_ratio /= lines;
  EXPECT_NEAR(mean_ratio, 1.0, 0.04);
  // And the actual errors of the averaged estimate have that variance.
  double err = 0.0;
  for (int i = 0; i < lines; ++i) err += std::norm((h1(i) - ThreeModes(f(i))) / sigma_true(i));
  EXPECT_NEAR(err / lines, 1.0, 0.06);
}

TEST(FrfNoise, CoherenceWithoutTheNumberOfAveragesFallsBackToTheScatter) {
  const Truth t = MakeTruth();
  const dynamics::Frf noisy = Noisy(t, 0.02, 4);
  const dynamics::Frf frf = dynamics::Frf::FromSamples(noisy.freq_hz(), noisy.receptance(),
                                                       Eigen::VectorXd::Constant(noisy.size(), 0.99));
  EXPECT_EQ(EstimateFrfNoise(frf).source, NoiseSource::kScatter);  // averages unknown
  NoiseOptions one;
  one.averages = 1;  // one impact: coherence 1 by construction, no information
  EXPECT_EQ(EstimateFrfNoise(frf, one).source, NoiseSource::kScatter);
}

// ln|Hm/H| and the chord 2 sin(Δφ/2), as calibration::WholeCurveResiduals.
std::array<double, 2> WholeCurveResidualsForTest(cd h_model, cd h_measured) {
  const cd ratio = h_model / h_measured;
  return {std::log(std::abs(ratio)), 2.0 * std::sin(0.5 * std::arg(ratio))};
}

TEST(FrfNoise, UsableDataKeepsTheUsableLinesWithTheirSigma) {
  const Truth t = MakeTruth();
  dynamics::FrfSet set;
  set.Insert({"P1", Axis::kX, Axis::kX}, Noisy(t, 0.02, 5));
  const NoiseModels noise = EstimateNoise(set);
  const dynamics::FrfSet usable = UsableData(set, noise);
  const dynamics::Frf& u = usable.at({"P1", Axis::kX, Axis::kX});
  EXPECT_EQ(u.size(), noise.begin()->second.usable_lines);
  ASSERT_TRUE(u.noise_sigma().has_value());
  // The weights of the log residuals make the true model's residuals unit
  // normal: the mean square of w (ln|H_true/H|, chord of the phase error)
  // over the usable lines is 1 (1.09 expected from rel's 4.5 % low bias,
  // ±0.06 for 2 × ~600 residuals).
  const Eigen::VectorXd w = LogResidualWeights(u);
  double ms = 0.0;
  for (int i = 0; i < u.size(); ++i) {
    const int k = static_cast<int>(std::lround(u.freq_hz()(i) / 0.625)) - 1;
    const auto r = WholeCurveResidualsForTest(t.h(k), u.receptance()(i));
    ms += w(i) * w(i) * (r[0] * r[0] + r[1] * r[1]);
  }
  ms /= 2.0 * u.size();
  EXPECT_GT(ms, 0.9);
  EXPECT_LT(ms, 1.2);
  // Without a noise model, all ones.
  EXPECT_EQ(LogResidualWeights(set.at({"P1", Axis::kX, Axis::kX})), Eigen::VectorXd::Ones(t.f.size()));
}

TEST(FrfNoise, NoiseFreeDataGetTheSmallestRelativeNoiseNotInfiniteWeights) {
  const Truth t = MakeTruth();
  const dynamics::Frf frf = dynamics::Frf::FromSamples(t.f, t.h);
  const FrfNoise n = EstimateFrfNoise(frf);
  EXPECT_GE(n.relative, 1e-6 * (1 - 1e-12));
  EXPECT_TRUE(n.sigma_m_per_N.allFinite());
  EXPECT_GT(n.sigma_m_per_N.minCoeff(), 0.0);
}

TEST(FrfNoise, RejectsBadOptionsAndTooFewLines) {
  NoiseOptions o;
  o.min_snr = 0.0;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
  const dynamics::Frf tiny =
      dynamics::Frf::FromSamples(Eigen::VectorXd::LinSpaced(5, 1, 5), Eigen::VectorXcd::Ones(5));
  EXPECT_THROW(EstimateFrfNoise(tiny), std::invalid_argument);
}

// A clear resonance in noisy data is found by the modal fit on the usable
// lines with the noise weights (issue #10 §3).
TEST(FrfNoise, ModalFitOnTheUsableLinesFindsEveryMode) {
  const Truth t = MakeTruth();
  for (unsigned seed : {11u, 12u}) {
    dynamics::FrfSet set;
    set.Insert({"P1", Axis::kX, Axis::kX}, Noisy(t, 0.02, seed));
    const dynamics::FrfSet usable = UsableData(set, EstimateNoise(set));
    const ModalFitResult fit = FitModes(usable.at({"P1", Axis::kX, Axis::kX}));
    ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
    for (double fn : {12.0, 45.0, 180.0}) {
      double best = 1e9;
      for (const auto& m : fit.modes) best = std::min(best, std::abs(m.freq_hz / fn - 1.0));
      EXPECT_LT(best, 0.005) << fn << " Hz, seed " << seed << ": " << fit.message;
    }
  }
}

}  // namespace
}  // namespace robomach::calibration
