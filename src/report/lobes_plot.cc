#include "robomach/report/lobes_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "robomach/report/plot.h"

namespace robomach::report {

double LobesDepthAxisClipMm(const std::vector<LobeCurve>& curves) {
  double smallest = INFINITY, largest_bottom = 0.0, largest = 0.0;
  for (const LobeCurve& c : curves) {
    double bottom = INFINITY;
    for (double d : c.depth_mm) {
      if (!std::isfinite(d) || d <= 0.0) continue;
      bottom = std::min(bottom, d);
      largest = std::max(largest, d);
    }
    if (!std::isfinite(bottom)) continue;
    smallest = std::min(smallest, bottom);
    largest_bottom = std::max(largest_bottom, bottom);
  }
  if (!std::isfinite(smallest)) return NAN;
  const double clip_mm = std::max(5.0 * smallest, 1.5 * largest_bottom);
  return largest > 1.05 * clip_mm ? clip_mm : NAN;
}

void SaveLobesPlot(const std::string& path, const std::string& title, const std::string& subtitle,
                   const std::vector<LobeCurve>& curves, const std::string& csv_name, const std::string& band_note) {
  int banded = 0;
  for (const LobeCurve& c : curves) banded += c.lower_mm.empty() ? 0 : 1;
  // Two translucent bands that overlap mix into a third colour (brown from
  // vermillion and pink): only a single band is shaded.
  const bool shade = banded == 1;
  Series band_key;  // the bands' legend entry, in grey: it belongs to no posture
  Figure fig(1, 1, 1000, 560);
  fig.title = title;
  Axes& ax = fig.at(0, 0);
  ax.title = subtitle;
  ax.x_label = "spindle speed [rpm]";
  ax.y_label = "critical axial depth [mm]";
  ax.y_min = 0.0;
  int color = 0;
  for (const LobeCurve& c : curves) {
    Series s;
    s.x = c.speed_rpm;
    s.y = c.depth_mm;
    s.label = c.label;
    s.color = PaletteColor(color++);
    s.markers = c.markers;
    const Rgb color = s.color;
    ax.series.push_back(std::move(s));
    if (!c.lower_mm.empty()) {
      // The band (no legend entry of its own), then its lower end dashed:
      // the safe depth.
      if (shade) {
        Series band;
        band.x = c.speed_rpm;
        band.y = c.upper_mm;
        band.y_fill_to = c.lower_mm;
        band.color = color;
        band.thickness = 1;
        ax.series.insert(ax.series.end() - 1, std::move(band));
      }
      Series safe;
      safe.x = c.speed_rpm;
      safe.y = c.lower_mm;
      if (band_key.label.empty()) {
        const std::string what = band_note.empty() ? std::string() : " (" + band_note + ")";
        band_key.label = shade ? "shaded: interval" + what + "; dashed: safe depth"
                               : "dashed: safe depth, the lower bound" + what;
        band_key.color = Rgb{110, 110, 110};
        band_key.dashed = true;
        band_key.thickness = 1;
        // One point on the first finite lower bound: listed, drawn over a
        // dash already there.
        for (size_t i = 0; i < c.lower_mm.size() && band_key.x.empty(); ++i) {
          if (std::isfinite(c.lower_mm[i]) && i < c.speed_rpm.size()) {
            band_key.x = {c.speed_rpm[i], c.speed_rpm[i]};
            band_key.y = {c.lower_mm[i], c.lower_mm[i]};
          }
        }
      }
      safe.color = color;
      safe.dashed = true;
      safe.thickness = 1;
      ax.series.push_back(std::move(safe));
    }
  }
  if (!band_key.label.empty()) ax.series.push_back(std::move(band_key));
  double clip_mm = LobesDepthAxisClipMm(curves);
  if (!std::isfinite(clip_mm) && banded > 0) {
    // A band's upper edge can rise far above its lobes (47 mm over lobes of
    // 1.7 - 6 mm): the axis ends at 1.5 times the curves' largest depth.
    double largest = 0.0, upper = 0.0;
    for (const LobeCurve& c : curves) {
      for (double d : c.depth_mm) {
        if (std::isfinite(d)) largest = std::max(largest, d);
      }
      for (double d : c.upper_mm) {
        if (std::isfinite(d)) upper = std::max(upper, d);
      }
    }
    if (largest > 0.0 && upper > 1.5 * largest) clip_mm = 1.5 * largest;
  }
  if (std::isfinite(clip_mm)) {
    ax.y_max = clip_mm;
    char clip_text[96];
    std::snprintf(clip_text, sizeof(clip_text), "; depth axis clipped at %.3g mm (full range in ", clip_mm);
    ax.title += clip_text + csv_name + ")";
  }
  fig.SavePng(path);
}

}  // namespace robomach::report
