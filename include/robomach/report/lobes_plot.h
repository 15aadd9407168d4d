#pragma once
// The lobe diagram of stability-lobes --plot: critical axial depth against
// spindle speed, one curve per tool tip and method.

#include <string>
#include <vector>

namespace robomach::report {

/// One curve of the diagram: NaN depths (no boundary) leave a gap.
struct LobeCurve {
  std::string label;              // e.g. "P1 ZOA"
  std::vector<double> speed_rpm;  // [rpm]
  std::vector<double> depth_mm;   // [mm]
  bool markers{false};            // SD's points (a coarser grid) as markers
  /// Optional (parameter uncertainty): the depth's interval per speed [mm],
  /// drawn as a band in the curve's colour with its lower end (the safe
  /// depth) as a dashed line; empty or NaN: no band there.
  std::vector<double> lower_mm, upper_mm;
};

/// Where the depth axis ends, or NaN when it shows the curves' full range.
/// The axis shows the lobes' bottoms, the depths a user can cut: between
/// lobes the critical depth rises to tens or hundreds of mm, and a linear
/// axis up to that squashes the sub-mm bottoms flat. It ends at 5 x the
/// smallest critical depth of all curves (the first lobes above the bottom
/// and the stable pockets between them), raised to 1.5 x the largest of the
/// curves' own smallest depths so that every curve's bottom is in the
/// picture; NaN when the largest depth is within 5 % of that.
double LobesDepthAxisClipMm(const std::vector<LobeCurve>& curves);

/// Draws the diagram to a PNG: `title` above, `subtitle` on the panel
/// (teeth, immersion, milling direction). A clipped depth axis is said in
/// the panel's title, naming `csv_name` as where the full range is.
/// Bands: `band_note` says what they are (level and method, e.g. "95 %,
/// Monte Carlo"); with the band's meaning it labels a grey legend entry of
/// its own (the bands belong to no one posture).
/// A single banded curve is shaded; with more, overlapping shades mix into
/// another colour, so only their lower bounds are drawn (the upper ones are
/// in the CSV) and the legend calls them the lower bound. When no lobe clips the depth axis
/// but a band's upper edge rises above 1.5 times the largest depth, the
/// axis ends there (said in the panel's title).
void SaveLobesPlot(const std::string& path, const std::string& title, const std::string& subtitle,
                   const std::vector<LobeCurve>& curves, const std::string& csv_name,
                   const std::string& band_note = "");

}  // namespace robomach::report
