// FRF estimation from impact records (issue #18, item 4), on hits simulated
// by time integration of a known 3-DOF chain (hammer_simulation.h), with
// sensor noise, an accelerometer channel, one double hit and one clipped
// hit. References: the analytic FRF (K − ω²M + iωC)⁻¹ of the chain, its
// state-matrix eigenvalues, and the known biases of H1 and H2.
#include "robomach/calibration/frf_estimate.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "calibration/hammer_simulation.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/common/units.h"

namespace robomach::calibration {
namespace {

using testing::AcquisitionSpec;
using testing::HammerSimulator;
using testing::HitSpec;
using testing::ThreeDofChain;
using ::testing::HasSubstr;
using ::testing::Not;

// Six good hits of different strength and timing, then a double hit (a
// rebound 12 ms later at 45 % of the peak) and a hit that clips the
// accelerometer (a hard hit into a ±40 m/s² range).
// Sensor noise as in AcquisitionSpec (force 0.05 N, displacement 20 nm,
// acceleration 0.05 m/s² rms), or none (then only the acquisition's filter
// and the simulation's hold differ from the analytic FRF).
std::vector<ImpactRecord> CampaignHits(const ThreeDofChain& sys, unsigned seed, bool noise) {
  std::mt19937 rng(seed);
  std::vector<ImpactRecord> hits;
  const double peaks[6] = {180, 220, 150, 240, 200, 170};
  const double starts[6] = {0.020, 0.031, 0.017, 0.026, 0.022, 0.035};
  AcquisitionSpec acq;
  if (!noise) acq.force_noise_N = acq.disp_noise_m = acq.acc_noise_m_per_s2 = 0.0;
  HammerSimulator sim(sys, acq);
  for (int i = 0; i < 6; ++i) {
    HitSpec h;
    h.peak_N = peaks[i];
    h.start_s = starts[i];
    hits.push_back(sim.Simulate(h, &rng, std::to_string(i + 1)));
  }
  HitSpec dbl;
  dbl.second_peak_N = 0.45 * dbl.peak_N;
  dbl.second_delay_s = 0.012;
  hits.push_back(sim.Simulate(dbl, &rng, "7"));
  AcquisitionSpec clip = acq;
  clip.acc_clip_m_per_s2 = 40.0;  // the good hits peak below 34 m/s², this one at 56
  HitSpec hard;
  hard.peak_N = 400.0;
  hits.push_back(HammerSimulator(sys, clip).Simulate(hard, &rng, "8"));
  return hits;
}

struct Comparison {
  int lines{0};          // lines with γ² > 0.9
  int within_2pc{0};     // of which within 2 %
  double max_rel{0.0};   // max |H1 − H| / |H| there
  double worst_f{0.0};
  /// max of (|H1 − H| / |H| − 2 %) / ε_c, ε_c the line's random error
  /// (see below): how many standard deviations beyond 2 % the worst line is.
  double max_excess_sigma{0.0};
  double excess_f{0.0};
  double rms_normalised{0.0};  // rms of |H1 − H| / (|H| ε_c): ≈ 1 for pure random error
};

// The normalised random error of an H1 estimate from n averages with
// coherence γ² [Bendat & Piersol 2010, ch. 9]: |H1| / |H| scatters with
// ε_r = sqrt(1 − γ²) / (|γ| sqrt(2n)), and so does its phase (in rad); the
// complex error |H1 − H| / |H| has rms ε_c = √2 ε_r. At γ² = 0.9 and
// n = 6, ε_r = 9.6 %: the "2 % where the coherence is above 0.9"
// cannot hold line by line with noise, only up to this random error.
double RandomError(double coherence, int n) {
  return std::sqrt((1.0 - coherence) / (n * coherence));
}

template <typename Truth>
Comparison Compare(const FrfEstimateResult& r, int channel, Truth truth) {
  Comparison c;
  for (int k = 0; k < r.freq_hz.size(); ++k) {
    const double g = r.channels[channel].coherence(k);
    if (g <= 0.9) continue;
    const std::complex<double> h = truth(r.freq_hz(k));
    const double e = std::abs(r.channels[channel].h1(k) - h) / std::abs(h);
    ++c.lines;
    if (e <= 0.02) ++c.within_2pc;
    if (e > c.max_rel) {
      c.max_rel = e;
      c.worst_f = r.freq_hz(k);
    }
    const double eps = std::max(RandomError(g, r.averages), 1e-12);
    c.rms_normalised += (e / eps) * (e / eps);
    const double excess = (e - 0.02) / eps;
    if (excess > c.max_excess_sigma) {
      c.max_excess_sigma = excess;
      c.excess_f = r.freq_hz(k);
    }
  }
  c.rms_normalised = std::sqrt(c.rms_normalised / std::max(c.lines, 1));
  return c;
}

class FrfEstimateCampaign : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sys_ = new ThreeDofChain(ThreeDofChain::Default());
    hits_ = new std::vector<ImpactRecord>(CampaignHits(*sys_, 7, true));
    clean_ = new std::vector<ImpactRecord>(CampaignHits(*sys_, 7, false));
  }
  static void TearDownTestSuite() {
    delete hits_;
    delete clean_;
    delete sys_;
  }
  static ThreeDofChain* sys_;
  static std::vector<ImpactRecord>* hits_;
  static std::vector<ImpactRecord>* clean_;
};
std::vector<ImpactRecord>* FrfEstimateCampaign::clean_ = nullptr;
ThreeDofChain* FrfEstimateCampaign::sys_ = nullptr;
std::vector<ImpactRecord>* FrfEstimateCampaign::hits_ = nullptr;

// The acceptance: the double and the clipped hit are rejected and
// named, and the H1 of the six good hits is within 2 % of the analytic FRF
// wherever the coherence is above 0.9 (drive-point receptance and transfer
// accelerance). With sensor noise, "within 2 %" holds up to the random
// error of a six-hit average (see RandomError): every coherent line is
// within 2 % + 4 ε_c. A complex Gaussian error exceeds k times its rms with
// probability e^{−k²}, 1e-7 per line for k = 4; the margin covers the
// estimated coherence's upward bias with six averages, which makes ε_c
// come out small [Bendat & Piersol 2010, ch. 9]. And the errors are the
// random error and not a bias: their rms in units of ε_c is about 1.
TEST_F(FrfEstimateCampaign, RejectsDoubleAndClippedHitsAndMatchesAnalyticFrf) {
  const FrfEstimateResult r = EstimateFrf(*hits_, testing::SimulatedChannels());
  ASSERT_EQ(r.status, FrfEstimateStatus::kOk);
  ASSERT_EQ(r.hits.size(), 8u);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(r.hits[i].status, HitStatus::kAccepted) << r.hits[i].id;
  EXPECT_EQ(r.averages, 6);
  EXPECT_EQ(r.hits[6].status, HitStatus::kDoubleHit);
  ASSERT_FALSE(r.hits[6].notes.empty());
  // The rebound: 12 ms after the start at 0.020 s, peak 0.3 ms later.
  EXPECT_THAT(r.hits[6].notes[0], HasSubstr("double hit: a second force pulse at t = 0.032"));
  EXPECT_EQ(r.hits[7].status, HitStatus::kOverload);
  ASSERT_FALSE(r.hits[7].notes.empty());
  EXPECT_THAT(r.hits[7].notes[0], HasSubstr("response a3 is clipped"));
  EXPECT_FALSE(r.leakage);

  // Band: Δf = 1 Hz to fs/2.56 = 1600 Hz.
  EXPECT_DOUBLE_EQ(r.freq_hz(0), 1.0);
  EXPECT_DOUBLE_EQ(r.freq_hz(r.freq_hz.size() - 1), 1600.0);
  const Comparison rec = Compare(r, 0, [&](double f) { return sys_->Receptance(f)(0, 0); });
  const Comparison acc = Compare(r, 1, [&](double f) { return sys_->Accelerance(f)(2, 0); });
  for (const auto& [name, c] : {std::pair{"receptance", rec}, std::pair{"accelerance", acc}}) {
    std::printf("noisy, %s: %d coherent lines, %d within 2 %%, max error %.2f %% at %.0f Hz, worst %.2f "
                "sigma beyond 2 %% at %.0f Hz, rms error %.2f sigma\n",
                name, c.lines, c.within_2pc, 100 * c.max_rel, c.worst_f, c.max_excess_sigma, c.excess_f,
                c.rms_normalised);
  }
  // Most of the band is coherent: the accelerometer's floor (0.05 m/s²)
  // hides the transfer accelerance below ~10 Hz and above ~600 Hz, where it
  // falls as f⁻² beyond the last mode; anti-resonances take a few lines.
  EXPECT_GT(rec.lines, 1400);
  EXPECT_GT(acc.lines, 300);
  EXPECT_LT(rec.max_excess_sigma, 4.0) << "at " << rec.excess_f << " Hz";
  EXPECT_LT(acc.max_excess_sigma, 4.0) << "at " << acc.excess_f << " Hz";
  // rms of a unit-variance error over > 300 lines: 1 ± 0.1; the coherence's
  // bias with six averages pushes it up (measured 1.2 to 1.4); 2 would be a
  // systematic error as large as the random one.
  EXPECT_GT(rec.rms_normalised, 0.7);
  EXPECT_LT(rec.rms_normalised, 2.0);
  EXPECT_GT(acc.rms_normalised, 0.7);
  EXPECT_LT(acc.rms_normalised, 2.0);
}

// The same checks on hits with another noise draw, not looked at while the
// noise levels and bounds above were chosen.
TEST_F(FrfEstimateCampaign, UntunedSeedStaysWithinTheRandomError) {
  for (const unsigned seed : {2024u, 31337u}) {
    const FrfEstimateResult r = EstimateFrf(CampaignHits(*sys_, seed, true), testing::SimulatedChannels());
    ASSERT_EQ(r.averages, 6) << seed;
    EXPECT_EQ(r.hits[6].status, HitStatus::kDoubleHit);
    EXPECT_EQ(r.hits[7].status, HitStatus::kOverload);
    const Comparison rec = Compare(r, 0, [&](double f) { return sys_->Receptance(f)(0, 0); });
    const Comparison acc = Compare(r, 1, [&](double f) { return sys_->Accelerance(f)(2, 0); });
    std::printf("seed %u: receptance %d/%d lines within 2 %%, worst %.2f sigma beyond; accelerance %d/%d, %.2f\n",
                seed, rec.within_2pc, rec.lines, rec.max_excess_sigma, acc.within_2pc, acc.lines,
                acc.max_excess_sigma);
    // Bounds as in RejectsDoubleAndClippedHitsAndMatchesAnalyticFrf.
    EXPECT_LT(rec.max_excess_sigma, 4.0) << seed;
    EXPECT_LT(acc.max_excess_sigma, 4.0) << seed;
    EXPECT_LT(rec.rms_normalised, 2.0) << seed;
    EXPECT_LT(acc.rms_normalised, 2.0) << seed;
  }
}

// Every hit rejected: no estimate, a status rather than an exception.
TEST_F(FrfEstimateCampaign, AllRejectedIsAStatus) {
  FrfEstimateOptions o;
  o.force_range_N = 100.0;  // every hit peaks above 100 N
  const FrfEstimateResult r = EstimateFrf(*hits_, testing::SimulatedChannels(), o);
  EXPECT_EQ(r.status, FrfEstimateStatus::kNoHits);
  EXPECT_EQ(r.averages, 0);
  EXPECT_TRUE(r.channels.empty());
  ASSERT_EQ(r.hits.size(), 8u);
  EXPECT_THAT(r.hits[0].notes.back(), HasSubstr("overload: force reaches"));
}

// The acceptance without sensor noise: the estimator's own errors (windows,
// offsets, the FFT) on top of the acquisition filter and the simulation's
// hold (0.2 % at 1600 Hz) are below 2 % on every coherent line, and every
// line is coherent.
TEST_F(FrfEstimateCampaign, WithoutSensorNoiseEveryLineIsWithinTwoPercent) {
  const FrfEstimateResult r = EstimateFrf(*clean_, testing::SimulatedChannels());
  ASSERT_EQ(r.averages, 6);
  const Comparison rec = Compare(r, 0, [&](double f) { return sys_->Receptance(f)(0, 0); });
  const Comparison acc = Compare(r, 1, [&](double f) { return sys_->Accelerance(f)(2, 0); });
  std::printf("clean, receptance: %d coherent lines, max error %.3f %% at %.0f Hz\n", rec.lines,
              100 * rec.max_rel, rec.worst_f);
  std::printf("clean, accelerance: %d coherent lines, max error %.3f %% at %.0f Hz\n", acc.lines,
              100 * acc.max_rel, acc.worst_f);
  EXPECT_EQ(rec.lines, 1600);
  EXPECT_EQ(acc.lines, 1600);
  EXPECT_LT(rec.max_rel, 0.02) << "worst at " << rec.worst_f << " Hz";
  EXPECT_LT(acc.max_rel, 0.02) << "worst at " << acc.worst_f << " Hz";
}

// γ² = H1 / H2 (eq. (3)) holds line by line whatever the noise: a second
// formula for the coherence.
TEST_F(FrfEstimateCampaign, CoherenceIsTheRatioOfH1ToH2) {
  const FrfEstimateResult r = EstimateFrf(*hits_, testing::SimulatedChannels());
  for (int c = 0; c < 2; ++c) {
    for (int k = 0; k < r.freq_hz.size(); ++k) {
      const std::complex<double> ratio = r.channels[c].h1(k) / r.channels[c].h2(k);
      // Both sides are formed from the same sums; rounding only (1e-12).
      EXPECT_NEAR(ratio.real(), r.channels[c].coherence(k), 1e-12) << k;
      EXPECT_NEAR(ratio.imag(), 0.0, 1e-12) << k;
    }
  }
}

// Near resonances, away from anti-resonances, the coherence is close to 1.
TEST_F(FrfEstimateCampaign, CoherenceNearOneAtResonances) {
  const FrfEstimateResult r = EstimateFrf(*hits_, testing::SimulatedChannels());
  for (const auto& [fn, zeta] : sys_->Modes()) {
    const int k = static_cast<int>(std::lround(fn)) - 1;  // Δf = 1 Hz from 1 Hz
    // At a resonance the response is 20-40 dB above the noise floors, so
    // 1 − γ² ≈ noise/signal power < 1e-3.
    EXPECT_GT(r.channels[0].coherence(k), 0.999) << fn << " Hz";
    EXPECT_GT(r.channels[1].coherence(k), 0.999) << fn << " Hz";
  }
}

// Rejected hits do not enter the average: the estimate with them rejected
// equals the estimate of the six good hits alone.
TEST_F(FrfEstimateCampaign, RejectedHitsAreNotAveraged) {
  const FrfEstimateResult all = EstimateFrf(*hits_, testing::SimulatedChannels());
  const std::vector<ImpactRecord> good(hits_->begin(), hits_->begin() + 6);
  const FrfEstimateResult six = EstimateFrf(good, testing::SimulatedChannels());
  ASSERT_EQ(six.averages, 6);
  EXPECT_EQ((all.channels[1].h1 - six.channels[1].h1).cwiseAbs().maxCoeff(), 0.0);
}

// The exponential window makes the estimate the FRF of h(t) e^{−t/τ}, i.e.
// H evaluated at s = iω + 1/τ; the modal fit of that FRF then has damping
// ratios too high by ≈ 1/(τ ω_n), and CorrectExponentialWindowDamping gives
// back the chain's damping from its state-matrix eigenvalues.
TEST_F(FrfEstimateCampaign, ExponentialWindowAndDampingCorrection) {
  FrfEstimateOptions o;
  o.exponential_tau_s = 0.1;  // ζ shift 1/(τω) = 0.038 at 42 Hz, about the mode's own damping
  const std::vector<ImpactRecord> good(clean_->begin(), clean_->begin() + 6);
  const FrfEstimateResult r = EstimateFrf(good, testing::SimulatedChannels(), o);
  const double a = 1.0 / o.exponential_tau_s;
  const Comparison rec = Compare(r, 0, [&](double f) { return sys_->Receptance(f, a)(0, 0); });
  EXPECT_GT(rec.lines, 1400);
  // As above: 2 %.
  EXPECT_LT(rec.max_rel, 0.02) << "worst at " << rec.worst_f << " Hz";

  // Modal fit of the windowed drive-point receptance, 1..600 Hz.
  const dynamics::Frf frf = dynamics::Frf::FromSamples(r.freq_hz, r.channels[0].h1, r.channels[0].coherence);
  ModalFitOptions fo;
  fo.fmax_hz = 600.0;
  ModalFitResult fit = FitModes(frf, fo);
  ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
  const auto truth = sys_->Modes();
  ASSERT_EQ(fit.modes.size(), truth.size());
  std::vector<FittedMode> corrected = fit.modes;
  CorrectExponentialWindowDamping(o.exponential_tau_s, &corrected);
  for (size_t m = 0; m < truth.size(); ++m) {
    const auto [fn, zeta] = truth[m];
    const double shift = 1.0 / (o.exponential_tau_s * HzToRadPerSec(fn));
    std::printf("mode %zu: %.2f Hz, zeta true %.4f, windowed fit %.4f (expected +%.4f), corrected %.4f\n", m,
                fn, zeta, fit.modes[m].damping_ratio, shift, corrected[m].damping_ratio);
    // The windowed fit is off by the window's shift...
    EXPECT_GT(fit.modes[m].damping_ratio - zeta, 0.8 * shift);
    // ...and the corrected damping matches the eigenvalues to 2 % of ζ,
    // with frequency to 0.1 %: the FRF itself is within 2 % of the truth
    // over the half-power band, and the fitted pole inherits at most that.
    EXPECT_NEAR(corrected[m].damping_ratio, zeta, 0.02 * zeta) << fn << " Hz";
    EXPECT_NEAR(corrected[m].freq_hz, fn, 1e-3 * fn);
    // The scalar form agrees with the pole form.
    const auto [f2, z2] =
        CorrectExponentialWindowDamping(fit.modes[m].freq_hz, fit.modes[m].damping_ratio, o.exponential_tau_s);
    EXPECT_NEAR(f2, corrected[m].freq_hz, 1e-9 * fn);
    EXPECT_NEAR(z2, corrected[m].damping_ratio, 1e-12);
  }
}

// Short records of a lightly damped structure leak; the estimator says so.
TEST(FrfEstimate, ShortRecordIsReportedAsLeakage) {
  const ThreeDofChain sys = ThreeDofChain::Default();
  AcquisitionSpec acq;
  acq.samples = 512;  // 0.125 s: the 70 Hz mode (decay time ≈ 0.1 s) is still ringing
  std::mt19937 rng(3);
  HammerSimulator sim(sys, acq);
  std::vector<ImpactRecord> hits;
  for (int i = 0; i < 3; ++i) hits.push_back(sim.Simulate(HitSpec{}, &rng, std::to_string(i + 1)));
  const FrfEstimateResult r = EstimateFrf(hits, testing::SimulatedChannels());
  EXPECT_TRUE(r.leakage);
  FrfEstimateOptions o;
  o.exponential_tau_s = 0.02;  // e^{-0.105/0.02} = 0.5 % at the end
  const FrfEstimateResult w = EstimateFrf(hits, testing::SimulatedChannels(), o);
  EXPECT_FALSE(w.leakage);
  // The verdict: leakage flags the leaking estimate; 3 hits against a
  // minimum of 5 flag both; the windowed one with a minimum of 3 is ok.
  const RunFindings leak = JudgeFrfEstimate(r, 3);
  ASSERT_EQ(leak.findings.size(), 1u);
  EXPECT_NE(leak.findings[0].message.find("leakage"), std::string::npos);
  const RunFindings few = JudgeFrfEstimate(r, 5, "--min-hits");
  ASSERT_EQ(few.findings.size(), 2u);
  EXPECT_EQ(few.findings[0].message, "3 accepted hit(s), fewer than --min-hits 5");
  EXPECT_EQ(JudgeFrfEstimate(w, 3).status(), RunStatus::kOk);
}

// Wrong units on purpose: responses recorded in mm under columns named in m
// (x 1000), or a force in kN under force_N (/ 1000), give receptances three
// decades too large; the simulated chain's peaks are ~1e-5 m/N, so the
// estimate must be flagged implausible, and the same hits in SI must not be.
TEST(FrfEstimate, ResponsesInMillimetresAreFlaggedAsAUnitMistake) {
  const ThreeDofChain sys = ThreeDofChain::Default();
  std::mt19937 rng(5);
  HammerSimulator sim(sys, AcquisitionSpec{});
  std::vector<ImpactRecord> si, mm, kn;
  for (int i = 0; i < 3; ++i) si.push_back(sim.Simulate(HitSpec{}, &rng, std::to_string(i + 1)));
  for (ImpactRecord h : si) {
    h.response *= 1000.0;
    mm.push_back(h);
  }
  for (ImpactRecord h : si) {
    h.force_N /= 1000.0;
    kn.push_back(h);
  }
  EXPECT_FALSE(EstimateFrf(si, testing::SimulatedChannels()).implausible);
  const FrfEstimateResult r = EstimateFrf(mm, testing::SimulatedChannels());
  EXPECT_TRUE(r.implausible);
  bool named = false;
  for (const std::string& w : r.warnings) named = named || w.find("probably recorded in mm") != std::string::npos;
  EXPECT_TRUE(named);
  EXPECT_TRUE(EstimateFrf(kn, testing::SimulatedChannels()).implausible);
}

// A prime record length (4099) is cut to 4096 for the FFT, with a warning,
// and the estimate is still the analytic FRF (clean data, 2 %).
TEST(FrfEstimate, PrimeLengthIsCutToAFastLength) {
  const ThreeDofChain sys = ThreeDofChain::Default();
  AcquisitionSpec acq;
  acq.samples = 4099;  // 1 s: the slowest decay (41.7 Hz, ζ 0.042, 1/(ζω) = 0.09 s) is at e^-11 by the end
  acq.force_noise_N = acq.disp_noise_m = acq.acc_noise_m_per_s2 = 0.0;
  std::mt19937 rng(5);
  HammerSimulator sim(sys, acq);
  std::vector<ImpactRecord> hits;
  for (int i = 0; i < 3; ++i) hits.push_back(sim.Simulate(HitSpec{}, &rng, std::to_string(i + 1)));
  const FrfEstimateResult r = EstimateFrf(hits, testing::SimulatedChannels());
  EXPECT_EQ(r.block_samples, 4096);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_THAT(r.warnings[0], HasSubstr("the last 3 of 4099 samples are dropped"));
  EXPECT_DOUBLE_EQ(r.freq_hz(0), 1.0);  // 4096 Hz / 4096
  double worst = 0.0;
  for (int k = 0; k < r.freq_hz.size(); ++k) {
    const std::complex<double> h = sys.Receptance(r.freq_hz(k))(0, 0);
    worst = std::max(worst, std::abs(r.channels[0].h1(k) - h) / std::abs(h));
  }
  EXPECT_LT(worst, 0.02);
}

// An fmax far above the Nyquist frequency (1e12, 1e20, 1e308 Hz) once
// overflowed the int line count into "fmax_hz 1e+12 is below the line
// spacing": the lines stop at fs/2 and the result says why.
TEST(FrfEstimate, HugeFmaxStopsAtNyquistWithAWarning) {
  const ThreeDofChain sys = ThreeDofChain::Default();
  AcquisitionSpec acq;
  acq.samples = 4096;
  acq.force_noise_N = acq.disp_noise_m = acq.acc_noise_m_per_s2 = 0.0;
  std::mt19937 rng(5);
  HammerSimulator sim(sys, acq);
  std::vector<ImpactRecord> hits;
  for (int i = 0; i < 3; ++i) hits.push_back(sim.Simulate(HitSpec{}, &rng, std::to_string(i + 1)));
  for (const double fmax : {1e6, 1e12, 1e20, 1e308}) {
    FrfEstimateOptions o;
    o.fmax_hz = fmax;
    const FrfEstimateResult r = EstimateFrf(hits, testing::SimulatedChannels(), o);
    ASSERT_EQ(r.freq_hz.size(), 2048) << fmax;  // 1 .. 2048 Hz = fs/2
    EXPECT_DOUBLE_EQ(r.freq_hz(r.freq_hz.size() - 1), 2048.0);
    bool named = false;
    for (const std::string& w : r.warnings) named |= w.find("above the Nyquist frequency 2048 Hz") != std::string::npos;
    EXPECT_TRUE(named) << fmax;
  }
  FrfEstimateOptions o;
  o.fmax_hz = 2048.0;  // exactly Nyquist: no warning
  for (const std::string& w : EstimateFrf(hits, testing::SimulatedChannels(), o).warnings) {
    EXPECT_THAT(w, Not(HasSubstr("Nyquist")));
  }
}

// One or two averaged hits: the coherence cannot mean much, and the result
// says so in its warnings (the tool prints them, Python returns them); three
// hits do not warn about it.
TEST(FrfEstimate, FewHitsWarnAboutTheCoherence) {
  const ThreeDofChain sys = ThreeDofChain::Default();
  AcquisitionSpec acq;
  std::mt19937 rng(11);
  HammerSimulator sim(sys, acq);
  std::vector<ImpactRecord> hits;
  for (int i = 0; i < 3; ++i) hits.push_back(sim.Simulate(HitSpec{}, &rng, std::to_string(i + 1)));
  auto warns = [](const FrfEstimateResult& r, const std::string& text) {
    for (const std::string& w : r.warnings) {
      if (w.find(text) != std::string::npos) return true;
    }
    return false;
  };
  const FrfEstimateResult one = EstimateFrf({hits[0]}, testing::SimulatedChannels());
  ASSERT_EQ(one.averages, 1);
  EXPECT_TRUE(warns(one, "one accepted hit: the coherence is 1 on every line"));
  const FrfEstimateResult two = EstimateFrf({hits[0], hits[1]}, testing::SimulatedChannels());
  ASSERT_EQ(two.averages, 2);
  EXPECT_TRUE(warns(two, "only 2 hits averaged"));
  const FrfEstimateResult three = EstimateFrf(hits, testing::SimulatedChannels());
  ASSERT_EQ(three.averages, 3);
  EXPECT_FALSE(warns(three, "hits averaged") || warns(three, "one accepted hit"));
}

// The known biases [Bendat & Piersol 2010]: noise on the response
// only leaves H1 unbiased and biases H2 up by 1/γ²; noise on the force only
// (no force window, so that it stays) leaves H2 unbiased and biases H1 down.
// Checked at lines with 0.3 < γ² < 0.8, the anti-resonance regions.
TEST(FrfEstimate, H1AndH2BiasesWithInputAndOutputNoise) {
  const ThreeDofChain sys = ThreeDofChain::Default();
  for (const bool output_noise : {true, false}) {
    AcquisitionSpec acq;
    acq.samples = 2048;
    acq.oversample = 4;  // coarser hold: the bias to detect is > 10 %
    acq.force_noise_N = output_noise ? 0.0 : 2.0;
    acq.disp_noise_m = output_noise ? 2e-6 : 0.0;
    acq.acc_noise_m_per_s2 = output_noise ? 2.0 : 0.0;
    std::mt19937 rng(11);
    HammerSimulator sim(sys, acq);
    std::vector<ImpactRecord> hits;
    for (int i = 0; i < 40; ++i) hits.push_back(sim.Simulate(HitSpec{}, &rng, std::to_string(i + 1)));
    FrfEstimateOptions o;
    o.force_window_s = -1.0;  // off: keep the force noise
    const FrfEstimateResult r = EstimateFrf(hits, testing::SimulatedChannels(), o);
    double log_h1 = 0, log_h2 = 0;
    int n = 0;
    for (int k = 0; k < r.freq_hz.size(); ++k) {
      const double g = r.channels[0].coherence(k);
      if (g < 0.3 || g > 0.8) continue;
      const double h = std::abs(sys.Receptance(r.freq_hz(k))(0, 0));
      log_h1 += std::log(std::abs(r.channels[0].h1(k)) / h);
      log_h2 += std::log(std::abs(r.channels[0].h2(k)) / h);
      ++n;
    }
    ASSERT_GT(n, 10) << "too few partly coherent lines to judge";
    log_h1 /= n;
    log_h2 /= n;
    std::printf("%s noise: %d lines, mean log(|H1|/|H|) = %.3f, log(|H2|/|H|) = %.3f\n",
                output_noise ? "output" : "input", n, log_h1, log_h2);
    // With 0.3 < γ² < 0.8 the biased estimator is off by −ln γ² ∈ (0.22,
    // 1.2) on average; the unbiased one scatters with ≈ sqrt((1−γ²)/(2nγ²))
    // ≈ 0.1 per line, averaged over > 10 lines: < 0.1.
    if (output_noise) {
      EXPECT_LT(std::abs(log_h1), 0.1);
      EXPECT_GT(log_h2, 0.2);
    } else {
      EXPECT_LT(std::abs(log_h2), 0.1);
      EXPECT_LT(log_h1, -0.2);
    }
  }
}

// Flat tops: a clipped sine is found; a slow, coarsely quantised sine that
// repeats its extreme value a few times is not (it steps in by one quantum).
TEST(DetectFlatTop, ClippedVersusQuantised) {
  const int n = 2000;
  Eigen::VectorXd clipped(n), quantised(n);
  for (int i = 0; i < n; ++i) {
    const double s = std::sin(2 * kPi * i / 1000.0);
    clipped(i) = std::min(s, 0.8);
    quantised(i) = std::round(s * 100.0) / 100.0;  // ~12 samples at the peak value
  }
  EXPECT_EQ(DetectFlatTop(clipped, 3), 148);  // asin(0.8)/(2π)·1000 = 147.6
  EXPECT_EQ(DetectFlatTop(quantised, 3), -1);
  Eigen::VectorXd q_clip = quantised.cwiseMin(0.8);
  EXPECT_GE(DetectFlatTop(q_clip, 3), 0);
  // A fast decaying response (6 samples per cycle) clipped at 0.6 of its
  // first peak: single clipped samples in three cycles (rule b); unclipped,
  // its maximum occurs once.
  Eigen::VectorXd fast(600);
  for (int i = 0; i < 600; ++i) fast(i) = std::exp(-i / 60.0) * std::sin(2 * kPi * i / 6.0 + 0.3);
  EXPECT_EQ(DetectFlatTop(fast, 3), -1);
  const Eigen::VectorXd fast_clip = fast.cwiseMin(0.6);
  EXPECT_EQ(DetectFlatTop(fast_clip, 3), 1);
  // Quantised to 1/5000 of its peak it still is not clipped: the peak
  // occurs once.
  const Eigen::VectorXd fast_q = (fast * 5000.0).array().round() / 5000.0;
  EXPECT_EQ(DetectFlatTop(fast_q, 3), -1);
}

TEST(CorrectExponentialWindowDamping, FirstOrderShift) {
  // ζ_m = ζ + 1/(τ ω_n) to first order; exact for the pole: check both ways.
  const double fn = 100.0, zeta = 0.02, tau = 0.1;
  const double wn = HzToRadPerSec(fn);
  const std::complex<double> pole(-zeta * wn - 1.0 / tau, wn * std::sqrt(1 - zeta * zeta));
  const auto [f, z] = CorrectExponentialWindowDamping(std::abs(pole) / (2 * kPi), -pole.real() / std::abs(pole), tau);
  EXPECT_NEAR(f, fn, 1e-9 * fn);
  EXPECT_NEAR(z, zeta, 1e-12);
  EXPECT_THROW(CorrectExponentialWindowDamping(100.0, 0.02, 0.0), std::invalid_argument);
}

TEST(FrfEstimateOptions, ValidationNamesTheField) {
  FrfEstimateOptions o;
  o.exponential_tau_s = -1;
  try {
    o.Validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("exponential_tau_s = -1"));
  }
}

// Issue #34 item 5: a single raw hit on a tool tip (the chain stiffened to
// modes near 1-2.6 kHz, receptance peaks ~1e-6 m/N, as a machining tool
// tip) whose accelerometer drifts: slow baseline wander (white noise
// through a first-order low-pass at 2 Hz, 0.3 m/s² rms) added to the
// acceleration channel. Divided by ω², it makes the lowest lines of the
// receptance 1e-3 m/N and more: the largest median of three over all
// coherent lines (the former check, computed here from H1) exceeds
// kMaxPlausibleReceptance, but on the band the noise model finds usable the
// largest is the tool tip's own, and the estimate is not flagged. The same
// hit with the response in um under _m (x1e6) still is.
TEST(FrfEstimate, DriftOfASingleHitIsNoUnitMistake) {
  ThreeDofChain sys = ThreeDofChain::Default();
  // Frequencies x25 (K/M x625), receptance /10 (K x10): M x0.016; C x0.4
  // keeps the damping ratios (ζ ∝ c/√(km)).
  sys.K *= 10.0;
  sys.M *= 10.0 / 625.0;
  sys.C *= 0.4;
  const std::vector<std::pair<double, double>> modes = sys.Modes();
  ASSERT_EQ(modes.size(), 3u);
  ASSERT_GT(modes.front().first, 800.0);
  ASSERT_LT(modes.back().first, 4500.0);
  AcquisitionSpec acq;
  acq.fs_hz = 12800.0;  // lines to 5000 Hz
  acq.samples = 6400;   // 2 Hz lines (0.5 s: the slowest decay, 1/(ζω) of a few ms, is long over)
  acq.oversample = 8;
  HammerSimulator sim(sys, acq);
  std::mt19937 rng(34);
  HitSpec spec;
  spec.pulse_s = 0.00015;  // a steel tip on a tool: the force spectrum flat well past 5 kHz
  ImpactRecord hit = sim.Simulate(spec, &rng, "1");
  std::normal_distribution<double> n01(0.0, 1.0);
  const double a = std::exp(-2.0 * M_PI * 2.0 / acq.fs_hz);  // first-order low-pass at 2 Hz
  double d = 0.0;
  std::vector<double> drift(acq.samples);
  double ms = 0.0;
  for (int k = 0; k < acq.samples; ++k) {
    d = a * d + (1.0 - a) * n01(rng);
    drift[k] = d;
    ms += d * d;
  }
  const double scale = 0.3 / std::sqrt(ms / acq.samples);
  for (int k = 0; k < acq.samples; ++k) hit.response(k, 1) += scale * drift[k];

  const FrfEstimateResult r = EstimateFrf({hit}, testing::SimulatedChannels());
  ASSERT_EQ(r.status, FrfEstimateStatus::kOk);
  // The former check, by its definition: the largest median of three
  // neighbouring |H1|/ω² over all lines (one hit: coherence 1 everywhere).
  const Eigen::VectorXcd& h1 = r.channels[1].h1;
  double all_lines = 0.0, true_peak = 0.0;
  for (int k = 1; k + 1 < h1.size(); ++k) {
    double m[3];
    for (int j = 0; j < 3; ++j) {
      const double w = HzToRadPerSec(r.freq_hz(k - 1 + j));
      m[j] = std::abs(h1(k - 1 + j)) / (w * w);
    }
    std::sort(m, m + 3);
    all_lines = std::max(all_lines, m[1]);
    true_peak = std::max(true_peak, std::abs(sys.Receptance(r.freq_hz(k))(2, 0)));
  }
  EXPECT_GT(all_lines, kMaxPlausibleReceptance) << "the drift no longer reproduces the former false alarm";
  EXPECT_GT(true_peak, 1e-7);
  EXPECT_LT(true_peak, 1e-5);
  EXPECT_FALSE(r.implausible);
  for (const std::string& w : r.warnings) EXPECT_THAT(w, ::testing::Not(HasSubstr("plausible"))) << w;
  // On its usable band, the largest receptance of the drifting channel is
  // the tool tip's: within 10 % of the analytic peak (one hit with 0.01 m/s²
  // sensor noise on a peak acceleration of thousands of m/s², and the
  // median of three on 2 Hz lines beside a half-power width of tens of Hz:
  // both well under 1 %; 10 % leaves room for the acquisition filter).
  Eigen::VectorXcd rec(h1.size());
  for (int k = 0; k < h1.size(); ++k) rec(k) = h1(k) / std::pow(HzToRadPerSec(r.freq_hz(k)), 2);
  const UsableBandPeak p = PeakReceptanceInUsableBand(dynamics::Frf::FromSamples(r.freq_hz, rec, r.channels[1].coherence), 1);
  EXPECT_TRUE(p.on_usable_band);
  EXPECT_NEAR(p.peak_m_per_N / true_peak, 1.0, 0.1);
  // The response in um under an _m column: flagged, and the band named.
  ImpactRecord um = hit;
  um.response *= 1e6;
  const FrfEstimateResult ru = EstimateFrf({um}, testing::SimulatedChannels());
  EXPECT_TRUE(ru.implausible);
  bool named = false;
  for (const std::string& w : ru.warnings) {
    named = named || (w.find("probably recorded in mm or um") != std::string::npos &&
                      w.find("on the usable band") != std::string::npos);
  }
  EXPECT_TRUE(named);
}

}  // namespace
}  // namespace robomach::calibration
