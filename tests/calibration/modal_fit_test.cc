// Modal fitting against synthetic FRFs with known modes: the receptance
// H(ω) = Σ A_k / (ω_k² − ω² + 2iζ_kω_kω) of proportionally damped modes
// [Ewins 2000, eq. 2.3-ish form], evaluated in closed form.
#include <gtest/gtest.h>

#include <random>

#include "robomach/calibration/modal_fit.h"
#include "robomach/common/units.h"

namespace robomach::calibration {
namespace {

struct TrueMode {
  double f_hz, zeta, A;  // A [m/N (rad/s)²]
};

dynamics::Frf Synthetic(const std::vector<TrueMode>& modes, double df_hz, double fmax_hz,
                        double noise = 0.0, unsigned seed = 42) {
  const int n = static_cast<int>(std::round(fmax_hz / df_hz));
  Eigen::VectorXd f(n);
  Eigen::VectorXcd h(n);
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    f(i) = (i + 1) * df_hz;
    const double w = HzToRadPerSec(f(i));
    std::complex<double> v = 0.0;
    for (const TrueMode& m : modes) {
      const double wn = HzToRadPerSec(m.f_hz);
      v += m.A / std::complex<double>(wn * wn - w * w, 2 * m.zeta * wn * w);
    }
    // Relative complex Gaussian noise of rms `noise` (each part noise/√2).
    v *= std::complex<double>(1.0 + noise / std::sqrt(2.0) * g(rng), noise / std::sqrt(2.0) * g(rng));
    h(i) = v;
  }
  return dynamics::Frf::FromSamples(f, h);
}

// Half-power points of an SDOF receptance, exactly: |H|² = |H_peak|²/2 at
// r² = 1 − 2ζ² ± 2ζ√(1 − ζ²) (r = ω/ω_n), so the half-power estimate
// (f2 − f1)/(2 f_peak) differs from ζ by O(ζ²) relative: 1.5 ζ² ≈ 6e-4 at
// ζ = 0.02. Linear interpolation of |H|² over a 0.01 Hz grid inside a 2 Hz
// half-power band adds (0.01/2)² ≈ 3e-5. The peak is at f_n √(1 − 2ζ²);
// the parabolic vertex through three lines is off by < 1e-3 of a line.
TEST(PeakPicking, HalfPowerDampingOfSingleMode) {
  const double zeta = 0.02, fn = 50.0;
  const dynamics::Frf frf = Synthetic({{fn, zeta, 1.0}}, 0.01, 100.0);
  const auto peaks = PickPeaks(frf);
  ASSERT_EQ(peaks.size(), 1u);
  EXPECT_TRUE(peaks[0].two_sided);
  EXPECT_NEAR(peaks[0].damping_ratio, zeta, 1e-3 * zeta);
  EXPECT_NEAR(peaks[0].peak_freq_hz, fn * std::sqrt(1 - 2 * zeta * zeta), 1e-3 * 0.01);
}

// Noise-free data from three modes, two of them 3 % apart with overlapping
// half-power bands (2ζ = 4-5 % > 3 %). The final nonlinear refinement fits
// the exact model class (poles and residues), so on noise-free data it
// converges to the truth up to its stopping rule (it stops when a step
// lowers the cost by less than 1e-10 relative; from a start within the
// linear regime Levenberg–Marquardt converges quadratically, so the relative
// residual is then far below 1e-6, and pole errors are of that order times ζ). Tolerances: 1e-6 relative fit residual, 1e-5 frequency,
// 1e-4 damping and modal constant (the damping is the real part of the pole,
// ζ ≈ 0.02 times its modulus, so its relative error is up to 1/ζ = 50 times
// the frequency's; the modal constant shares that error).
TEST(ModalFit, RecoversCloseModesWithoutNoise) {
  const std::vector<TrueMode> truth = {{40.0, 0.02, 2.0e-3}, {41.2, 0.025, 1.5e-3}, {120.0, 0.03, 4.0e-3}};
  const dynamics::Frf frf = Synthetic(truth, 0.25, 250.0);
  const ModalFitResult r = FitModes(frf);
  ASSERT_EQ(r.status, SolverStatus::kConverged) << r.message;
  ASSERT_EQ(r.modes.size(), 3u) << r.message;
  EXPECT_LT(r.relative_rms_error, 1e-6);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(r.modes[k].freq_hz, truth[k].f_hz, 1e-5 * truth[k].f_hz) << k;
    EXPECT_NEAR(r.modes[k].damping_ratio, truth[k].zeta, 1e-4 * truth[k].zeta) << k;
    EXPECT_NEAR(r.modes[k].modal_constant.real(), truth[k].A, 1e-4 * truth[k].A) << k;
    EXPECT_NEAR(r.modes[k].modal_constant.imag(), 0.0, 1e-4 * truth[k].A) << k;
  }
}

// The same with 2 % relative noise. Error budget of a mode from the lines in
// its half-power band, N_hp = 2ζ f / Δf ≈ 6.4 at 40 Hz (0.25 Hz grid): a
// pole's position is set to about σ_rel · ζ ω_n / √N_hp, i.e.
// δf/f ≈ 0.02 · 0.02 / 2.5 ≈ 1.6e-4, δζ/ζ ≈ σ / √N_hp ≈ 0.8 %, and the modal
// constant like δζ/ζ. The two close modes share their lines, which roughly
// doubles these (the Fisher information splits). Tolerances are 5 standard
// deviations of the doubled figures: 2e-3 in frequency, 8 % in damping and
// modal constant. Three seeds.
TEST(ModalFit, RecoversCloseModesWithTwoPercentNoise) {
  const std::vector<TrueMode> truth = {{40.0, 0.02, 2.0e-3}, {41.2, 0.025, 1.5e-3}, {120.0, 0.03, 4.0e-3}};
  for (unsigned seed : {1u, 2u, 3u}) {
    const dynamics::Frf frf = Synthetic(truth, 0.25, 250.0, 0.02, seed);
    const ModalFitResult r = FitModes(frf);
    ASSERT_EQ(r.status, SolverStatus::kConverged) << r.message;
    ASSERT_EQ(r.modes.size(), 3u) << "seed " << seed << ": " << r.message;
    // The fit residual is the noise: 2 % rms.
    EXPECT_LT(r.relative_rms_error, 0.03);
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(r.modes[k].freq_hz, truth[k].f_hz, 2e-3 * truth[k].f_hz) << seed << " " << k;
      EXPECT_NEAR(r.modes[k].damping_ratio, truth[k].zeta, 0.08 * truth[k].zeta) << seed << " " << k;
      EXPECT_NEAR(std::abs(r.modes[k].modal_constant), truth[k].A, 0.08 * truth[k].A) << seed << " " << k;
    }
  }
}

// The peak of the fitted curve against the peak of the true curve on a
// 1e-4 Hz grid (noise-free): the fit reproduces the data to < 1e-6, so its
// peak agrees to that order; 1e-5 relative in |H|. The peak frequency of the
// grid search is within one grid step (1e-4 Hz) plus the golden-section
// tolerance; the flat top of the peak makes it ill-determined to ~1e-3 Hz
// by a 1e-6 change of |H| (|H| ≈ |H_p| (1 − ((f−f_p)/(ζ f_p))²/2...)), so 2e-3 Hz.
TEST(ModalFit, PeakOfFittedCurveMatchesTruePeak) {
  const std::vector<TrueMode> truth = {{40.0, 0.02, 2.0e-3}, {120.0, 0.03, 4.0e-3}};
  const dynamics::Frf frf = Synthetic(truth, 0.25, 250.0);
  const ModalFitResult r = FitModes(frf);
  ASSERT_EQ(r.status, SolverStatus::kConverged);
  const auto [fp, ap] = r.PeakIn(35.0, 45.0);
  const dynamics::Frf fine = Synthetic(truth, 1e-4, 45.0);
  double best = 0, f_best = 0;
  for (int i = 0; i < fine.size(); ++i) {
    if (std::abs(fine.receptance()(i)) > best) {
      best = std::abs(fine.receptance()(i));
      f_best = fine.freq_hz()(i);
    }
  }
  EXPECT_NEAR(ap, best, 1e-5 * best);
  EXPECT_NEAR(fp, f_best, 2e-3);
}

TEST(ModalFit, ReportsStatusInsteadOfThrowing) {
  const dynamics::Frf tiny = Synthetic({{40.0, 0.02, 1.0}}, 10.0, 50.0);
  const ModalFitResult r = FitModes(tiny);
  EXPECT_EQ(r.status, SolverStatus::kFailed);
  EXPECT_NE(r.message.find("too few lines"), std::string::npos);
}

}  // namespace
}  // namespace robomach::calibration
