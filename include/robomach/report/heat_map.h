#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace robomach::report {

/// A scalar field on a regular grid drawn as coloured cells with axes, a
/// colour bar and a legend entry for cells without a value. Units belong in
/// the labels ("x [mm]", "critical depth [mm]").
struct HeatMap {
  std::string title;
  std::string x_label, y_label, colorbar_label;
  double x0{0.0}, y0{0.0};   // centre of cell (0, 0)
  double dx{1.0}, dy{1.0};   // cell pitch
  int nx{0}, ny{0};
  std::vector<double> values;        // row-major, ny rows of nx; NaN = no value
  std::vector<int> marks;            // same size or empty; 0 = none, 1 = hatched
  std::string mark_label;            // legend text of hatched cells, e.g. "unreachable"
  std::string nan_label{"no value"}; // legend text of grey cells
  /// Categorical axes: one label per column / row at the cell centres
  /// instead of numeric ticks (e.g. mode numbers, posture ids); ASCII only.
  std::vector<std::string> x_tick_labels;
  std::vector<std::string> y_tick_labels;
  bool first_row_at_top{false};      // row 0 drawn at the top (tables), not the bottom (plots)
  bool annotate{false};              // print each cell's value (3 significant digits) in it
  bool symmetric_range{false};       // colour range −max|v| … +max|v|: 0 in the middle
  /// The colour range when both are finite (values beyond take the end
  /// colours): maps to be compared side by side share one scale.
  double range_min{NAN}, range_max{NAN};
  int width_px{1000}, height_px{720};
};

/// Renders to PNG bytes (viridis colours, colour bar with ticks).
/// @throws std::invalid_argument, naming the field, for a map that cannot be
///   drawn: nx or ny < 1, dx or dy zero or not finite, values (or non-empty
///   marks) not of nx · ny cells, or a size that leaves no room for the plot.
std::vector<unsigned char> EncodeHeatMapPng(const HeatMap& map);
/// Renders and writes atomically (formats.md §4).
/// @throws OutputError if the file cannot be written.
void SaveHeatMapPng(const HeatMap& map, const std::string& path);
/// Several maps stacked top to bottom in one PNG (the widest sets the width).
std::vector<unsigned char> EncodeHeatMapsPng(const std::vector<HeatMap>& maps);
void SaveHeatMapsPng(const std::vector<HeatMap>& maps, const std::string& path);

}  // namespace robomach::report
