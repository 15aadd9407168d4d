#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace robomach::report {

/// An RGB colour, 0..255 per channel.
struct Rgb {
  unsigned char r{0}, g{0}, b{0};
};

/// Colours that stay distinct for colour-blind readers (Okabe and Ito 2008).
Rgb PaletteColor(int i);

/// One curve of a plot.
struct Series {
  std::vector<double> x;
  std::vector<double> y;
  std::string label;       // shown in the legend if not empty
  Rgb color;
  int thickness{2};        // [px]
  bool dashed{false};
  bool markers{false};     // small circles at the points instead of a line
  /// Optional: the series is a band filled between y and these values
  /// (same x), in its colour at 25 % opacity, under every curve, with no
  /// line of its own; a non-finite value on either side leaves a gap (a
  /// confidence band).
  std::vector<double> y_fill_to;
};

/// A labelled vertical line (a mode frequency, a limit).
struct VerticalMarker {
  double x{0.0};
  std::string label;
  Rgb color{120, 120, 120};
  /// Which labels are kept when they cannot all be placed (a mode's peak
  /// receptance, say): labels are placed in descending priority, and one
  /// that finds no place clear of the labels placed before it is left out
  /// (its line is still drawn). Equal priorities: left to right.
  double priority{0.0};
};

/// One panel: axes with labelled ticks, grid, curves, legend. Units belong
/// in the axis labels ("frequency [Hz]").
struct Axes {
  std::string title;
  std::string x_label;
  std::string y_label;
  bool log_x{false};
  bool log_y{false};
  /// Fixed ranges; NaN means "from the data".
  double x_min{NAN}, x_max{NAN}, y_min{NAN}, y_max{NAN};
  std::vector<Series> series;
  std::vector<VerticalMarker> markers;
  /// Fixed y ticks (e.g. every 90° for phase); empty = automatic.
  std::vector<double> y_ticks;
  /// The preferred corner of the legend. Where its box would hide a curve
  /// or points, the legend goes to the corner where it hides the fewest
  /// (the preferred one on a tie). Series without a finite point to draw
  /// get no legend entry.
  enum class LegendPosition { kTopRight, kTopLeft, kBottomLeft, kBottomRight };
  LegendPosition legend{LegendPosition::kTopRight};
};

/// Where a marker's label was drawn, in pixels of the PNG (origin top left).
/// Labels go beside their marker line, left or right of it, where their box
/// crosses no curve, no legend and no other label, and, where there is room,
/// no other marker line (see over_marker_line). Labels never overlap each
/// other: one without room is left out (VerticalMarker::priority says which)
/// and the panel's title says how many were.
struct PlacedLabel {
  int panel{0};             // row * cols + col
  std::string text;
  double marker_x{0.0};     // the marker's x, in data units
  int x{0}, y{0}, width{0}, height{0};  // the label's box [px]
  int line_x{0};            // the marker line's pixel column
  /// false: no clear place in the panel; the label is drawn on a white box
  /// over the curves (it hides a piece of a curve rather than being crossed).
  bool clear{true};
  /// true: marker lines closer than the label is wide; the box crosses
  /// another marker line and is drawn on a white ground that interrupts it.
  bool over_marker_line{false};
};

/// Where a panel's legend was drawn and what it lists.
struct PlacedLegend {
  int panel{0};
  std::vector<std::string> entries;     // the series' labels, in order
  int x{0}, y{0}, width{0}, height{0};  // the box [px]
};

/// A figure of rows × cols panels rendered to PNG.
class Figure {
 public:
  Figure(int rows, int cols, int panel_width_px = 900, int panel_height_px = 380);
  Axes& at(int row, int col) { return axes_[row * cols_ + col]; }
  std::string title;
  /// Renders and writes atomically (formats.md §4).
  /// @throws OutputError if the file cannot be written.
  void SavePng(const std::string& path) const;
  /// Encoded PNG bytes; `labels`, if given, receives where each marker
  /// label was drawn, `legends` where each legend was (for tests and callers
  /// that annotate further).
  std::vector<unsigned char> EncodePng(std::vector<PlacedLabel>* labels = nullptr,
                                       std::vector<PlacedLegend>* legends = nullptr) const;

 private:
  int rows_, cols_, panel_w_, panel_h_;
  std::vector<Axes> axes_;
};

/// "Nice" tick positions for a linear axis (steps of 1, 2 or 5 × 10^k).
std::vector<double> LinearTicks(double lo, double hi, int target_count = 6);
/// Decades (and 2, 5 within them when few decades) for a log axis.
std::vector<double> LogTicks(double lo, double hi);

}  // namespace robomach::report
