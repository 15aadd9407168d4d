#pragma once

#include <string>

#include <Eigen/Core>

#include "robomach/common/units.h"

namespace robomach::drilling {

/// Which axis of the tool-tip frame (at the initial posture) the hole runs along.
enum class HoleAxis { kTipX, kTipY, kTipZ };

/// "tip_x", "tip_y", "tip_z" (a drill file's process.hole_axis, formats.md §9.2).
const char* ToString(HoleAxis a);
/// The inverse of ToString. @throws std::invalid_argument "hole axis
/// 'NAME': expected tip_x, tip_y or tip_z".
HoleAxis ParseHoleAxis(const std::string& name);

/// The drilling scenario of formats.md §9.2 (`process:`, `offset:`,
/// `simulation:`), SI and radians.
struct DrillingProcess {
  double feed_per_rev{0.10e-3};            // f [m/rev]
  double spindle_speed_rad_s{RpmToRadPerSec(1500.0)};
  Eigen::VectorXd initial_posture;         // q0 [rad]
  HoleAxis hole_axis{HoleAxis::kTipZ};
  double initial_tilt{0.0};                // drill axis against the hole axis at entry [rad]
  double duration{2.0};                    // [s]
  double control_period{1e-3};             // [s], also the TDE delay
  double error_band{DegToRad(0.05)};       // [rad], for the settling time

  double feed_speed() const { return feed_per_rev * spindle_speed_rad_s / (2.0 * kPi); }  // [m/s]
};

}  // namespace robomach::drilling
