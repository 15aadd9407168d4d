#include "robomach/report/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "robomach/common/errors.h"
#include "robomach/io/atomic_file.h"

namespace robomach::report {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.5;
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);

cv::Scalar ToCv(Rgb c) { return cv::Scalar(c.b, c.g, c.r); }

std::string TickLabel(double v, bool log) {
  char buf[32];
  if (v == 0.0) return "0";
  const double a = std::abs(v);
  if (a >= 1e5 || a < 1e-3) {
    // As many mantissa digits as the tick needs ("1.5e-4", not "2e-4":
    // ticks in steps of 5e-5 must not be rounded to one digit).
    std::snprintf(buf, sizeof(buf), "%.6e", v);
    // "1.500000e-07" -> "1.5e-7"
    std::string s(buf);
    const size_t e = s.find('e');
    if (e != std::string::npos) {
      std::string mant = s.substr(0, e), ex = s.substr(e + 1);
      while (mant.back() == '0') mant.pop_back();
      if (mant.back() == '.') mant.pop_back();
      bool neg = ex[0] == '-';
      ex = ex.substr(1);
      while (ex.size() > 1 && ex[0] == '0') ex = ex.substr(1);
      if (log && mant == "1") return "1e" + std::string(neg ? "-" : "") + ex;
      return mant + "e" + (neg ? "-" : "") + ex;
    }
    return s;
  }
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

void PutText(cv::Mat& img, const std::string& s, cv::Point p, double scale = kFontScale,
             cv::Scalar color = kBlack, int thickness = 1) {
  cv::putText(img, s, p, kFont, scale, color, thickness, cv::LINE_AA);
}

cv::Size TextSize(const std::string& s, double scale = kFontScale, int thickness = 1) {
  int base = 0;
  return cv::getTextSize(s, kFont, scale, thickness, &base);
}

// Text rotated by 90° (reading upwards), centred at `centre`.
void PutVerticalText(cv::Mat& img, const std::string& s, cv::Point centre) {
  const cv::Size sz = TextSize(s);
  cv::Mat t(sz.height + 8, sz.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
  PutText(t, s, cv::Point(2, sz.height + 2));
  cv::Mat r;
  cv::rotate(t, r, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int x0 = std::clamp(centre.x - r.cols / 2, 0, img.cols - r.cols);
  const int y0 = std::clamp(centre.y - r.rows / 2, 0, img.rows - r.rows);
  r.copyTo(img(cv::Rect(x0, y0, r.cols, r.rows)));
}

void DashedLine(cv::Mat& img, cv::Point a, cv::Point b, cv::Scalar c, int thickness) {
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  const int n = std::max(1, static_cast<int>(len / 8.0));
  for (int i = 0; i < n; i += 2) {
    const double t0 = static_cast<double>(i) / n, t1 = std::min(1.0, static_cast<double>(i + 1) / n);
    cv::line(img, a + (b - a) * t0, a + (b - a) * t1, c, thickness, cv::LINE_AA);
  }
}

// A dashed polyline whose dashes run on across its vertices (8 px on, 8 px
// off along the path), so that a curve of many short segments still reads
// as dashed.
void DashedPolyline(cv::Mat& img, const std::vector<cv::Point>& pts, cv::Scalar c, int thickness) {
  constexpr double kDash = 8.0;
  double phase = 0.0;  // distance along the path modulo 2 kDash
  for (size_t i = 1; i < pts.size(); ++i) {
    const cv::Point2d a(pts[i - 1]), b(pts[i]);
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    double at = 0.0;
    while (at < len) {
      const bool on = phase < kDash;
      const double step = std::min(len - at, (on ? kDash : 2.0 * kDash) - phase);
      if (on && len > 0.0) {
        const cv::Point2d p0 = a + (b - a) * (at / len), p1 = a + (b - a) * ((at + step) / len);
        cv::line(img, cv::Point(cvRound(p0.x), cvRound(p0.y)), cv::Point(cvRound(p1.x), cvRound(p1.y)), c, thickness,
                 cv::LINE_AA);
      }
      at += step;
      phase = std::fmod(phase + step, 2.0 * kDash);
    }
  }
}

struct Range {
  double lo, hi;
};

Range DataRange(const Axes& ax, bool x_axis) {
  const bool log = x_axis ? ax.log_x : ax.log_y;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Series& s : ax.series) {
    for (double v : x_axis ? s.x : s.y) {
      if (!std::isfinite(v) || (log && v <= 0.0)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (x_axis) {
    for (const auto& m : ax.markers) {
      if (std::isfinite(m.x) && (!log || m.x > 0)) {
        lo = std::min(lo, m.x);
        hi = std::max(hi, m.x);
      }
    }
  }
  if (!std::isfinite(lo)) return {log ? 0.1 : 0.0, log ? 10.0 : 1.0};
  if (lo == hi) {
    if (log) return {lo / 2, hi * 2};
    const double d = lo == 0.0 ? 1.0 : std::abs(lo) * 0.1;
    return {lo - d, hi + d};
  }
  if (!log && !x_axis) {
    const double pad = 0.05 * (hi - lo);
    return {lo - pad, hi + pad};
  }
  if (log && !x_axis) return {lo / 1.3, hi * 1.3};
  return {lo, hi};
}

// ---- marker labels (issue #35: "10.4 Hz" read "1.4 Hz" where a curve ran
// through it).
constexpr double kLabelScale = 0.4;
constexpr int kLabelPad = 1;   // [px] between the text and its box
constexpr int kLabelGap = 3;   // [px] between a marker line and its label's box

int TextBaseline(const std::string& s, double scale) {
  int base = 0;
  cv::getTextSize(s, kFont, scale, 1, &base);
  return base;
}

struct MarkerLabel {
  std::string text;
  double data_x;
  int line_x;        // the marker line's column in the plot area [px]
  cv::Scalar color;
  double priority;   // VerticalMarker::priority
  cv::Rect box;      // in the plot area, set by PlaceLabels
  bool clear;        // set by PlaceLabels
  bool over_line;    // set by PlaceLabels: the box crosses another marker line
  bool placed;       // set by PlaceLabels: false = left out, no room
};

// Places each label beside its marker line, left or right of it, as high in
// the plot as it can go, on pixels that no curve (`ink`, 255 where a curve
// or the legend is), no label placed before it and, if at all possible, no
// other marker line occupies. Where marker lines are closer than a label is
// wide, it may cross other marker lines (over_line = true; it is drawn on a
// white ground that interrupts them, so that a dashed line through "10.4"
// cannot read "1.4"). A label that finds no place free of curves goes where
// it covers the fewest curve pixels, with clear = false; one that finds no
// place clear of the labels before it is left out (placed = false): with
// thirty modes in a panel, overlapping labels are unreadable. Labels are
// placed by descending priority, so the strongest modes keep theirs.
// Exhaustive over the
// plot's rows: a few hundred candidate boxes per label, each checked with
// the summed-area table in constant time.
void PlaceLabels(const cv::Mat1b& ink, const cv::Rect& legend, const std::vector<int>& line_x,
                 std::vector<MarkerLabel>* labels) {
  const int W = ink.cols, H = ink.rows;
  // The legend is drawn over everything: no label goes under it, not even
  // one without a clear place.
  cv::Mat1b taken(ink.size(), static_cast<unsigned char>(0));
  taken(legend & cv::Rect(0, 0, W, H)).setTo(255);
  cv::Mat1i ink_sum;
  cv::integral(ink / 255, ink_sum, CV_32S);
  auto sum_of = [](const cv::Mat1i& s, const cv::Rect& r) {
    return s(r.y + r.height, r.x + r.width) - s(r.y, r.x + r.width) - s(r.y + r.height, r.x) + s(r.y, r.x);
  };
  // By priority, then left to right: the label of the lower frequency takes
  // its place first.
  std::vector<MarkerLabel*> order;
  for (auto& l : *labels) order.push_back(&l);
  std::stable_sort(order.begin(), order.end(), [](auto* a, auto* b) {
    if (a->priority != b->priority) return a->priority > b->priority;
    return a->line_x < b->line_x;
  });
  for (MarkerLabel* l : order) {
    const cv::Size sz = TextSize(l->text, kLabelScale);
    const int bw = sz.width + 2 * kLabelPad;
    const int bh = sz.height + TextBaseline(l->text, kLabelScale) + 2 * kLabelPad;
    cv::Mat1i taken_sum;
    cv::integral(taken / 255, taken_sum, CV_32S);
    const auto crosses_other_line = [&](const cv::Rect& r) {
      for (int x : line_x) {
        if (x != l->line_x && x >= r.x - 1 && x <= r.x + r.width) return true;
      }
      return false;
    };
    // Cost in pixels: the height below the top, and a label left of its
    // line costs as if it were 8 px lower (right of the line reads first).
    long best_cost = std::numeric_limits<long>::max();
    cv::Rect best;
    bool found = false, over_line = false;
    for (int pass = 0; pass < 2 && !found; ++pass) {
      for (int side = 0; side < 2; ++side) {
        const int bx = side == 0 ? l->line_x + kLabelGap : l->line_x - kLabelGap - bw;
        if (bx < 1 || bx + bw > W - 1) continue;
        for (int by = 3; by + bh <= H - 2; ++by) {
          const cv::Rect r(bx, by, bw, bh);
          const long cost = by + 8L * side;
          if (cost >= best_cost) break;
          if (sum_of(ink_sum, r) > 0 || sum_of(taken_sum, r) > 0) continue;
          if (pass == 0 && crosses_other_line(r)) continue;
          best_cost = cost;
          best = r;
          found = true;
          over_line = pass == 1;
          break;
        }
      }
    }
    if (!found) {
      // No clear place: the fewest curve pixels, then the highest, but
      // never over another label.
      long fewest = std::numeric_limits<long>::max();
      for (int side = 0; side < 2; ++side) {
        const int bx = std::clamp(side == 0 ? l->line_x + kLabelGap : l->line_x - kLabelGap - bw, 0, std::max(0, W - bw));
        for (int by = 0; by + bh <= H; ++by) {
          const cv::Rect r(bx, by, std::min(bw, W), bh);
          if (sum_of(taken_sum, r) > 0) continue;
          const long c = 1000L * sum_of(ink_sum, r) + by;
          if (c < fewest) fewest = c, best = r;
        }
      }
      if (fewest == std::numeric_limits<long>::max()) {
        l->placed = false;
        continue;
      }
    }
    l->placed = true;
    l->box = best;
    l->clear = found;
    l->over_line = over_line || (!found && crosses_other_line(best));
    // A label keeps 6 px of space beside it and 1 px above and below: two
    // labels side by side would read as one line of text.
    const cv::Rect grown = cv::Rect(best.x - 6, best.y - 1, best.width + 12, best.height + 2) & cv::Rect(0, 0, W, H);
    taken(grown).setTo(255);
  }
}

// The plot area of a panel and its data-to-pixel mapping: every stage of
// RenderAxes maps through the same ranges, so they are fixed once here.
struct PlotFrame {
  cv::Rect plot;
  Range xr, yr;
  bool log_x = false, log_y = false;
  // Image column of the data value v (not rounded).
  double Tx(double v) const {
    const double t = log_x ? (std::log10(v) - std::log10(xr.lo)) / (std::log10(xr.hi) - std::log10(xr.lo))
                           : (v - xr.lo) / (xr.hi - xr.lo);
    return plot.x + t * plot.width;
  }
  // Image row of the data value v (not rounded).
  double Ty(double v) const {
    const double t = log_y ? (std::log10(v) - std::log10(yr.lo)) / (std::log10(yr.hi) - std::log10(yr.lo))
                           : (v - yr.lo) / (yr.hi - yr.lo);
    return plot.y + plot.height - t * plot.height;
  }
  // A data point's pixel in the plot area, clamped far outside it.
  cv::Point ToPx(double x, double y) const {
    return cv::Point(static_cast<int>(std::lround(std::clamp(Tx(x) - plot.x, -1e4, 1e4))),
                     static_cast<int>(std::lround(std::clamp(Ty(y) - plot.y, -1e4, 1e4))));
  }
};

// The plot area inside `area` (margins for the ticks, labels and title) and
// the axis ranges: the data's, unless the axes fix them.
PlotFrame MakePlotFrame(const Axes& ax, cv::Rect area) {
  const int left = 80, right = 20, top = 28, bottom = 48;
  PlotFrame f;
  f.plot = cv::Rect(area.x + left, area.y + top, area.width - left - right, area.height - top - bottom);
  f.xr = DataRange(ax, true);
  f.yr = DataRange(ax, false);
  if (std::isfinite(ax.x_min)) f.xr.lo = ax.x_min;
  if (std::isfinite(ax.x_max)) f.xr.hi = ax.x_max;
  if (std::isfinite(ax.y_min)) f.yr.lo = ax.y_min;
  if (std::isfinite(ax.y_max)) f.yr.hi = ax.y_max;
  f.log_x = ax.log_x;
  f.log_y = ax.log_y;
  return f;
}

// Grid lines and tick labels of both axes (drawn first: all else goes over
// them).
void DrawGridAndTicks(cv::Mat& img, const Axes& ax, const PlotFrame& f) {
  const cv::Rect& plot = f.plot;
  const Range &xr = f.xr, &yr = f.yr;
  const auto xt = ax.log_x ? LogTicks(xr.lo, xr.hi) : LinearTicks(xr.lo, xr.hi);
  const auto yt = !ax.y_ticks.empty() ? ax.y_ticks : ax.log_y ? LogTicks(yr.lo, yr.hi)
                                                               : LinearTicks(yr.lo, yr.hi, 5);
  for (double v : xt) {
    const int x = static_cast<int>(std::lround(f.Tx(v)));
    if (x < plot.x - 1 || x > plot.x + plot.width + 1) continue;
    cv::line(img, {x, plot.y}, {x, plot.y + plot.height}, kGrid, 1);
    const std::string s = TickLabel(v, ax.log_x);
    const cv::Size sz = TextSize(s);
    PutText(img, s, {x - sz.width / 2, plot.y + plot.height + 18});
  }
  for (double v : yt) {
    if (v < std::min(yr.lo, yr.hi) - 1e-12 * std::abs(yr.hi) || v > std::max(yr.lo, yr.hi) + 1e-12 * std::abs(yr.hi)) continue;
    const int y = static_cast<int>(std::lround(f.Ty(v)));
    cv::line(img, {plot.x, y}, {plot.x + plot.width, y}, kGrid, 1);
    const std::string s = TickLabel(v, ax.log_y);
    const cv::Size sz = TextSize(s);
    PutText(img, s, {plot.x - sz.width - 6, y + sz.height / 2});
  }
}

// The series with a y_fill_to: bands between two curves, blended into the
// plot area `roi` before the curves so that they lie under them.
void DrawBands(cv::Mat& roi, const Axes& ax, const PlotFrame& f) {
  for (const Series& s : ax.series) {
    if (s.y_fill_to.empty()) continue;
    cv::Mat overlay = roi.clone();
    std::vector<cv::Point> top, bottom;
    auto fill = [&] {
      if (top.size() >= 2) {
        std::vector<cv::Point> poly(top);
        poly.insert(poly.end(), bottom.rbegin(), bottom.rend());
        cv::fillPoly(overlay, std::vector<std::vector<cv::Point>>{poly}, ToCv(s.color), cv::LINE_AA);
      }
      top.clear();
      bottom.clear();
    };
    const size_t n = std::min({s.x.size(), s.y.size(), s.y_fill_to.size()});
    for (size_t i = 0; i < n; ++i) {
      const bool ok = std::isfinite(s.x[i]) && std::isfinite(s.y[i]) && std::isfinite(s.y_fill_to[i]) &&
                      (!ax.log_x || s.x[i] > 0) && (!ax.log_y || (s.y[i] > 0 && s.y_fill_to[i] > 0));
      if (!ok) {
        fill();
        continue;
      }
      top.push_back(f.ToPx(s.x[i], s.y[i]));
      bottom.push_back(f.ToPx(s.x[i], s.y_fill_to[i]));
    }
    fill();
    cv::addWeighted(overlay, 0.25, roi, 0.75, 0.0, roi);
  }
}

// The lines and point markers of the other series into the plot area `roi`,
// each also into `ink` (widened for the antialiased edge) for the placing of
// the legend and the marker labels.
void DrawCurves(cv::Mat& roi, cv::Mat1b& ink, const Axes& ax, const PlotFrame& f) {
  const cv::Rect& plot = f.plot;
  for (const Series& s : ax.series) {
    if (!s.y_fill_to.empty()) continue;  // a band only
    std::vector<cv::Point> pts;
    auto flush = [&] {
      if (pts.size() >= 2 && !s.markers) {
        if (s.dashed) {
          DashedPolyline(roi, pts, ToCv(s.color), s.thickness);
        } else {
          cv::polylines(roi, pts, false, ToCv(s.color), s.thickness, cv::LINE_AA);
        }
        cv::polylines(ink, pts, false, cv::Scalar(255), s.thickness + 2, cv::LINE_8);
      }
      pts.clear();
    };
    const size_t n = std::min(s.x.size(), s.y.size());
    for (size_t i = 0; i < n; ++i) {
      const bool ok = std::isfinite(s.x[i]) && std::isfinite(s.y[i]) &&
                      (!ax.log_x || s.x[i] > 0) && (!ax.log_y || s.y[i] > 0);
      if (!ok) {
        flush();
        continue;
      }
      const double px = std::clamp(f.Tx(s.x[i]) - plot.x, -1e4, 1e4);
      const double py = std::clamp(f.Ty(s.y[i]) - plot.y, -1e4, 1e4);
      const cv::Point p(static_cast<int>(std::lround(px)), static_cast<int>(std::lround(py)));
      if (s.markers) {
        cv::circle(roi, p, 3, ToCv(s.color), cv::FILLED, cv::LINE_AA);
        cv::circle(ink, p, 5, cv::Scalar(255), cv::FILLED);
      }
      pts.push_back(p);
    }
    flush();
  }
}

// The legend of a panel: its entries and its box in image coordinates.
struct LegendLayout {
  std::vector<const Series*> listed;
  int count = 0;
  cv::Rect box;
};

// The legend's box in a corner inside the plot (drawn last, reserved now
// so that no label is put under it): the preferred corner unless it hides
// curves or points, else the corner that hides the fewest. Only series
// with a point to draw are listed ("measured, not used" when every line
// was used would name a curve that is not there).
LegendLayout PlaceLegend(const Axes& ax, const PlotFrame& f, cv::Mat1b& ink) {
  const cv::Rect& plot = f.plot;
  LegendLayout lg;
  std::vector<const Series*>& listed = lg.listed;
  for (const Series& s : ax.series) {
    if (s.label.empty()) continue;
    bool any = false;
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()) && !any; ++i) {
      any = std::isfinite(s.x[i]) && std::isfinite(s.y[i]) && (!ax.log_x || s.x[i] > 0) && (!ax.log_y || s.y[i] > 0);
    }
    if (any) listed.push_back(&s);
  }
  int legend_width = 0;
  for (const Series* s : listed) legend_width = std::max(legend_width, TextSize(s->label).width);
  const int count = static_cast<int>(listed.size());
  lg.count = count;
  using LP = Axes::LegendPosition;
  const auto legend_box_at = [&](LP corner) {
    const bool at_right = corner == LP::kTopRight || corner == LP::kBottomRight;
    const bool at_top = corner == LP::kTopRight || corner == LP::kTopLeft;
    const int x = at_right ? plot.x + plot.width - legend_width - 50 : plot.x + 14;
    const int y = at_top ? plot.y + 8 : plot.y + plot.height - 18 * count - 10;
    return cv::Rect(x - 6, y - 2, legend_width + 54, 18 * count + 6);
  };
  cv::Rect& legend_box = lg.box;
  legend_box = legend_box_at(ax.legend);
  if (count > 0) {
    const auto hidden = [&](const cv::Rect& box) {
      const cv::Rect r = (box - plot.tl()) & cv::Rect(0, 0, ink.cols, ink.rows);
      return r.empty() ? 0 : cv::countNonZero(ink(r));
    };
    int fewest = hidden(legend_box);
    for (LP corner : {LP::kTopRight, LP::kTopLeft, LP::kBottomLeft, LP::kBottomRight}) {
      const cv::Rect box = legend_box_at(corner);
      const int n = hidden(box);
      if (n < fewest) fewest = n, legend_box = box;
    }
    cv::rectangle(ink, legend_box - plot.tl(), cv::Scalar(255), cv::FILLED);
  }
  return lg;
}

// Where RenderAxes reports what it placed: the panel's index and the
// caller's lists (either may be null).
struct PanelSink {
  int panel;
  std::vector<PlacedLabel>* placed;
  std::vector<PlacedLegend>* legends;
};

// How many marker labels a panel had, and how many found no room (the
// title says so).
struct MarkerLabelCount {
  size_t total = 0;
  int left_out = 0;
};

// Vertical markers: the dashed lines, then their labels where they cross
// no curve, no other label and, if possible, no other marker line.
MarkerLabelCount DrawMarkers(cv::Mat& img, const Axes& ax, const PlotFrame& f, const cv::Mat1b& ink,
                             const LegendLayout& legend, const PanelSink& out) {
  const cv::Rect& plot = f.plot;
  const Range& xr = f.xr;
  std::vector<MarkerLabel> labels;
  std::vector<int> line_x;
  for (const auto& m : ax.markers) {
    if (!std::isfinite(m.x) || m.x < std::min(xr.lo, xr.hi) || m.x > std::max(xr.lo, xr.hi)) continue;
    const int x = static_cast<int>(std::lround(f.Tx(m.x)));
    DashedLine(img, {x, plot.y}, {x, plot.y + plot.height}, ToCv(m.color), 1);
    line_x.push_back(x - plot.x);
    if (!m.label.empty()) labels.push_back({m.label, m.x, x - plot.x, ToCv(m.color), m.priority, {}, true, false, true});
  }
  PlaceLabels(ink, legend.count > 0 ? legend.box - plot.tl() : cv::Rect(), line_x, &labels);
  int left_out = 0;
  for (MarkerLabel& l : labels) {
    if (!l.placed) {
      ++left_out;
      continue;
    }
    const cv::Rect box = l.box + plot.tl();
    // Over another marker line, or without a clear place, the label gets a
    // white ground: it then hides a piece of that line or curve instead of
    // being crossed by it.
    if (!l.clear || l.over_line) cv::rectangle(img, box, cv::Scalar(255, 255, 255), cv::FILLED);
    PutText(img, l.text, {box.x + kLabelPad, box.y + box.height - kLabelPad - TextBaseline(l.text, kLabelScale)},
            kLabelScale, l.color);
    if (out.placed) out.placed->push_back({out.panel, l.text, l.data_x, box.x, box.y, box.width, box.height,
                                           l.line_x + plot.x, l.clear, l.over_line});
  }
  return {labels.size(), left_out};
}

// The axis labels and the panel's title (which counts the marker labels
// left out for want of room).
void DrawAxisLabelsAndTitle(cv::Mat& img, const Axes& ax, cv::Rect area, const PlotFrame& f,
                            const MarkerLabelCount& marks) {
  const cv::Rect& plot = f.plot;
  const cv::Size xs = TextSize(ax.x_label);
  PutText(img, ax.x_label, {plot.x + plot.width / 2 - xs.width / 2, area.y + area.height - 8});
  PutVerticalText(img, ax.y_label, {area.x + 14, plot.y + plot.height / 2});
  std::string title = ax.title;
  if (marks.left_out > 0) {
    title += std::string(title.empty() ? "" : " ") + "(" + std::to_string(marks.left_out) + " of " +
             std::to_string(marks.total) + " line labels left out: no room)";
  }
  if (!title.empty()) {
    PutText(img, title, {plot.x, area.y + 19}, 0.55, kBlack, 1);
  }
}

// The legend, drawn last over everything in the box PlaceLegend chose.
void DrawLegend(cv::Mat& img, const LegendLayout& legend, const PanelSink& out) {
  const cv::Rect& legend_box = legend.box;
  int lx = legend_box.x + 6, ly = legend_box.y + 2;
  if (legend.count > 0) {
    if (out.legends) {
      PlacedLegend pl{out.panel, {}, legend_box.x, legend_box.y, legend_box.width, legend_box.height};
      for (const Series* s : legend.listed) pl.entries.push_back(s->label);
      out.legends->push_back(std::move(pl));
    }
    cv::rectangle(img, legend_box, cv::Scalar(255, 255, 255), cv::FILLED);
    cv::rectangle(img, legend_box, cv::Scalar(180, 180, 180), 1);
    for (const Series* sp : legend.listed) {
      const Series& s = *sp;
      if (s.dashed) DashedLine(img, {lx, ly + 9}, {lx + 36, ly + 9}, ToCv(s.color), s.thickness);
      else if (s.markers) cv::circle(img, {lx + 18, ly + 9}, 3, ToCv(s.color), cv::FILLED);
      else cv::line(img, {lx, ly + 9}, {lx + 36, ly + 9}, ToCv(s.color), s.thickness, cv::LINE_AA);
      PutText(img, s.label, {lx + 42, ly + 14}, 0.45);
      ly += 18;
    }
  }
}

void RenderAxes(cv::Mat& img, const Axes& ax, cv::Rect area, int panel, std::vector<PlacedLabel>* placed,
                std::vector<PlacedLegend>* legends) {
  const PlotFrame f = MakePlotFrame(ax, area);
  // Grid and ticks.
  DrawGridAndTicks(img, ax, f);
  // Curves, clipped to the plot area. `ink` marks every pixel a curve
  // covers, widened by a pixel on each side for the antialiased edge: the
  // marker labels are placed where it is clear (PlaceLabels).
  cv::Mat roi = img(f.plot);
  cv::Mat1b ink(f.plot.size(), static_cast<unsigned char>(0));
  // Bands first, blended under the curves.
  DrawBands(roi, ax, f);
  DrawCurves(roi, ink, ax, f);
  const LegendLayout legend = PlaceLegend(ax, f, ink);
  const PanelSink out{panel, placed, legends};
  const MarkerLabelCount marks = DrawMarkers(img, ax, f, ink, legend, out);
  cv::rectangle(img, f.plot, kBlack, 1);
  // Labels and title.
  DrawAxisLabelsAndTitle(img, ax, area, f, marks);
  // Legend.
  DrawLegend(img, legend, out);
}

}  // namespace

Rgb PaletteColor(int i) {
  static const Rgb kColors[] = {{0, 114, 178},  {213, 94, 0},  {0, 158, 115}, {204, 121, 167},
                                {230, 159, 0},  {86, 180, 233}, {0, 0, 0},     {240, 228, 66}};
  return kColors[((i % 8) + 8) % 8];
}

std::vector<double> LinearTicks(double lo, double hi, int target_count) {
  if (hi < lo) std::swap(lo, hi);
  const double span = hi - lo;
  if (!(span > 0) || !std::isfinite(span)) return {lo};
  const double raw = span / std::max(1, target_count);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  }
  std::vector<double> t;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) {
    t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  }
  return t;
}

std::vector<double> LogTicks(double lo, double hi) {
  if (hi < lo) std::swap(lo, hi);
  std::vector<double> t;
  const int d0 = static_cast<int>(std::floor(std::log10(lo)));
  const int d1 = static_cast<int>(std::ceil(std::log10(hi)));
  const bool fine = d1 - d0 <= 3;
  for (int d = d0; d <= d1; ++d) {
    for (double m : fine ? std::vector<double>{1, 2, 5} : std::vector<double>{1}) {
      const double v = m * std::pow(10.0, d);
      if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) t.push_back(v);
    }
  }
  return t;
}

Figure::Figure(int rows, int cols, int panel_width_px, int panel_height_px)
    : rows_(rows), cols_(cols), panel_w_(panel_width_px), panel_h_(panel_height_px), axes_(rows * cols) {
  if (rows < 1 || cols < 1) throw std::invalid_argument("Figure: needs at least one panel");
}

std::vector<unsigned char> Figure::EncodePng(std::vector<PlacedLabel>* labels,
                                             std::vector<PlacedLegend>* legends) const {
  if (labels) labels->clear();
  if (legends) legends->clear();
  const int title_h = title.empty() ? 0 : 34;
  cv::Mat img(rows_ * panel_h_ + title_h, cols_ * panel_w_, CV_8UC3, cv::Scalar(255, 255, 255));
  if (!title.empty()) {
    // A title wider than the figure is set smaller (down to the size of a
    // panel's title) rather than cut at both ends.
    double scale = 0.7;
    while (scale > 0.5 && TextSize(title, scale, 2).width > img.cols - 16) scale -= 0.025;
    const cv::Size sz = TextSize(title, scale, 2);
    PutText(img, title, {std::max(4, img.cols / 2 - sz.width / 2), 24}, scale, kBlack, 2);
  }
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < cols_; ++c) {
      RenderAxes(img, axes_[r * cols_ + c], cv::Rect(c * panel_w_, title_h + r * panel_h_, panel_w_, panel_h_),
                 r * cols_ + c, labels, legends);
    }
  }
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", img, png)) throw OutputError("PNG encoding failed");
  return png;
}

void Figure::SavePng(const std::string& path) const {
  const std::vector<unsigned char> png = EncodePng();
  io::WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace robomach::report
