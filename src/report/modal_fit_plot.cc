#include "robomach/report/modal_fit_plot.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include "robomach/report/frf_plot.h"

namespace robomach::report {

void FillModalFitPanels(const dynamics::Frf& measured, const calibration::FrfNoise& noise,
                        const calibration::ModalFitResult& fit, const std::string& title, Axes* mag, Axes* phase) {
  // Lines at 0 Hz have no place on a log axis and no phase.
  std::vector<int> lines;
  for (int i = 0; i < measured.size(); ++i) {
    if (measured.freq_hz()(i) > 0.0) lines.push_back(i);
  }
  const int n = static_cast<int>(lines.size());
  Eigen::VectorXd f(n);
  Eigen::VectorXcd used(n), left_out(n), model(n), floor(n);
  const std::complex<double> gap(NAN, NAN);  // breaks a line
  for (int k = 0; k < n; ++k) {
    const int i = lines[k];
    f(k) = measured.freq_hz()(i);
    const bool u = noise.usable.at(i);
    used(k) = u ? measured.receptance()(i) : gap;
    // Each curve keeps its neighbouring line so that the two meet.
    const bool next_to_unusable =
        (i > 0 && !noise.usable[i - 1]) || (i + 1 < measured.size() && !noise.usable[i + 1]);
    left_out(k) = !u || next_to_unusable ? measured.receptance()(i) : gap;
    model(k) = fit.modes.empty() ? gap : fit.Evaluate(f(k));
    floor(k) = noise.floor_m_per_N(i);
  }
  std::vector<FrfCurve> curves;
  // The model wide and underneath, the measured lines thin on top, so
  // that both stay visible where they agree.
  curves.push_back({f, left_out, "measured, not used (below the SNR limit)", Rgb{185, 185, 185}, false, 1});
  if (!fit.modes.empty()) {
    char label[96];
    std::snprintf(label, sizeof(label), "modal fit (%zu modes)", fit.modes.size());
    curves.push_back({f, model, label, PaletteColor(1), false, 5});
  }
  curves.push_back({f, used, "measured, usable (fitted)", PaletteColor(0), false, 1});
  FrfCurve fl{f, floor, "noise floor", PaletteColor(3), true, 1};
  fl.magnitude_only = true;
  curves.push_back(fl);
  std::vector<double> modes;
  for (const calibration::FittedMode& m : fit.modes) modes.push_back(m.freq_hz);
  FillFrfPanels(curves, modes, title, mag, phase);
  // The edges of the usable stretches; only the outer two are labelled,
  // and an edge at the end of the FRF is not marked.
  const double f_first = n > 0 ? f(0) : 0.0, f_last = n > 0 ? f(n - 1) : 0.0;
  for (size_t b = 0; b < noise.usable_bands.size(); ++b) {
    const auto [lo, hi] = noise.usable_bands[b];
    char a[48], c[48];
    std::snprintf(a, sizeof(a), "usable from %.4g Hz", lo);
    std::snprintf(c, sizeof(c), "usable to %.4g Hz", hi);
    for (Axes* ax : {mag, phase}) {
      const bool label = ax == mag;
      if (lo > f_first) ax->markers.push_back({lo, label && b == 0 ? a : "", PaletteColor(2)});
      if (hi < f_last) {
        ax->markers.push_back({hi, label && b + 1 == noise.usable_bands.size() ? c : "", PaletteColor(2)});
      }
    }
  }
}

}  // namespace robomach::report

namespace robomach::report {

void FillStabilisationPanel(const std::vector<calibration::StabilisationPole>& poles,
                            const std::vector<double>& mode_freq_hz, double fmin_hz, double fmax_hz, Axes* ax) {
  ax->x_label = "frequency [Hz]";
  ax->y_label = "model order";
  ax->log_x = fmin_hz > 0.0 && fmax_hz / fmin_hz > 100.0;
  ax->x_min = ax->log_x ? fmin_hz : 0.0;
  ax->x_max = fmax_hz > 0.0 ? fmax_hz : NAN;
  Series unstable, stable;
  unstable.markers = stable.markers = true;
  unstable.label = "pole";
  stable.label = "stable pole";
  unstable.color = {180, 180, 180};
  stable.color = PaletteColor(2);
  for (const auto& p : poles) {
    Series& s = p.stable ? stable : unstable;
    s.x.push_back(p.freq_hz);
    s.y.push_back(p.order);
  }
  ax->series.push_back(std::move(unstable));
  ax->series.push_back(std::move(stable));
  for (double f : mode_freq_hz) {
    char l[32];
    std::snprintf(l, sizeof(l), "%.1f Hz", f);
    ax->markers.push_back({f, l});
  }
}

void WriteModalAnalysisPng(const std::string& path, const calibration::PoseModes& pose,
                           const dynamics::FrfSet& measured, const calibration::NoiseModels& noise) {
  int frf_rows = 0;
  for (const calibration::ModalGroup& g : pose.groups) frf_rows += 2 * static_cast<int>(g.keys.size());
  const int rows = static_cast<int>(pose.groups.size()) + frf_rows;
  Figure fig(std::max(1, rows), 1, 1000, 320);
  fig.title = "robomach frf-modes: posture " + pose.pose_id;
  int row = 0;
  for (const calibration::ModalGroup& g : pose.groups) {
    Axes& ax = fig.at(row++, 0);
    std::string which;
    for (const auto& k : g.keys) which += std::string(which.empty() ? "H" : ", H") + AxisName(k.response) + AxisName(k.excitation);
    char head[200];
    std::snprintf(head, sizeof(head), "stabilisation diagram of %s: %zu modes, orders %d..%d", which.c_str(),
                  g.fit.modes.size(), g.fit.min_order, g.fit.max_order);
    ax.title = head;
    std::vector<double> modes;
    for (const auto& m : g.fit.modes) modes.push_back(m.freq_hz);
    FillStabilisationPanel(g.fit.stabilisation, modes, g.fit.fmin_hz, g.fit.fmax_hz, &ax);
    for (size_t i = 0; i < g.keys.size(); ++i) {
      const dynamics::Frf& frf = measured.at(g.keys[i]);
      calibration::FrfNoise nz;
      const auto it = noise.find(g.keys[i]);
      if (it != noise.end()) {
        nz = it->second;
      } else {
        nz.usable.assign(frf.size(), 1);
        nz.floor_m_per_N = Eigen::VectorXd::Constant(frf.size(), NAN);
      }
      calibration::ModalFitResult fit;
      if (i < g.fit.per_frf.size()) fit = g.fit.per_frf[i];
      char title[240];
      const double noise_units = i < g.fit.misfit_in_noise.size() ? g.fit.misfit_in_noise[i] : NAN;
      const double rel = i < g.misfit.size() ? g.misfit[i] : NAN;
      if (std::isfinite(noise_units)) {
        std::snprintf(title, sizeof(title), "H%c%c: %zu modes, misfit %.3g (%.2f x the noise)",
                      AxisName(g.keys[i].response), AxisName(g.keys[i].excitation), fit.modes.size(), rel,
                      noise_units);
      } else {
        std::snprintf(title, sizeof(title), "H%c%c: %zu modes, misfit %.3g", AxisName(g.keys[i].response),
                      AxisName(g.keys[i].excitation), fit.modes.size(), rel);
      }
      FillModalFitPanels(frf, nz, fit, title, &fig.at(row, 0), &fig.at(row + 1, 0));
      row += 2;
    }
  }
  fig.SavePng(path);
}

}  // namespace robomach::report
