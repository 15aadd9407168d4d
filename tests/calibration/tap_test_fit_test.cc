// Issue #18: the stabilised modal fit on a tool-tip tap test whose
// integrated accelerometer signal drifts below ~100 Hz. The data are made
// by tests/tap_test_synth.h from the modes' closed form; the fit must find
// those modes (and no mode in the drift) once the noise model has put the
// drift outside the usable band.
#include <gtest/gtest.h>

#include <cmath>

#include "../tap_test_synth.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/common/units.h"

namespace robomach::calibration {
namespace {

struct FitOfTap {
  FrfNoise noise;
  ModalFitResult fit;
};

FitOfTap FitTap(const testing::TapTest& t) {
  const dynamics::Frf frf = dynamics::Frf::FromSamples(t.freq_hz, t.measured);
  NoiseOptions no;
  no.wide_floor = true;  // a tap test with integrated-accelerometer drift
  FitOfTap out{EstimateFrfNoise(frf, no), {}};
  std::vector<int> lines;
  for (int i = 0; i < frf.size(); ++i) {
    if (out.noise.usable[i]) lines.push_back(i);
  }
  out.fit = FitModes(frf.WithNoise(out.noise.sigma_m_per_N).Select(lines));
  return out;
}

// Each fitted mode against the true one. Tolerances from the information
// in the data: a mode's parameters are carried by the ~2ζf/Δf lines of its
// half-power band (64 to 157 lines here), each with relative noise ε
// (1 % or 2 %), so the relative standard deviation of ζ and of the modal
// constant is about ε/√(2ζf/Δf) ≤ 2 %/8 = 2.5e-3, and that of the
// frequency ζ times that, ≤ 1e-4 (a Cramér-Rao estimate for a single mode
// [Pintelon & Schoukens 2012, ch. 7]). Asserted at about 4 of those
// standard deviations: 4e-4 on the frequency, 1 % on ζ and on the modal
// constant 1/m (measured on the acceptance case: 1.5e-5, 1e-3 and 2e-4).
void ExpectModes(const ModalFitResult& fit, const std::vector<testing::TapMode>& truth, double f_tol,
                 double rel_tol) {
  ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
  ASSERT_EQ(fit.modes.size(), truth.size()) << fit.message;
  for (size_t k = 0; k < truth.size(); ++k) {
    const FittedMode& m = fit.modes[k];
    EXPECT_NEAR(m.freq_hz, truth[k].freq_hz, f_tol * truth[k].freq_hz) << "mode " << k;
    EXPECT_NEAR(m.damping_ratio, truth[k].damping_ratio, rel_tol * truth[k].damping_ratio) << "mode " << k;
    // A = 1/m for a driving point (modal_fit.h), real up to the noise.
    const double A = 1.0 / truth[k].mass_kg();
    EXPECT_NEAR(m.modal_constant.real(), A, rel_tol * A) << "mode " << k;
    EXPECT_LT(std::abs(m.modal_constant.imag()), rel_tol * A) << "mode " << k;
  }
}

// The acceptance case of issue #18: three modes at 1074, 1961 and 2617 Hz,
// ζ = 0.03, 1 % noise, 1 Hz lines to 5 kHz, a drift smooth over 15 lines
// rising as 1/f² below 100 Hz to 5× the resonance peak at 20 Hz. Before the
// noise model looked at the drift with wide second differences, the drift
// smooth on the grid passed for signal down to 15-60 Hz on some seeds and
// the fit added modes there (18-80 Hz, ζ up to 0.26).
TEST(TapTestFit, FindsTheThreeModesAboveTheDrift) {
  const testing::TapTestOptions o;
  const testing::TapTest t = testing::MakeTapTest(o);
  const FitOfTap r = FitTap(t);
  // The drift's envelope is still 0.4 × the static compliance at 90 Hz
  // (then 1/10 of it with the 1/f² shape's zero at 100 Hz), so the band
  // must start near there, and it must not start inside the modes.
  ASSERT_FALSE(r.noise.usable_bands.empty());
  EXPECT_GT(r.noise.usable_bands.front().first, 60.0) << r.noise.description;
  EXPECT_LT(r.noise.usable_bands.front().first, 200.0) << r.noise.description;
  EXPECT_EQ(r.noise.usable_bands.back().second, 5000.0);
  ExpectModes(r.fit, o.modes, 4e-4, 0.01);
  // The fit is within the noise: rms misfit relative to |H| ≈ the 1 %.
  EXPECT_LT(r.fit.relative_rms_error, 0.02);
}

// Other seeds of the same test, drifts correlated over 1 to 30 lines, and
// an envelope flat below 20 Hz: the same modes, never one in the drift.
// (Seeds 101 and 103 gave a fourth mode at 66-78 Hz with wide second
// differences over 8 lines only; see frf_noise.cc.)
TEST(TapTestFit, OtherSeedsAndDriftWidthsGiveNoModeInTheDrift) {
  struct Case {
    unsigned seed;
    int lines;
    double flat_below_hz;
  };
  for (const Case& c : std::vector<Case>{{1, 15, 0.0}, {2, 3, 0.0}, {3, 1, 20.0}, {101, 15, 0.0}, {103, 30, 20.0}}) {
    testing::TapTestOptions o;
    o.seed = c.seed;
    o.drift_correlation_lines = c.lines;
    o.drift_flat_below_hz = c.flat_below_hz;
    const auto seed = c.seed;
    const auto lines = c.lines;
    const FitOfTap r = FitTap(testing::MakeTapTest(o));
    SCOPED_TRACE("seed " + std::to_string(seed) + ", drift over " + std::to_string(lines) + " lines");
    ExpectModes(r.fit, o.modes, 4e-4, 0.01);
  }
}

// A case not tuned on: two modes (650 Hz, ζ 0.02; 1400 Hz, ζ 0.05), 2 %
// relative noise, an accelerometer floor flat in accelerance (so rising as
// 1/f² in receptance at every line, white) and a flat one of 4e-10 m/N,
// with a hammer band limit at 3 kHz above which the floors rise as f⁸
// (SNR 3 near 3.7 kHz, 1.7 at 4 kHz), and a drift 10× the peak at
// 20 Hz correlated over 8 lines, 0.5 Hz lines to 4 kHz. Tolerances as
// above for ε = 2 % (the half-power bands hold 52 and 280 lines).
TEST(TapTestFit, UntunedCaseWithAccelerometerFloorAndBandLimit) {
  testing::TapTestOptions o;
  o.modes = {{650.0, 0.02, 1.5e7}, {1400.0, 0.05, 4.0e7}};
  o.df_hz = 0.5;
  o.fmax_hz = 4000.0;
  o.include_zero_line = false;
  o.relative_noise = 0.02;
  o.absolute_noise_m_per_s2_per_N = 2e-3;
  o.absolute_noise_m_per_N = 4e-10;
  o.band_limit_hz = 3000.0;
  o.drift_ratio = 10.0;
  o.drift_correlation_lines = 8;
  o.seed = 7;
  const testing::TapTest t = testing::MakeTapTest(o);
  const FitOfTap r = FitTap(t);
  ASSERT_FALSE(r.noise.usable_bands.empty());
  EXPECT_GT(r.noise.usable_bands.front().first, 50.0) << r.noise.description;
  // Above the band limit the floor crosses the signal: from 3.9 kHz on
  // (true SNR below 2.3) at most a tenth of the lines count as usable
  // (the SNR estimate scatters by ~25 % line to line, frf_noise_test).
  int above = 0, usable_above = 0;
  for (int i = 0; i < t.freq_hz.size(); ++i) {
    if (t.freq_hz(i) < 3900.0) continue;
    ++above;
    usable_above += r.noise.usable[i];
  }
  EXPECT_LT(usable_above, above / 10) << r.noise.description;
  ExpectModes(r.fit, o.modes, 4e-4, 0.02);
}

}  // namespace
}  // namespace robomach::calibration
