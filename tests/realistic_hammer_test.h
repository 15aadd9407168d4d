#pragma once

// Issue #10's "hammer data as they really come", shared by the calibration
// and audit tests and the audit benchmark: a 5120 Hz test (lines 0.625 to
// 2560 Hz, 4096 per FRF), 2 % relative noise plus an additive floor flat in
// acceleration (the accelerometer) and in receptance, raised above the
// hammer's 1 kHz cutoff, so that the signal-to-noise ratio falls below 1 a
// few hundred hertz up and at the lowest lines; and the sixth posture of
// the data set, far from the five demonstration postures.

#include <string>
#include <utility>
#include <vector>

#include "robomach/calibration/virtual_hammer_test.h"

namespace robomach::testing {

inline calibration::VirtualHammerOptions RealisticHammerTest(unsigned seed, bool coherence = false) {
  calibration::VirtualHammerOptions o;
  o.sample_rate_hz = 5120.0;
  o.block_samples = 8192;  // Δf = 0.625 Hz
  o.fmin_hz = 0.625;
  o.fmax_hz = 2560.0;
  o.relative_noise = 0.02;
  o.absolute_noise_m_per_s2_per_N = 1.5e-4;
  o.absolute_noise_m_per_N = 4e-9;
  o.hammer_cutoff_hz = 1000.0;
  o.averages = 5;
  o.coherence = coherence;
  o.seed = seed;
  return o;
}

/// P6 of the data set [deg].
inline std::pair<std::string, std::vector<double>> SixthPostureDeg() {
  return {"P6", {-40, -65, 85, 15, -50, -20}};
}

}  // namespace robomach::testing
