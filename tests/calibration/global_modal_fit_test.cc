// The global modal fit (common poles, residues per FRF, mode shapes, MAC;
// issue #34 §1-2) against analytic references: a simply supported
// Euler–Bernoulli beam in a roving-hammer test (natural frequencies and
// mode shapes in closed form), two modes 3 % apart seen by three FRFs, and
// on real files other software wrote (../shared/external, read where they
// lie, skipped when absent).

#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/global_modal_fit.h"
#include "robomach/common/units.h"
#include "robomach/io/frf_files.h"

namespace robomach::calibration {
namespace {

using cd = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;

// Simply supported beam, length 1 m, steel 30 x 10 mm (bending about the
// thin side): ω_n = (nπ/L)² sqrt(EI/(ρA)), mass-normalised shapes
// φ_n(x) = sqrt(2/(ρAL)) sin(nπx/L) [Blevins, Formulas for natural frequency
// and mode shape, Table 8-1].
struct Beam {
  double L = 1.0, E = 2.1e11, rho = 7850.0, b = 0.03, h = 0.01;
  double EI() const { return E * b * h * h * h / 12.0; }
  double rhoA() const { return rho * b * h; }
  double OmegaN(int n) const { return std::pow(n * kPi / L, 2) * std::sqrt(EI() / rhoA()); }
  double Phi(int n, double x) const { return std::sqrt(2.0 / (rhoA() * L)) * std::sin(n * kPi * x / L); }
};

// H(x_j, x_ref) with modal damping ζ_n, modes 1..12 (those above the band
// act as the upper residual), complex Gaussian noise of `noise_rel` × |H|.
std::vector<dynamics::Frf> RovingBeam(const Beam& beam, const std::vector<double>& points, double x_ref,
                                      double noise_rel, unsigned seed, double fmax_hz, double df_hz) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n_lines = static_cast<int>(std::round(fmax_hz / df_hz));
  Eigen::VectorXd f(n_lines);
  for (int k = 0; k < n_lines; ++k) f(k) = (k + 1) * df_hz;
  std::vector<dynamics::Frf> out;
  for (double x : points) {
    Eigen::VectorXcd H(n_lines);
    for (int k = 0; k < n_lines; ++k) {
      const double w = HzToRadPerSec(f(k));
      cd h = 0.0;
      for (int n = 1; n <= 12; ++n) {
        const double wn = beam.OmegaN(n), zeta = 0.01 + 0.002 * n;
        h += beam.Phi(n, x) * beam.Phi(n, x_ref) / (wn * wn - w * w + cd(0, 2.0 * zeta * wn * w));
      }
      H(k) = h * (1.0 + noise_rel / std::sqrt(2.0) * cd(gauss(rng), gauss(rng)));
    }
    out.push_back(dynamics::Frf::FromSamples(f, H));
  }
  return out;
}

TEST(GlobalModalFit, RovingHammerOnEulerBernoulliBeamGivesAnalyticModesAndShapes) {
  const Beam beam;
  std::vector<double> points;
  for (int j = 1; j <= 11; ++j) points.push_back(j / 12.0);
  const double x_ref = 0.37;
  const double fmax = 1.2 * RadPerSecToHz(beam.OmegaN(5));  // modes 1-5 in the band, mode 6 at 1.44 f5
  const auto frfs = RovingBeam(beam, points, x_ref, 0.01, 3401, fmax, fmax / 2000.0);
  const GlobalModalFitResult fit = FitModesGlobal(frfs);
  ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
  ASSERT_EQ(fit.modes.size(), 5u) << fit.message;
  Eigen::MatrixXcd analytic(points.size(), 5);
  for (int n = 1; n <= 5; ++n) {
    const double fn = RadPerSecToHz(beam.OmegaN(n));
    EXPECT_NEAR(fit.modes[n - 1].freq_hz, fn, 0.002 * fn) << "mode " << n;
    EXPECT_NEAR(fit.modes[n - 1].damping_ratio, 0.01 + 0.002 * n, 0.05 * (0.01 + 0.002 * n)) << "mode " << n;
    for (size_t j = 0; j < points.size(); ++j) analytic(j, n - 1) = beam.Phi(n, points[j]);
  }
  const Eigen::MatrixXd mac = ModalAssuranceCriterion(fit.ModeShapes(), analytic);
  for (int n = 0; n < 5; ++n) {
    EXPECT_GE(mac(n, n), 0.99) << "mode " << n + 1;
    for (int m = 0; m < 5; ++m) {
      if (m != n) EXPECT_LT(mac(n, m), 0.1) << "modes " << n + 1 << ", " << m + 1;
    }
  }
  // The residue of point j is φ_n(x_j) φ_n(x_ref): with the reference point
  // (x_ref) among the points, shapes are mass-normalised; here the scale is
  // checked through A = φ(x_j) φ(x_ref) directly on the point nearest the
  // middle, mode 1.
  const Eigen::MatrixXcd A = fit.ModalConstants();
  const double a_expect = beam.Phi(1, points[5]) * beam.Phi(1, x_ref);
  EXPECT_NEAR(A(5, 0).real(), a_expect, 0.02 * std::abs(a_expect));
  EXPECT_LT(std::abs(A(5, 0).imag()), 0.02 * std::abs(a_expect));
}

TEST(GlobalModalFit, MassNormalisedShapesWithADrivingPoint) {
  const Beam beam;
  const std::vector<double> points{0.15, 0.3, 0.37, 0.55, 0.8};
  const double fmax = 1.3 * RadPerSecToHz(beam.OmegaN(3));
  // 4000 lines: mode 1 (23 Hz, zeta 1.2 %) spans 8 lines of its half-power band.
  const auto frfs = RovingBeam(beam, points, 0.37, 0.005, 3402, fmax, fmax / 4000.0);
  const GlobalModalFitResult fit = FitModesGlobal(frfs);
  ASSERT_EQ(fit.modes.size(), 3u) << fit.message;
  for (int n = 1; n <= 3; ++n) {
    const double fn = RadPerSecToHz(beam.OmegaN(n));
    EXPECT_NEAR(fit.modes[n - 1].freq_hz, fn, 0.002 * fn) << "mode " << n;
    EXPECT_NEAR(fit.modes[n - 1].damping_ratio, 0.01 + 0.002 * n, 0.05 * (0.01 + 0.002 * n)) << "mode " << n;
  }
  const Eigen::MatrixXcd phi = fit.ModeShapes(/*driving_point=*/2);
  for (int n = 1; n <= 3; ++n) {
    // Sign of a mass-normalised shape is arbitrary; compare up to it.
    const double sign = phi(2, n - 1).real() * beam.Phi(n, 0.37) > 0 ? 1.0 : -1.0;
    for (size_t j = 0; j < points.size(); ++j) {
      const double expect = beam.Phi(n, points[j]);
      EXPECT_NEAR(sign * phi(j, n - 1).real(), expect, 0.02 * beam.Phi(n, 0.5 / n) + 1e-12)
          << "mode " << n << " point " << j;
    }
  }
}

// Two modes 3 % apart (a nearly symmetric structure: the same frequency in
// two directions, split by a small asymmetry) and a third mode, seen by
// three FRFs with different mixtures, 2 % noise.
TEST(GlobalModalFit, ResolvesTwoModesThreePercentApart) {
  const double f1 = 400.0, f2 = 412.0, f3 = 900.0;
  const double z1 = 0.012, z2 = 0.015, z3 = 0.02;
  const double phi[3][3] = {{1.0, 0.8, 0.5}, {0.7, -1.0, 0.4}, {0.3, 0.6, -0.9}};  // [frf][mode]
  const double m = 2.0;                                                            // modal mass [kg]
  std::mt19937 rng(3403);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n_lines = 1500;
  Eigen::VectorXd f(n_lines);
  for (int k = 0; k < n_lines; ++k) f(k) = 100.0 + k * (1200.0 - 100.0) / (n_lines - 1);
  std::vector<dynamics::Frf> frfs;
  for (int o = 0; o < 3; ++o) {
    Eigen::VectorXcd H(n_lines);
    for (int k = 0; k < n_lines; ++k) {
      const double w = HzToRadPerSec(f(k));
      cd h = 0.0;
      const double fr[3] = {f1, f2, f3}, zr[3] = {z1, z2, z3};
      for (int r = 0; r < 3; ++r) {
        const double wn = HzToRadPerSec(fr[r]);
        h += phi[o][r] / m / (wn * wn - w * w + cd(0, 2 * zr[r] * wn * w));
      }
      H(k) = h * (1.0 + 0.02 / std::sqrt(2.0) * cd(gauss(rng), gauss(rng)));
    }
    frfs.push_back(dynamics::Frf::FromSamples(f, H));
  }
  const GlobalModalFitResult fit = FitModesGlobal(frfs);
  ASSERT_EQ(fit.modes.size(), 3u) << fit.message;
  EXPECT_NEAR(fit.modes[0].freq_hz, f1, 0.002 * f1);
  EXPECT_NEAR(fit.modes[1].freq_hz, f2, 0.002 * f2);
  EXPECT_NEAR(fit.modes[2].freq_hz, f3, 0.002 * f3);
  EXPECT_NEAR(fit.modes[0].damping_ratio, z1, 0.1 * z1);
  EXPECT_NEAR(fit.modes[1].damping_ratio, z2, 0.1 * z2);
  Eigen::MatrixXcd truth(3, 3);
  for (int o = 0; o < 3; ++o)
    for (int r = 0; r < 3; ++r) truth(o, r) = phi[o][r];
  const Eigen::MatrixXd mac = ModalAssuranceCriterion(fit.ModalConstants(), truth);
  for (int r = 0; r < 3; ++r) EXPECT_GE(mac(r, r), 0.99) << "mode " << r + 1;
}

// Two modes with a known noise model (0.5 % of |H|), plus an error the
// noise model does not know: complex white noise of rms `tau` in the
// accelerance (what a modal model cannot fit and the noise model did not
// foresee). The model error the fit estimates is that τ.
std::vector<dynamics::Frf> TwoModesWithAnUnknownError(double tau, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n = 490;
  Eigen::VectorXd f(n), sigma(n);
  Eigen::VectorXcd H(n);
  for (int k = 0; k < n; ++k) {
    f(k) = 10.0 + k;
    const double w = HzToRadPerSec(f(k));
    cd h = 0.0;
    for (auto [fn, zeta, m] : {std::tuple{120.0, 0.02, 2.0}, std::tuple{310.0, 0.015, 5.0}}) {
      const double wn = HzToRadPerSec(fn);
      h += 1.0 / (m * (wn * wn - w * w + cd(0, 2.0 * zeta * wn * w)));
    }
    sigma(k) = 0.005 * std::abs(h);
    H(k) = h + sigma(k) / std::sqrt(2.0) * cd(gauss(rng), gauss(rng)) +
           tau / (w * w) / std::sqrt(2.0) * cd(gauss(rng), gauss(rng));
  }
  return {dynamics::Frf::FromSamples(f, H).WithNoise(sigma)};
}

TEST(GlobalModalFit, ModelErrorIsTheErrorTheNoiseModelDidNotKnow) {
  // The accelerance is 0.002-0.7 (m/s²)/N away from the peaks (12.5 and 6.7
  // at them): τ = 0.01 is above the noise (0.5 % of |H|) on most lines, so
  // they all measure it (on a few dozen lines, τ = 0.001 came out 0.88-1.19
  // × itself over three seeds).
  for (unsigned seed : {3u, 4u, 5u}) {
    const double tau = 1e-2;
    const auto frfs = TwoModesWithAnUnknownError(tau, seed);
    GlobalModalFitOptions o;
    o.model_error_power = 2;
    const GlobalModalFitResult fit = FitModesGlobal(frfs, o);
    ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
    const GlobalModalFitResult plain = FitModesGlobal(frfs, GlobalModalFitOptions{});
    ASSERT_GT(plain.misfit_in_noise[0], 2.0) << "the unknown error should show as a misfit: " << plain.message;
    ASSERT_EQ(fit.model_error.size(), 1u);
    // τ² by the random-effects estimate over about 400 lines (relative
    // standard deviation of τ about 1/(2 sqrt(400)) = 2.5 %): within 10 %.
    EXPECT_NEAR(fit.model_error[0], tau, 0.10 * tau) << fit.message;
    EXPECT_EQ(fit.model_error_power, 2);
    EXPECT_NEAR(fit.misfit_in_noise_weights_alone[0], plain.misfit_in_noise[0], 1e-9 * plain.misfit_in_noise[0]);
    // The refit gives up misfit in units of σ alone for the model error.
    EXPECT_GE(fit.misfit_in_noise[0], 0.99 * plain.misfit_in_noise[0]);
    EXPECT_NE(fit.message.find("model error white in the accelerance"), std::string::npos) << fit.message;
    // Both modes stay where they are.
    ASSERT_EQ(fit.modes.size(), 2u) << fit.message;
    EXPECT_NEAR(fit.modes[0].freq_hz, 120.0, 0.5);
    EXPECT_NEAR(fit.modes[1].freq_hz, 310.0, 1.0);
  }
  // Without the unknown error the fit is within the noise: no model error,
  // the same fit as without the option.
  const auto clean = TwoModesWithAnUnknownError(0.0, 7u);
  GlobalModalFitOptions o;
  o.model_error_power = 2;
  const GlobalModalFitResult fit = FitModesGlobal(clean, o);
  const GlobalModalFitResult plain = FitModesGlobal(clean, GlobalModalFitOptions{});
  ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
  EXPECT_LT(plain.misfit_in_noise[0], 2.0) << plain.message;
  EXPECT_EQ(fit.model_error[0], 0.0);
  EXPECT_EQ(fit.message, plain.message);
  ASSERT_EQ(fit.modes.size(), plain.modes.size());
  for (size_t r = 0; r < fit.modes.size(); ++r) EXPECT_EQ(fit.modes[r].freq_hz, plain.modes[r].freq_hz);
}

// Two modes (60, 180 Hz) measured from 5 Hz, a tenth of the lowest, with
// 0.5 % noise; with `mass_kg` > 0 the structure is free and its receptance
// has the rigid body's mass line −1/(M ω²) below the modes.
dynamics::Frf FreeOrGrounded(double mass_kg, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n = 396;
  Eigen::VectorXd f(n), sigma(n);
  Eigen::VectorXcd H(n);
  for (int k = 0; k < n; ++k) {
    f(k) = 5.0 + k;
    const double w = HzToRadPerSec(f(k));
    cd h = mass_kg > 0.0 ? cd(-1.0 / (mass_kg * w * w)) : cd(0.0);
    for (auto [fn, zeta, m] : {std::tuple{60.0, 0.02, 3.0}, std::tuple{180.0, 0.02, 4.0}}) {
      const double wn = HzToRadPerSec(fn);
      h += 1.0 / (m * (wn * wn - w * w + cd(0, 2.0 * zeta * wn * w)));
    }
    sigma(k) = 0.005 * std::abs(h);
    H(k) = h + sigma(k) / std::sqrt(2.0) * cd(gauss(rng), gauss(rng));
  }
  return dynamics::Frf::FromSamples(f, H).WithNoise(sigma);
}

TEST(GlobalModalFit, LowerResidualOfAFreeStructureKeptByTheBic) {
  for (unsigned seed : {11u, 12u}) {
    const GlobalModalFitResult free = FitModesGlobal({FreeOrGrounded(20.0, seed)});
    ASSERT_EQ(free.status, SolverStatus::kConverged) << free.message;
    EXPECT_NE(free.message.find("lower residual"), std::string::npos) << free.message;
    // The mass line is the lower residual: L/s² = −L/ω², L = 1/M. It
    // dominates a few dozen lines below 15 Hz at 0.5 % noise each: L to about
    // 0.1 % (0.05 % and 0.01 % for the two seeds); within 0.5 %.
    EXPECT_NEAR(free.per_frf[0].lower_residual.real(), 1.0 / 20.0, 0.005 / 20.0) << free.message;
    // Within the noise: the rms over 396 lines scatters by about 2.5 %
    // (0.98, 1.01); under 1.15.
    EXPECT_LT(free.misfit_in_noise[0], 1.15) << free.message;
    ASSERT_EQ(free.modes.size(), 2u) << free.message;
    EXPECT_NEAR(free.modes[0].freq_hz, 60.0, 0.1);
    // Grounded: no mass line, the BIC does not take the two parameters.
    const GlobalModalFitResult grounded = FitModesGlobal({FreeOrGrounded(0.0, seed)});
    ASSERT_EQ(grounded.status, SolverStatus::kConverged) << grounded.message;
    EXPECT_EQ(grounded.message.find("lower residual"), std::string::npos) << grounded.message;
    EXPECT_EQ(grounded.per_frf[0].lower_residual, cd(0.0)) << grounded.message;
  }
}

TEST(GlobalModalFit, MacOfKnownVectors) {
  Eigen::MatrixXcd a(3, 2), b(3, 1);
  a << 1, 0, 2, 1, 3, 0;
  b << cd(0, -2), cd(0, -4), cd(0, -6);  // −2i × a's first column
  const Eigen::MatrixXd mac = ModalAssuranceCriterion(a, b);
  EXPECT_NEAR(mac(0, 0), 1.0, 1e-15);
  // a₂ = (0,1,0): |a₂ᴴ b|² / (|a₂|²|b|²) = 16 / (1 · 56).
  EXPECT_NEAR(mac(1, 0), 16.0 / 56.0, 1e-15);
  EXPECT_THROW(ModalAssuranceCriterion(a, Eigen::MatrixXcd(2, 1)), std::invalid_argument);
}

TEST(GlobalModalFit, RefusesFrfsOnOtherLines) {
  Eigen::VectorXd f1 = Eigen::VectorXd::LinSpaced(100, 10, 100), f2 = Eigen::VectorXd::LinSpaced(100, 10, 110);
  const Eigen::VectorXcd h = Eigen::VectorXcd::Constant(100, cd(1e-6, 0));
  EXPECT_THROW(FitModesGlobal({dynamics::Frf::FromSamples(f1, h), dynamics::Frf::FromSamples(f2, h)}),
               std::invalid_argument);
}

// ------------------------------------------------ real files (../shared) --

std::string Shared(const std::string& rel) {
  return std::string(ROBOMACH_SOURCE_DIR) + "/../shared/external/frf_uff58/" + rel;
}

// pyuff's measured beam accelerances (numpy text, one complex per line,
// 0..1000 Hz in 1 Hz steps, roving hammer, response node 1).
std::vector<dynamics::Frf> PyuffBeam() {
  std::vector<dynamics::Frf> out;
  for (int p = 1; p <= 3; ++p) {
    std::ifstream in(Shared("pyuff/meas_point_" + std::to_string(p) + ".txt"));
    std::vector<cd> v;
    std::string line;
    while (std::getline(in, line)) {
      // "(re+imj)"
      for (char& c : line)
        if (c == '(' || c == ')') c = ' ';
      const size_t j = line.find('j');
      if (j == std::string::npos) continue;
      // split at the sign that starts the imaginary part (not an exponent's)
      size_t split = std::string::npos;
      for (size_t i = j; i-- > 1;) {
        if ((line[i] == '+' || line[i] == '-') && line[i - 1] != 'e' && line[i - 1] != 'E' && line[i - 1] != ' ') {
          split = i;
          break;
        }
      }
      v.emplace_back(std::stod(line.substr(0, split)), std::stod(line.substr(split, j - split)));
    }
    const int n = static_cast<int>(v.size()) - 1;  // 0 Hz dropped: no receptance
    Eigen::VectorXd f(n);
    Eigen::VectorXcd H(n);
    for (int k = 0; k < n; ++k) {
      f(k) = k + 1.0;
      const double w = HzToRadPerSec(f(k));
      H(k) = v[k + 1] / (-w * w);  // accelerance to receptance
    }
    out.push_back(dynamics::Frf::FromSamples(f, H));
  }
  return out;
}

// The noise model the tools attach (frf_noise.h): measured data have a
// floor, and 1/|H| weights would make the anti-resonances' noise dominate.
std::vector<dynamics::Frf> WithNoiseModels(std::vector<dynamics::Frf> frfs) {
  for (dynamics::Frf& f : frfs) f = f.WithNoise(EstimateFrfNoise(f).sigma_m_per_N);
  return frfs;
}

void DumpFit(const GlobalModalFitResult& fit, const std::vector<dynamics::Frf>& frfs, int power) {
  std::printf("%s\n", fit.message.c_str());
  for (const GlobalMode& m : fit.modes) std::printf("  %.2f Hz zeta %.4f support %d\n", m.freq_hz, m.damping_ratio, m.stable_orders);
  for (size_t i = 0; i < frfs.size(); ++i)
    std::printf("  FRF %zu misfit %.4f noise %.2f\n", i + 1, RelativeMisfit(fit.per_frf[i], frfs[i], power), fit.misfit_in_noise[i]);
}

TEST(GlobalModalFitRealFiles, PyuffBeamEveryPeakFoundAndMisfitAtMostThePeers) {
  if (!std::filesystem::exists(Shared("pyuff/meas_point_1.txt"))) {
    GTEST_SKIP() << "../shared/external/frf_uff58/pyuff is absent (a clone without ../shared)";
  }
  const auto frfs = WithNoiseModels(PyuffBeam());
  // The peer's criterion: least squares of the accelerance as measured,
  // every line alike (frf-modes --weights quantity).
  GlobalModalFitOptions o;
  o.uniform_weights_power = 2;
  const GlobalModalFitResult fit = FitModesGlobal(frfs, o);
  ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
  if (std::getenv("ROBOMACH_DUMP_FIT")) DumpFit(fit, frfs, 2);
  // sdypy-EMA 0.31 (LSCF/LSFD, the three FRFs jointly) on the same files:
  // misfit 0.026 / 0.045 / 0.029 as accelerance (issue #34; rerun by
  // bench/peer_modal_sdypy.sh: 0.027 / 0.050 / 0.027).
  const double peer[3] = {0.026, 0.045, 0.029};
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(RelativeMisfit(fit.per_frf[i], frfs[i], 2), peer[i]) << "FRF " << i + 1 << ": " << fit.message;
  }
  // The peaks the files show (SOURCES.md, read on the 1 Hz grid): 52, 142,
  // 279, 460, 687, 959 Hz; a mode within one line of each.
  for (double f : {52.0, 142.0, 279.0, 460.0, 687.0, 959.0}) {
    double nearest = 1e300;
    for (const GlobalMode& m : fit.modes) nearest = std::min(nearest, std::abs(m.freq_hz - f));
    EXPECT_LE(nearest, 1.0) << "no mode within a line of " << f << " Hz: " << fit.message;
  }
  // One set of poles: every FRF's table has the same modes.
  for (const ModalFitResult& r : fit.per_frf) ASSERT_EQ(r.modes.size(), fit.modes.size());
}

TEST(GlobalModalFitRealFiles, PyuffBeamModelErrorFitsTheOneLinePeaks) {
  if (!std::filesystem::exists(Shared("pyuff/meas_point_1.txt"))) {
    GTEST_SKIP() << "../shared/external/frf_uff58/pyuff is absent (a clone without ../shared)";
  }
  const auto frfs = WithNoiseModels(PyuffBeam());
  // frf-modes' default: the noise model's weights, and a model error white
  // in the accelerance where the fit leaves more than twice the noise.
  GlobalModalFitOptions o;
  o.model_error_power = 2;
  const GlobalModalFitResult fit = FitModesGlobal(frfs, o);
  ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
  if (std::getenv("ROBOMACH_DUMP_FIT")) DumpFit(fit, frfs, 2);
  GlobalModalFitOptions plain;
  const GlobalModalFitResult noise_only = FitModesGlobal(frfs, plain);
  ASSERT_EQ(noise_only.status, SolverStatus::kConverged) << noise_only.message;
  if (std::getenv("ROBOMACH_DUMP_FIT")) DumpFit(noise_only, frfs, 2);
  // The noise model leaves 2.4 times the noise on FRFs 2 and 3 (1.8 on
  // FRF 1), mostly at the peaks, which are one line wide (ζ 0.01-0.04 % on
  // 1 Hz lines); weighted with the model error, the peaks are fitted: the
  // relative misfit falls on every FRF (0.045 / 0.062 / 0.050 to 0.034 /
  // 0.048 / 0.034 on 2026-12-02; sdypy-EMA's 0.0265 / 0.0504 / 0.0273 in
  // bench/peer_modal_sdypy.py, not asserted here). The FRF within twice
  // its noise keeps no model error.
  ASSERT_EQ(fit.model_error.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    // The first pass is the fit with the noise's weights alone, and it is
    // what the summary's misfit_noise_sigmas_noise_weights reports.
    EXPECT_NEAR(fit.misfit_in_noise_weights_alone[i], noise_only.misfit_in_noise[i],
                1e-9 * noise_only.misfit_in_noise[i]) << "FRF " << i + 1;
    EXPECT_LT(RelativeMisfit(fit.per_frf[i], frfs[i], 2), RelativeMisfit(noise_only.per_frf[i], frfs[i], 2))
        << "FRF " << i + 1 << ": " << fit.message;
  }
  // Every peak the files show still has its mode.
  for (double f : {52.0, 142.0, 279.0, 460.0, 687.0, 959.0}) {
    double nearest = 1e300;
    for (const GlobalMode& m : fit.modes) nearest = std::min(nearest, std::abs(m.freq_hz - f));
    EXPECT_LE(nearest, 1.0) << "no mode within a line of " << f << " Hz: " << fit.message;
  }
  EXPECT_NE(fit.message.find("model error"), std::string::npos) << fit.message;
}

TEST(GlobalModalFitRealFiles, Dataset58ModesAtTheFilesPeaks) {
  const std::string path = Shared("ufffiles_jl/dataset58_FRF.unv");
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << "../shared/external/frf_uff58/ufffiles_jl is absent (a clone without ../shared)";
  }
  const io::FrfReadResult read = io::ReadFrfFile(path);
  ASSERT_EQ(read.frfs.size(), 1);
  const dynamics::Frf frf = WithNoiseModels({read.frfs.begin()->second}).front();
  const GlobalModalFitResult fit = FitModesGlobal({frf});
  ASSERT_EQ(fit.status, SolverStatus::kConverged) << fit.message;
  if (std::getenv("ROBOMACH_DUMP_FIT")) DumpFit(fit, {frf}, 1);
  // The peaks of the file (SOURCES.md, 0.5 Hz grid): 81.5, 175, 376.5, 464,
  // 544 Hz, each within 0.5 % (issue #34's acceptance). About 30 modes in
  // 5-800 Hz: a dense FRF, fitted band by band; in one band at order 100 the
  // clusters of the lowest modes were too short to count and the 81.5 Hz
  // mode came out at 80.1 Hz, 1.7 % off.
  EXPECT_GT(fit.bands, 1) << fit.message;
  for (double f : {81.5, 175.0, 376.5, 464.0, 544.0}) {
    double nearest = 1e300;
    for (const GlobalMode& m : fit.modes) nearest = std::min(nearest, std::abs(m.freq_hz - f));
    EXPECT_LT(nearest, 0.005 * f) << "mode near " << f << " Hz: " << fit.message;
  }
}

}  // namespace
}  // namespace robomach::calibration
