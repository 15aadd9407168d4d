#pragma once

// A virtual hammer test: "measured" tool-tip FRFs of a robot model with
// known truth, on the frequency grid of a real impact test, with seeded
// noise. This is how tests and users make data to check calibration and
// modal fitting against.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/frames.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::calibration {

/// The grid and noise of a virtual hammer test.
///
/// Grid: an FFT of a record of `block_samples` at `sample_rate_hz` has lines
/// at k Δf, Δf = sample_rate_hz / block_samples. The default 20480 samples at
/// the seed's 5120 Hz is a 4 s record, Δf = 0.25 Hz: the slowest decay of the
/// default KR210 (10.5 Hz, ζ ≈ 0.04, time constant 1/(ζω) ≈ 0.38 s) has died
/// out to e^{-10} within the record, so leakage is negligible without a window,
/// and the lightly damped modes get 3 or more lines in their half-power band
/// (2ζf/Δf ≥ 3.4 at 10.5 Hz). The band stops at 500 Hz, about twice the
/// highest mode of the default robot (≈ 260 Hz) and well inside the
/// anti-aliasing limit of 5120 Hz sampling (0.4 fs = 2048 Hz): 2000 lines.
struct VirtualHammerOptions {
  double sample_rate_hz{5120.0};
  int block_samples{20480};
  double fmin_hz{0.25};   // lowest line kept [Hz] (> 0: the 0 Hz line is not measured)
  double fmax_hz{500.0};  // highest line kept [Hz]
  /// Response/excitation pairs, in the robot base frame.
  std::vector<std::pair<Axis, Axis>> directions{{Axis::kX, Axis::kX}, {Axis::kY, Axis::kY}};
  /// Noise added to each line:
  ///   H (1 + relative_noise · n₁) + floor(f) · n₂,
  /// n₁, n₂ complex standard normal (each part of variance 1/2), so these are
  /// rms values of the final (averaged) estimate. The additive floor is that
  /// of the response sensor, flat in the quantity it measures, divided by the
  /// normalised force spectrum of the hammer:
  ///   floor(f)² = [a_r² + (a_v/ω)² + (a_a/ω²)²] / |F(f)/F(0)|²,
  /// a_r, a_v, a_a the floors flat in receptance, mobility and accelerance.
  double relative_noise{0.0};
  double absolute_noise_m_per_N{0.0};             // a_r [m/N]
  double absolute_noise_m_per_s_per_N{0.0};       // a_v [(m/s)/N]
  double absolute_noise_m_per_s2_per_N{0.0};      // a_a [(m/s²)/N]
  /// The hammer tip's force spectrum |F(f)/F(0)| = 1 / √(1 + (f/f_c)⁴):
  /// flat below the cutoff f_c, −3 dB at it, falling as f⁻² above, the slope
  /// of the envelope of a half-sine impact's spectrum (without its zeros,
  /// which a real tip's pulse shape smears out). 0: a flat force spectrum.
  double hammer_cutoff_hz{0.0};
  /// Averages behind the estimate (for the coherence), >= 2 with coherence.
  int averages{5};
  unsigned seed{1};
  /// Also give a coherence, the value that an H1 estimate averaged over
  /// n = `averages` impacts of equal force has for this noise: the impacts'
  /// scatter about their mean is (n − 1) n σ² and |H|² (1 − γ²)/γ² is that
  /// over n (see calibration/frf_noise.h), so
  /// γ² = |H|² / (|H|² + (n − 1) σ²), σ² = (relative_noise |H|)² + floor(f)².
  bool coherence{false};
  /// Round values to 13 significant digits (UFF58's E20.12) so CSV and UFF58
  /// copies of the data hold identical numbers.
  bool round_to_uff_precision{true};

  /// sample_rate_hz > 0; block_samples >= 2; 0 < fmin_hz < fmax_hz <=
  /// sample_rate_hz / 2 with at least one line of spacing sample_rate_hz /
  /// block_samples between them; the noise rms values and hammer_cutoff_hz
  /// finite and >= 0; averages >= 1 (>= 2 with coherence); directions not
  /// empty.
  /// @throws OptionError naming the field first, with its value and the
  ///   bound ("VirtualHammerOptions: fmax_hz 500000: above the Nyquist
  ///   frequency 2560 Hz of sample_rate_hz 5120").
  void Validate() const;
};

/// The sample rate a robot config gives its hammer tests (the value
/// `hammer_test.sample_rate_hz`), else `fallback` [Hz]: frf-synth's default.
double ConfiguredSampleRateHz(const dynamics::RobotDescription& description,
                              double fallback = VirtualHammerOptions{}.sample_rate_hz);

/// The additive noise floor of the options at one line [m/N] (see above).
double SynthNoiseFloor(const VirtualHammerOptions& options, double freq_hz);

/// The frequency lines of the options' grid [Hz]: f_p = f_0 + p Δf with
/// f_0 = ceil(fmin/Δf) Δf (the form a UFF58 reader reconstructs).
Eigen::VectorXd HammerTestGrid(const VirtualHammerOptions& options);

struct NamedPosture {
  std::string id;
  Eigen::VectorXd q;  // [rad]
};

/// The model's tool-tip receptance at each posture and direction pair, with
/// noise. Deterministic for a given seed.
dynamics::FrfSet SynthesizeHammerTest(const std::shared_ptr<const dynamics::RobotModel>& model,
                                      const std::vector<NamedPosture>& postures,
                                      const VirtualHammerOptions& options);

}  // namespace robomach::calibration
