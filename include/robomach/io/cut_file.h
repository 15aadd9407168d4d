#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/stability/milling.h"

namespace robomach::io {

/// A milling cut as `cut_*.yaml` describes it (see config/cut_demo.yaml for
/// the documented schema). Values in SI and radians.
struct CutSpec {
  stability::MillingProcess process;
  double tool_diameter{0.0};               // [m]
  double feed_per_tooth{0.0};              // [m]
  Eigen::Vector3d feed_direction_B{Eigen::Vector3d::UnitX()};  // unit, base frame
  double spindle_speed_min_rad_s{0.0};
  double spindle_speed_max_rad_s{0.0};
  int spindle_speed_count{200};            // speeds scanned in [min, max]
  std::optional<double> spindle_speed_rad_s;  // the operating speed, if fixed
  std::string path;
  int feed_line{0}, feed_column{0};        // where feed_direction is, for messages
  /// "implausible (unit mistake?): file:line:col: ..." for each value outside
  /// its plausible range below (docs/plausibility.md): a tool prints them and
  /// flags its result (exit 3).
  std::vector<std::string> implausible;

  /// `spindle_speed_count` speeds evenly spaced in [min, max] (or the fixed one).
  Eigen::VectorXd SpeedGrid() const;
  /// `count` speeds evenly spaced in [min, max] (0: spindle_speed_count),
  /// the fixed speed ignored: stability-lobes' grids.
  Eigen::VectorXd SpeedRange(int count) const;
};

// Plausible ranges of a cut file's values, about 100 times wider than
// practice (docs/plausibility.md). Sources: Sandvik Coromant, Milling
// technical guide (cutter diameters from 0.1 mm micro end mills to 500 mm
// face mills; feeds per tooth 0.01 to 0.5 mm); Altintas, Manufacturing
// Automation, 2nd ed. (2012), Ch. 2 and 3 (tangential cutting coefficients
// of aluminium to nickel alloys about 300 to 4000 N/mm²).
inline constexpr double kMinPlausibleCutterDiameterMm = 0.05;
inline constexpr double kMaxPlausibleCutterDiameterMm = 1000.0;
inline constexpr double kMinPlausibleFeedPerToothMm = 1e-4;
inline constexpr double kMaxPlausibleFeedPerToothMm = 5.0;
inline constexpr double kMinPlausibleCuttingCoefficientNPerMm2 = 10.0;   // ktc, Ks
inline constexpr double kMaxPlausibleCuttingCoefficientNPerMm2 = 1e5;    // ktc, krc, kac, Ks
inline constexpr double kMinPlausibleSpindleSpeedRpm = 10.0;
inline constexpr double kMaxPlausibleSpindleSpeedRpm = 200000.0;

/// Reads a cut file. Keys: `diameter_mm`, `teeth` (>= 1), `radial_immersion`
/// (a_e/D in (0, 1]), `milling` (up | down), `feed_direction` ([x, y, z] in
/// the base frame), `feed_per_tooth_mm`, `cutting_coefficients` with either
/// `ktc_N_per_mm2`, `krc_N_per_mm2` (and optional `kac_N_per_mm2`) or
/// `Ks_N_per_mm2` with `beta_deg`; `spindle_speed_min_rpm`,
/// `spindle_speed_max_rpm`, optional `spindle_speed_count` and
/// `spindle_speed_rpm`. Unknown keys are rejected. Values outside the
/// plausible ranges above are listed in CutSpec::implausible.
/// @throws InputError with file:line:col naming the key and what was expected.
CutSpec ReadCutFile(const std::string& path);

}  // namespace robomach::io
