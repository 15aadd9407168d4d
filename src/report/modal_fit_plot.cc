#include "robomach/report/modal_fit_plot.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <vector>

#include "robomach/common/frames.h"
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
  std::vector<double> modes, strength;
  for (const calibration::FittedMode& m : fit.modes) {
    modes.push_back(m.freq_hz);
    strength.push_back(m.peak_contribution);
  }
  FillFrfPanels(curves, modes, title, mag, phase, strength);
  // The magnitude axis goes down to 1e-3 x the smallest measured |H| (three
  // decades below the data are room for the antiresonances and the floor
  // where it matters); a floor of, say, 1e-16 m/N under data of 1e-6 m/N
  // would otherwise squash the FRF into the top third of the panel. What
  // lies lower is cut off at the axis.
  double h_min = std::numeric_limits<double>::infinity(), lowest = h_min;
  for (int k = 0; k < n; ++k) {
    const double h = std::abs(measured.receptance()(lines[k]));
    if (std::isfinite(h) && h > 0.0) h_min = std::min(h_min, h);
  }
  for (const Series& s : mag->series) {
    for (double v : s.y) {
      if (std::isfinite(v) && v > 0.0) lowest = std::min(lowest, v);
    }
  }
  if (std::isfinite(h_min) && lowest < 1e-3 * h_min) mag->y_min = 1e-3 * h_min;
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
      // The band's edges keep their labels before any mode's.
      constexpr double kFirst = std::numeric_limits<double>::infinity();
      if (lo > f_first) ax->markers.push_back({lo, label && b == 0 ? a : "", PaletteColor(2), kFirst});
      if (hi < f_last) {
        ax->markers.push_back({hi, label && b + 1 == noise.usable_bands.size() ? c : "", PaletteColor(2), kFirst});
      }
    }
  }
}

}  // namespace robomach::report

namespace robomach::report {

void FillStabilisationPanel(const std::vector<calibration::StabilisationPole>& poles,
                            const std::vector<double>& mode_freq_hz, double fmin_hz, double fmax_hz, Axes* ax,
                            const std::vector<double>& mode_strength) {
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
  for (size_t k = 0; k < mode_freq_hz.size(); ++k) {
    char l[32];
    std::snprintf(l, sizeof(l), "%.1f Hz", mode_freq_hz[k]);
    VerticalMarker m{mode_freq_hz[k], l};
    if (k < mode_strength.size() && std::isfinite(mode_strength[k])) m.priority = mode_strength[k];
    ax->markers.push_back(m);
  }
}

namespace {

constexpr size_t kMaxFrfsDrawn = 4;

// The FRFs of a fit that are drawn: all up to kMaxFrfsDrawn; of a larger
// (roving) test the driving point and then the worst fits in units of the
// noise (the ones a user must look at).
std::vector<size_t> FrfsDrawn(const calibration::ModalGroup& g) {
  std::vector<size_t> all(g.keys.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  if (all.size() <= kMaxFrfsDrawn) return all;
  auto badness = [&](size_t i) {
    const double ns = i < g.fit.misfit_in_noise.size() ? g.fit.misfit_in_noise[i] : NAN;
    if (std::isfinite(ns)) return ns;
    return i < g.misfit.size() && std::isfinite(g.misfit[i]) ? g.misfit[i] : 0.0;
  };
  std::vector<size_t> out;
  for (size_t i : all) {
    if (g.keys[i].IsDrivingPoint()) {
      out.push_back(i);
      break;
    }
  }
  std::vector<size_t> rest;
  for (size_t i : all) {
    if (out.empty() || i != out[0]) rest.push_back(i);
  }
  std::stable_sort(rest.begin(), rest.end(), [&](size_t a, size_t b) { return badness(a) > badness(b); });
  for (size_t i : rest) {
    if (out.size() == kMaxFrfsDrawn) break;
    out.push_back(i);
  }
  return out;
}

}  // namespace

void WriteModalAnalysisPng(const std::string& path, const calibration::PoseModes& pose,
                           const dynamics::FrfSet& measured, const calibration::NoiseModels& noise) {
  int rows = 0;
  for (const calibration::ModalGroup& g : pose.groups) {
    rows += 1 + 2 * static_cast<int>(FrfsDrawn(g).size());
    if (g.fit.status == SolverStatus::kConverged && calibration::ShapesOfRovingTest(g)) ++rows;
  }
  Figure fig(std::max(1, rows), 1, 1000, 320);
  fig.title = "robomach frf-modes: posture " + pose.pose_id;
  int row = 0;
  for (const calibration::ModalGroup& g : pose.groups) {
    Axes& ax = fig.at(row++, 0);
    std::string which;
    if (g.keys.size() <= kMaxFrfsDrawn) {
      for (const auto& k : g.keys) which += (which.empty() ? "" : ", ") + k.Label();
    } else {
      which = std::to_string(g.keys.size()) + " FRFs (" + g.keys.front().Label() + " .. " + g.keys.back().Label() +
              "; drawn below: the driving point and the worst fits)";
    }
    char head[240];
    std::snprintf(head, sizeof(head), "stabilisation diagram of %s: %zu modes, orders %d..%d", which.c_str(),
                  g.fit.modes.size(), g.fit.min_order, g.fit.max_order);
    ax.title = head;
    // A mode's strength: its largest peak receptance over the FRFs fitted
    // (the labels of the strongest are kept where not all fit).
    std::vector<double> modes, strength;
    for (size_t r = 0; r < g.fit.modes.size(); ++r) {
      modes.push_back(g.fit.modes[r].freq_hz);
      double s = 0.0;
      for (const calibration::ModalFitResult& f : g.fit.per_frf) {
        if (r < f.modes.size() && std::isfinite(f.modes[r].peak_contribution)) s = std::max(s, f.modes[r].peak_contribution);
      }
      strength.push_back(s);
    }
    FillStabilisationPanel(g.fit.stabilisation, modes, g.fit.fmin_hz, g.fit.fmax_hz, &ax, strength);
    if (g.fit.status == SolverStatus::kConverged) {
      if (const auto rs = calibration::ShapesOfRovingTest(g)) {
        // The shapes over the roving points: the component in phase with
        // the mode's largest, scaled so that the largest is 1.
        Axes& sx = fig.at(row++, 0);
        sx.title = std::string("mode shapes over the ") + (rs->roving == "excitation" ? "hammer" : "sensor") +
                   " points (real part, largest 1; fixed " + (rs->roving == "excitation" ? "sensor" : "hammer") +
                   " at point " + std::to_string(rs->fixed_point) + AxisName(rs->fixed_direction) + ")";
        sx.x_label = "point";
        sx.y_label = "shape";
        std::vector<size_t> order(rs->points.size());
        for (size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return rs->points[a] < rs->points[b]; });
        for (int r = 0; r < rs->shapes.cols(); ++r) {
          int imax = 0;
          rs->shapes.col(r).cwiseAbs().maxCoeff(&imax);
          const std::complex<double> pivot = rs->shapes(imax, r);
          Series se;
          char lab[64];
          std::snprintf(lab, sizeof(lab), "%.4g Hz", g.fit.modes[r].freq_hz);
          se.label = lab;
          se.color = PaletteColor(r);
          for (size_t i : order) {
            se.x.push_back(rs->points[i]);
            se.y.push_back(std::abs(pivot) > 0.0 ? (rs->shapes(i, r) / pivot).real() : 0.0);
          }
          sx.series.push_back(se);
          Series dots = se;
          dots.label.clear();
          dots.markers = true;
          sx.series.push_back(dots);
        }
      }
    }
    const std::vector<size_t> drawn = FrfsDrawn(g);
    for (size_t n = 0; n < drawn.size(); ++n) {
      const size_t i = drawn[n];
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
      char title[300];
      const double noise_units = i < g.fit.misfit_in_noise.size() ? g.fit.misfit_in_noise[i] : NAN;
      const double rel = i < g.misfit.size() ? g.misfit[i] : NAN;
      std::string label = g.keys[i].Label();
      if (g.keys[i].IsDrivingPoint() && (g.keys[i].response_point != 0 || drawn.size() < g.keys.size())) {
        label += " (driving point)";
      }
      if (std::isfinite(noise_units)) {
        std::snprintf(title, sizeof(title), "%s: %zu modes, misfit %.3g (%.2f x the noise)", label.c_str(),
                      fit.modes.size(), rel, noise_units);
      } else {
        std::snprintf(title, sizeof(title), "%s: %zu modes, misfit %.3g", label.c_str(), fit.modes.size(), rel);
      }
      FillModalFitPanels(frf, nz, fit, title, &fig.at(row, 0), &fig.at(row + 1, 0));
      row += 2;
    }
  }
  fig.SavePng(path);
}

}  // namespace robomach::report
