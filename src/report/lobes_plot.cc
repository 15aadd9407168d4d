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
  const bool shade = banded <= 2;
  bool labelled = false;
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
      if (!labelled) {
        const std::string what = band_note.empty() ? std::string() : " (" + band_note + ")";
        safe.label = shade ? "shaded: interval" + what + "; dashed: safe depth"
                           : "dashed: safe depth, the lower bound" + what;
        labelled = true;
      }
      safe.color = color;
      safe.dashed = true;
      safe.thickness = 1;
      ax.series.push_back(std::move(safe));
    }
  }
  const double clip_mm = LobesDepthAxisClipMm(curves);
  if (std::isfinite(clip_mm)) {
    ax.y_max = clip_mm;
    char clip_text[96];
    std::snprintf(clip_text, sizeof(clip_text), "; depth axis clipped at %.3g mm (full range in ", clip_mm);
    ax.title += clip_text + csv_name + ")";
  }
  fig.SavePng(path);
}

}  // namespace robomach::report
