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
  curves.push_back({f, left_out, "measured, not used (below the SNR limit)", Rgb{185, 185, 185}, false, 1});
  curves.push_back({f, used, "measured, usable (fitted)", PaletteColor(0), false, 2});
  if (!fit.modes.empty()) {
    char label[96];
    std::snprintf(label, sizeof(label), "modal fit (%zu modes)", fit.modes.size());
    curves.push_back({f, model, label, PaletteColor(1), true, 2});
  }
  FrfCurve fl{f, floor, "noise floor", PaletteColor(3), true, 1};
  fl.magnitude_only = true;
  curves.push_back(fl);
  std::vector<double> modes;
  for (const calibration::FittedMode& m : fit.modes) modes.push_back(m.freq_hz);
  FillFrfPanels(curves, modes, title, mag, phase);
  for (const auto& [lo, hi] : noise.usable_bands) {
    char a[48], b[48];
    std::snprintf(a, sizeof(a), "usable from %.4g Hz", lo);
    std::snprintf(b, sizeof(b), "usable to %.4g Hz", hi);
    for (Axes* ax : {mag, phase}) {
      ax->markers.push_back({lo, ax == mag ? a : "", PaletteColor(2)});
      ax->markers.push_back({hi, ax == mag ? b : "", PaletteColor(2)});
    }
  }
}

}  // namespace robomach::report
