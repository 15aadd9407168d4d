#include "robomach/report/residual_plot.h"

#include <algorithm>

#include "robomach/report/plot.h"

namespace robomach::report {

void SaveCaseResidualFigure(const std::string& path, const std::string& title, const CaseResidualsMm& r) {
  Figure fig(1, 2, 640, 420);
  fig.title = title;
  Axes& a = fig.at(0, 0);
  a.title = "residual per load case";
  a.x_label = "case (file order)";
  a.y_label = "|measured - predicted| [mm]";
  Series in, out, noise, thr;
  in.label = "cases";
  in.markers = true;
  in.color = PaletteColor(0);
  out.label = "outliers";
  out.markers = true;
  out.color = PaletteColor(1);
  for (size_t c = 0; c < r.norm_mm.size(); ++c) {
    Series& s = r.outlier[c] ? out : in;
    s.x.push_back(static_cast<double>(c + 1));
    s.y.push_back(r.norm_mm[c]);
  }
  const double n = static_cast<double>(r.norm_mm.size());
  // E|r| for 3 Gaussian components of σ is σ·2√(2/π) ≈ 1.6 σ.
  noise.x = {1.0, n};
  noise.y = {1.596 * r.noise_sigma_mm, 1.596 * r.noise_sigma_mm};
  noise.label = "expected from tracker noise";
  noise.dashed = true;
  noise.color = PaletteColor(2);
  thr.x = {1.0, n};
  thr.y = {r.threshold_mm, r.threshold_mm};
  thr.label = "outlier threshold";
  thr.dashed = true;
  thr.color = PaletteColor(1);
  a.series = {in, noise, thr};
  if (!out.x.empty()) a.series.push_back(out);

  Axes& b = fig.at(0, 1);
  b.title = "displacement components";
  b.x_label = "predicted [mm]";
  b.y_label = "measured [mm]";
  Series pts, diag;
  pts.markers = true;
  pts.label = "x, y, z of every case";
  pts.color = PaletteColor(0);
  double lo = 0.0, hi = 0.0;
  for (size_t c = 0; c < r.predicted_mm.size(); ++c) {
    for (int k = 0; k < 3; ++k) {
      pts.x.push_back(r.predicted_mm[c](k));
      pts.y.push_back(r.measured_mm[c](k));
      lo = std::min({lo, pts.x.back(), pts.y.back()});
      hi = std::max({hi, pts.x.back(), pts.y.back()});
    }
  }
  diag.x = {lo, hi};
  diag.y = {lo, hi};
  diag.label = "measured = predicted";
  diag.dashed = true;
  diag.color = PaletteColor(2);
  b.series = {diag, pts};
  fig.SavePng(path);
}

}  // namespace robomach::report
