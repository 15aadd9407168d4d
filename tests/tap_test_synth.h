#pragma once

// Issue #18's tool-tip tap test as it really comes, shared by the calibration
// and stability tests and the stability-lobes fixture: a receptance from a
// few modes of a tool tip, 1 Hz lines from 0 to 5000 Hz, complex noise
// proportional to |H|, and below 100 Hz the drift of the integrated
// accelerometer signal: a slowly wandering complex error whose rms envelope
// rises as 1/f² to a multiple of the resonance peak at 20 Hz. A real drift
// is smooth over a few lines (the leakage of a slow trend in the time
// record), not white, so the noise model's second differences see only a
// small part of it; that is what made the modal fit fail (issue #18).
//
// Made here from its definition, not by the code under test: the modes are
// summed in closed form, H(ω) = Σ 1/(k_r − m_r ω² + i c_r ω) with
// m_r = k_r/ω_r², c_r = 2 ζ_r √(k_r m_r) [Ewins 2000, eq. 2.3].

#include <algorithm>
#include <cmath>
#include <complex>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace robomach::testing {

struct TapMode {
  double freq_hz;
  double damping_ratio;
  double stiffness_N_per_m;  // modal stiffness k_r at the tool tip (1/k_r = static compliance of the mode)
  double mass_kg() const {
    const double w = 2.0 * 3.14159265358979323846 * freq_hz;
    return stiffness_N_per_m / (w * w);
  }
};

struct TapTestOptions {
  /// Issue #18: three modes near 1.07, 1.96 and 2.62 kHz, ζ ≈ 0.03. The
  /// stiffnesses 2e7, 3e7, 5e7 N/m (modal masses 0.44, 0.20, 0.18 kg) are
  /// of the order of a 20 mm end mill in a holder on a machining spindle
  /// (peak receptance 0.85 µm/N at the first mode, dynamic stiffness
  /// 2ζk ≈ 1.2 N/µm).
  std::vector<TapMode> modes{{1074.0, 0.03, 2.0e7}, {1961.0, 0.03, 3.0e7}, {2617.0, 0.03, 5.0e7}};
  double df_hz{1.0};
  double fmax_hz{5000.0};
  bool include_zero_line{true};
  /// Relative complex noise: σ = relative_noise |H| (each part σ/√2).
  double relative_noise{0.01};
  /// Additive complex noise floor [m/N], flat in receptance (0: none).
  double absolute_noise_m_per_N{0.0};
  /// Additive floor flat in accelerance [(m/s²)/N] (the accelerometer's
  /// own noise), i.e. floor/ω² in receptance; above the hammer's band limit
  /// (0: none) every additive floor rises as (f/limit)⁸ (the force spectrum
  /// of the hammer tip falls by 24 dB per octave there, and the floor of
  /// the ratio response/force rises with its square).
  double absolute_noise_m_per_s2_per_N{0.0};
  double band_limit_hz{0.0};
  /// Drift: rms envelope D(f) = drift_ratio · peak · (1/f² − 1/f_d²) /
  /// (1/20² − 1/f_d²) below f_d = drift_below_hz (continuous, zero at f_d),
  /// D(20 Hz) = drift_ratio × the largest |H| of the modes; f ≥ 1 Hz in it
  /// (the 0 Hz line gets the 1 Hz envelope).
  double drift_ratio{5.0};
  double drift_below_hz{100.0};
  /// The drift is white complex noise averaged over this many lines
  /// (a moving average renormalised to unit rms): smooth over that width.
  int drift_correlation_lines{15};
  /// Below this frequency the envelope stays at its value there (0: rises to 1 Hz).
  double drift_flat_below_hz{0.0};
  unsigned seed{18};
};

struct TapTest {
  Eigen::VectorXd freq_hz;
  Eigen::VectorXcd measured;   // [m/N]
  Eigen::VectorXcd truth;      // the modes alone [m/N]
  double peak_m_per_N{0.0};    // largest |truth|
};

inline std::complex<double> TapReceptance(const std::vector<TapMode>& modes, double f_hz) {
  const double w = 2.0 * 3.14159265358979323846 * f_hz;
  std::complex<double> h = 0.0;
  for (const TapMode& m : modes) {
    const double mass = m.mass_kg();
    const double c = 2.0 * m.damping_ratio * std::sqrt(m.stiffness_N_per_m * mass);
    h += 1.0 / std::complex<double>(m.stiffness_N_per_m - mass * w * w, c * w);
  }
  return h;
}

inline TapTest MakeTapTest(const TapTestOptions& o = {}) {
  const int first = o.include_zero_line ? 0 : 1;
  const int last = static_cast<int>(std::round(o.fmax_hz / o.df_hz));
  const int n = last - first + 1;
  TapTest t;
  t.freq_hz.resize(n);
  t.truth.resize(n);
  t.measured.resize(n);
  for (int i = 0; i < n; ++i) {
    t.freq_hz(i) = (first + i) * o.df_hz;
    t.truth(i) = TapReceptance(o.modes, t.freq_hz(i));
    t.peak_m_per_N = std::max(t.peak_m_per_N, std::abs(t.truth(i)));
  }
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const int K = std::max(1, o.drift_correlation_lines);
  std::vector<std::complex<double>> white(n + K);
  for (auto& w : white) w = {g(rng), g(rng)};
  const double fd = o.drift_below_hz;
  for (int i = 0; i < n; ++i) {
    std::complex<double> drift = 0.0;
    for (int j = 0; j < K; ++j) drift += white[i + j];
    drift /= std::sqrt(2.0 * K);  // unit rms complex
    const double f = std::max({t.freq_hz(i), 1.0, o.drift_flat_below_hz});
    const double env = f < fd ? o.drift_ratio * t.peak_m_per_N * (1.0 / (f * f) - 1.0 / (fd * fd)) /
                                    (1.0 / 400.0 - 1.0 / (fd * fd))
                              : 0.0;
    const double s = o.relative_noise * std::abs(t.truth(i)) / std::sqrt(2.0);
    const double w = 2.0 * 3.14159265358979323846 * std::max(t.freq_hz(i), o.df_hz);
    const double lift = o.band_limit_hz > 0.0 && t.freq_hz(i) > o.band_limit_hz
                            ? std::pow(t.freq_hz(i) / o.band_limit_hz, 8)
                            : 1.0;
    const double a = lift * (o.absolute_noise_m_per_N + o.absolute_noise_m_per_s2_per_N / (w * w)) / std::sqrt(2.0);
    t.measured(i) = t.truth(i) + std::complex<double>(s * g(rng), s * g(rng)) +
                    std::complex<double>(a * g(rng), a * g(rng)) + env * drift;
  }
  return t;
}

/// Writes `t` as formats.md §3 CSV (receptance), one FRF per direction pair
/// in `pairs` ("xx", "yy", "zz"), all with the same data.
inline void WriteTapTestCsv(const std::string& path, const TapTest& t, const std::string& pose_id,
                            const std::vector<std::string>& pairs) {
  std::ofstream os(path);
  os.precision(10);
  os << "# quantity: receptance\npose_id,response,excitation,freq_hz,re,im\n";
  for (const std::string& p : pairs) {
    for (int i = 0; i < t.freq_hz.size(); ++i) {
      os << pose_id << ',' << p[0] << ',' << p[1] << ',' << t.freq_hz(i) << ',' << t.measured(i).real() << ','
         << t.measured(i).imag() << '\n';
    }
  }
}

}  // namespace robomach::testing
