#pragma once
// Positioning accuracy and repeatability of an axis per ISO 230-2:2014 §2-§3
// (formats.md §8.6). Unit-neutral: every value is in the unit of the
// deviations given (mm for linear axes, degrees for rotary ones, as the runs
// file writes them; this is the one place the library keeps a file unit,
// because ISO 230-2 figures are reported in it and nothing is converted).

#include <string>
#include <vector>

namespace robomach::machine {

/// One approach of a target position.
struct Iso230Approach {
  double target{0.0};
  int run{1};          // 1..m
  bool up{true};       // approached moving in + direction (ISO's upward arrow)
  double deviation{0.0};  // measured - target (wrapped for rotary axes)
};

/// Per-target statistics; names follow ISO 230-2 (x̄i↑, si↑, Bi, Ri...).
struct Iso230Target {
  double target{0.0};
  int runs_up{0}, runs_down{0};
  double mean_up{0.0}, mean_down{0.0};   // mean unidirectional positioning deviation
  double s_up{0.0}, s_down{0.0};         // estimator of the standard uncertainty (m - 1 in the denominator)
  double mean{0.0};                      // mean bidirectional deviation (mean_up + mean_down) / 2
  double reversal{0.0};                  // Bi = mean_up - mean_down
  double R_up{0.0}, R_down{0.0};         // 4 s
  double R{0.0};                         // max(2 s_up + 2 s_down + |Bi|, R_up, R_down)
};

/// Axis figures of ISO 230-2 (formats.md §8.6 names).
struct Iso230Result {
  std::vector<Iso230Target> targets;  // in increasing target order
  double A{0.0}, A_up{0.0}, A_down{0.0};  // accuracy (bidirectional, unidirectional)
  double E{0.0}, E_up{0.0}, E_down{0.0};  // systematic positioning error
  double M{0.0};                          // mean bidirectional positioning error
  double R{0.0}, R_up{0.0}, R_down{0.0};  // repeatability
  double B{0.0};                          // reversal value: max |Bi|
  double B_mean{0.0};                     // mean reversal value: mean of Bi
};

/// @throws std::invalid_argument if a target lacks one direction or has
///   fewer than 2 runs in a direction (no standard uncertainty), if a run is
///   given twice, or if there are no targets.
Iso230Result EvaluateIso230(const std::vector<Iso230Approach>& approaches);

// Unit plausibility of positioning runs (issue #22 item 1). A machine-tool
// axis positions to tens of micrometres over its travel: ISO 10791-2 and
// ISO 10791-4 acceptance tolerances for A are 0.01-0.05 mm per 1000 mm of
// travel, uncompensated axes of large machines reach ~0.1 mm per metre
// (ISO/TR 230-9 examples); rotary axes are within 5-60 arcsec (ISO 10791-1
// A tolerances for B/C tables: 10-20 arcsec). The limits below are ~100
// times wider, so only a unit mistake exceeds them: micrometres under an
// _mm header (deviations 1000 times too large), measured values in um with
// targets in mm (deviations as large as the targets), arcsec under _deg.
//
// Short strokes (issue #34 item 5): the relative limit alone flagged a real
// stage of 8 mm stroke (targets -4..4 mm, deviations up to 0.10 mm, 1.25 %,
// measured by a laser triangulation sensor). Part of a small axis's error
// does not shrink with its stroke: the backlash of a lead-screw stage
// without a preloaded nut (0.02-0.1 mm), the lead error of a rolled screw
// (ISO 3408-3 class 10: 0.21 mm per 300 mm, and its periodic part within
// any turn), a triangulation sensor's linearity (0.1 % of a 10-50 mm
// range). So the relative limit has a floor, kMinPlausibleDeviationLimitMm
// = 0.25 mm (3.1 % of that 8 mm stroke, 2.5 times its 0.10 mm). The
// unit mistake stays caught: um under _mm multiplies every deviation by
// 1000, so a short axis is missed only if its true deviations are below
// 0.25 um (a nanopositioning stage; the plain 1 % missed those below
// 0.08 um of an 8 mm stroke), and any axis off by more than 1 um is caught
// by the absolute 1 mm limit whatever its stroke.
/// Largest plausible |deviation| of a linear axis as a fraction of the
/// targets' magnitude (max(|target|, travel)): 1 % is 10 mm per metre.
/// The limit is max(this x magnitude, kMinPlausibleDeviationLimitMm).
inline constexpr double kMaxPlausibleDeviationFraction = 0.01;
/// Floor of the relative limit [mm] (short strokes, see above).
inline constexpr double kMinPlausibleDeviationLimitMm = 0.25;
/// Largest plausible |deviation| of a linear axis [mm].
inline constexpr double kMaxPlausibleLinearDeviationMm = 1.0;
/// Largest plausible |deviation| of a rotary axis [deg] (3600 arcsec).
inline constexpr double kMaxPlausibleRotaryDeviationDeg = 1.0;

/// Findings of the unit plausibility check of one axis's result (the mean
/// deviations per direction and the ranges of the runs, mean ± 2 s, against
/// the limits above), each a sentence naming the axis, the value, the limit
/// and the likely unit mistake; empty if plausible. `unit` is "mm" or "deg".
std::vector<std::string> Iso230UnitFindings(const std::string& axis, const Iso230Result& result, bool rotary);

/// Wraps an angle deviation into (-180, 180] degrees.
double WrapDeviationDeg(double deviation_deg);

}  // namespace robomach::machine
