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
  /// Noise added to each line: H (1 + relative_noise · n₁) + absolute_noise · n₂,
  /// n₁, n₂ complex standard normal (each part of variance 1/2), so these
  /// are rms values: relative [-] and absolute [m/N].
  double relative_noise{0.0};
  double absolute_noise_m_per_N{0.0};
  unsigned seed{1};
  /// Also give a coherence: the value an H1 estimate has with output noise
  /// of the variance above, γ² = |H|² / (|H|² + σ²) with
  /// σ² = (relative_noise |H|)² + absolute_noise² (one average).
  bool coherence{false};
  /// Round values to 13 significant digits (UFF58's E20.12) so CSV and UFF58
  /// copies of the data hold identical numbers.
  bool round_to_uff_precision{true};
};

/// @throws std::invalid_argument naming the field for a bad option.
void CheckValid(const VirtualHammerOptions& options);

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
