#pragma once

#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/report/plot.h"

namespace robomach::report {

/// One FRF curve for a magnitude/phase plot.
struct FrfCurve {
  Eigen::VectorXd freq_hz;
  Eigen::VectorXcd receptance;  // [m/N]
  std::string label;            // e.g. "Hxx"
  Rgb color;
  bool dashed{false};
  int thickness{2};             // [px]
  /// Drawn in the magnitude panel only (a noise floor has no phase).
  bool magnitude_only{false};
  /// Optional confidence band of |H| (same length, its own lines): filled
  /// in the curve's colour under the curves in the magnitude panel.
  Eigen::VectorXd band_freq_hz{}, band_lower{}, band_upper{};  // [Hz], [m/N]
};

/// Fills a magnitude panel (log |H| in m/N) and a phase panel (degrees, -180..180)
/// with `curves` and marks `mode_freq_hz` as labelled vertical lines;
/// `mode_strength` (e.g. each mode's peak receptance; empty: all equal) says
/// whose labels are kept where they cannot all be placed.
/// The frequency axis is logarithmic when it spans more than two decades.
void FillFrfPanels(const std::vector<FrfCurve>& curves, const std::vector<double>& mode_freq_hz,
                   const std::string& title, Axes* magnitude, Axes* phase,
                   const std::vector<double>& mode_strength = {});

}  // namespace robomach::report
