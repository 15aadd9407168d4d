#include "robomach/report/frf_plot.h"

#include <cmath>
#include <cstdio>

#include "robomach/common/units.h"

namespace robomach::report {

void FillFrfPanels(const std::vector<FrfCurve>& curves, const std::vector<double>& mode_freq_hz,
                   const std::string& title, Axes* mag, Axes* phase, const std::vector<double>& mode_strength) {
  double fmin = INFINITY, fmax = 0.0;
  for (const auto& c : curves) {
    for (Eigen::Index i = 0; i < c.freq_hz.size(); ++i) {
      if (c.freq_hz(i) > 0) fmin = std::min(fmin, c.freq_hz(i));
      fmax = std::max(fmax, c.freq_hz(i));
    }
  }
  const bool log_x = std::isfinite(fmin) && fmax / fmin > 100.0;
  mag->title = title;
  mag->x_label = "frequency [Hz]";
  mag->y_label = "|H| [m/N]";
  mag->log_y = true;
  mag->log_x = log_x;
  // Low frequencies are flat (static compliance) and leave the lower left
  // corner free; the mode labels use the top of the panel.
  mag->legend = Axes::LegendPosition::kBottomLeft;
  phase->x_label = "frequency [Hz]";
  phase->y_label = "phase [deg]";
  phase->log_x = log_x;
  phase->y_min = -180.0;
  phase->y_max = 180.0;
  phase->y_ticks = {-180, -90, 0, 90, 180};
  for (const auto& c : curves) {
    if (c.band_freq_hz.size() > 0) {
      Series band;  // no legend entry: the curve's own colour says whose
      band.x.assign(c.band_freq_hz.data(), c.band_freq_hz.data() + c.band_freq_hz.size());
      band.y.assign(c.band_upper.data(), c.band_upper.data() + c.band_upper.size());
      band.y_fill_to.assign(c.band_lower.data(), c.band_lower.data() + c.band_lower.size());
      band.color = c.color;
      mag->series.push_back(std::move(band));
    }
  }
  for (const auto& c : curves) {
    Series m, p;
    m.label = c.label;
    m.color = p.color = c.color;
    m.dashed = p.dashed = c.dashed;
    m.thickness = p.thickness = c.thickness;
    for (Eigen::Index i = 0; i < c.freq_hz.size(); ++i) {
      m.x.push_back(c.freq_hz(i));
      p.x.push_back(c.freq_hz(i));
      m.y.push_back(std::abs(c.receptance(i)));
      p.y.push_back(RadToDeg(std::arg(c.receptance(i))));
    }
    // Break the phase line where it wraps, instead of drawing a vertical jump.
    for (size_t i = 1; i < p.y.size(); ++i) {
      if (std::abs(p.y[i] - p.y[i - 1]) > 180.0) p.y[i - 1] = NAN;
    }
    mag->series.push_back(std::move(m));
    if (!c.magnitude_only) phase->series.push_back(std::move(p));
  }
  for (size_t k = 0; k < mode_freq_hz.size(); ++k) {
    if (!(mode_freq_hz[k] > 0.0) || (fmax > 0 && mode_freq_hz[k] > fmax)) continue;
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.1f Hz", mode_freq_hz[k]);
    VerticalMarker marker{mode_freq_hz[k], buf};
    if (k < mode_strength.size() && std::isfinite(mode_strength[k])) marker.priority = mode_strength[k];
    mag->markers.push_back(marker);
    phase->markers.push_back({mode_freq_hz[k], ""});
  }
  if (std::isfinite(fmin)) {
    mag->x_min = phase->x_min = log_x ? fmin : 0.0;
    mag->x_max = phase->x_max = fmax;
  }
}

}  // namespace robomach::report
