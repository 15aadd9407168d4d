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

/// Wraps an angle deviation into (-180, 180] degrees.
double WrapDeviationDeg(double deviation_deg);

}  // namespace robomach::machine
