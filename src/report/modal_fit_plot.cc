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
