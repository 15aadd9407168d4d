// polish-plan's and polish-sim's pictures (seed Figs. 18-20): the removal
// map and its histogram, the path with its guide lines in the developed
// plane, the optimiser's convergence. Output writing, so it stays with the
// tools; the numbers drawn are the library's.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "polish_support.h"
#include "robomach/report/heat_map.h"
#include "robomach/report/plot.h"

namespace robomach::apps {

std::vector<std::string> PicturePaths(const std::string& png, bool with_convergence) {
  const std::filesystem::path p(png);
  const std::string stem = (p.parent_path() / p.stem()).string();
  std::vector<std::string> out = {png, stem + "_histogram.png", stem + "_path.png"};
  if (with_convergence) out.push_back(stem + "_convergence.png");
  return out;
}

namespace {

// Removal map (seed Fig. 19) on the developed plane; returns the removal of
// every point of the region [um] for the histogram.
std::vector<double> WriteRemovalMap(const std::string& path, const polishing::SampleGrid& grid,
                                    const std::vector<double>& removal_m, const std::string& title) {
  report::HeatMap map;
  map.title = title + ": removal";
  map.x_label = "s (arc length along u) [mm]";
  map.y_label = "t (arc length along v) [mm]";
  map.colorbar_label = "removal [um]";
  map.nan_label = "margin (not polished)";
  // Block-averaged to at most ~150 cells a side: the drawing costs per cell.
  const int f = std::max(1, static_cast<int>(std::ceil(std::max(grid.ns(), grid.nt()) / 150.0)));
  map.nx = (grid.ns() + f - 1) / f;
  map.ny = (grid.nt() + f - 1) / f;
  const double ds = 1e3 * grid.length_s() / std::max(1, grid.ns() - 1);
  const double dt = 1e3 * grid.length_t() / std::max(1, grid.nt() - 1);
  map.dx = ds * f;
  map.dy = dt * f;
  map.x0 = 0.5 * (f - 1) * ds;
  map.y0 = 0.5 * (f - 1) * dt;
  std::vector<double> sum(map.nx * map.ny, 0.0), cnt(map.nx * map.ny, 0.0);
  std::vector<double> region;
  for (int j = 0; j < grid.nt(); ++j) {
    for (int i = 0; i < grid.ns(); ++i) {
      const int k = grid.index(i, j);
      if (!grid.in_region()[k]) continue;
      const int c = (j / f) * map.nx + i / f;
      sum[c] += 1e6 * removal_m[k];
      cnt[c] += 1.0;
      region.push_back(1e6 * removal_m[k]);
    }
  }
  map.values.assign(map.nx * map.ny, std::nan(""));
  for (size_t c = 0; c < sum.size(); ++c)
    if (cnt[c] > 0) map.values[c] = sum[c] / cnt[c];
  if (f > 1) map.title += " (" + std::to_string(f) + " x " + std::to_string(f) + " point averages)";
  report::SaveHeatMapPng(map, path);
  return region;
}

// Histogram of the removal (seed Fig. 20).
void WriteHistogram(const std::string& path, const std::vector<double>& region, const std::string& title) {
  report::Figure hist(1, 1, 900, 420);
  hist.title = title + ": removal histogram";
  auto& ax = hist.at(0, 0);
  ax.x_label = "removal [um]";
  ax.y_label = "fraction of sample points [%]";
  if (!region.empty()) {
    const double lo = *std::min_element(region.begin(), region.end());
    const double hi = *std::max_element(region.begin(), region.end());
    const int bins = 40;
    const double w = (hi - lo) > 0 ? (hi - lo) / bins : 1.0;
    std::vector<double> count(bins, 0.0);
    for (double x : region) count[std::min(bins - 1, static_cast<int>((x - lo) / w))] += 100.0 / region.size();
    report::Series s;
    s.color = report::PaletteColor(0);
    for (int b = 0; b < bins; ++b) {  // bars as outlines
      s.x.insert(s.x.end(), {lo + b * w, lo + b * w, lo + (b + 1) * w, lo + (b + 1) * w});
      s.y.insert(s.y.end(), {0.0, count[b], count[b], 0.0});
    }
    ax.series.push_back(s);
    ax.y_min = 0.0;
  }
  hist.SavePng(path);
}

// Path with guide lines (seed Fig. 18) in the developed plane, as the
// removal map: an x-y view says little about a steep or wrapped face.
void WritePathPicture(const std::string& path, const polishing::SampleGrid& grid,
                      const std::vector<polishing::PathRow>& rows,
                      const std::vector<std::vector<Eigen::Vector2d>>& guide_lines_st, const std::string& title) {
  report::Figure fp(1, 1, 900, 700);
  fp.title = title + ": path (developed plane)";
  auto& a2 = fp.at(0, 0);
  a2.x_label = "s (arc length along u) [mm]";
  a2.y_label = "t (arc length along v) [mm]";
  auto s_mm = [&](const polishing::PathRow& r) { return 1e3 * grid.SOfU(r.u); };
  auto t_mm = [&](const polishing::PathRow& r) { return 1e3 * grid.TOfV(r.v); };
  // One series per stretch in contact (blue) or lifted (rows with force 0,
  // thin grey dashes); a segment belongs to the stretch of its first row.
  bool labelled[2] = {false, false};
  for (size_t i = 0; i < rows.size();) {
    const bool lifted = rows[i].force == 0.0;
    report::Series s;
    size_t j = i;
    while (j < rows.size() && (rows[j].force == 0.0) == lifted) {
      s.x.push_back(s_mm(rows[j]));
      s.y.push_back(t_mm(rows[j]));
      ++j;
    }
    if (lifted && j < rows.size()) {  // the lifted move ends where the tool sets down
      s.x.push_back(s_mm(rows[j]));
      s.y.push_back(t_mm(rows[j]));
    }
    if (lifted && s.x.size() > 2) {
      // A lift is straight in the developed plane: its ends draw it, and the
      // dashes stay visible (rows every 0.5 mm would draw it solid).
      s.x = {s.x.front(), s.x.back()};
      s.y = {s.y.front(), s.y.back()};
    }
    if (s.x.size() >= 2) {
      s.label = labelled[lifted] ? "" : (lifted ? "lifted" : "contact path");
      s.color = lifted ? report::Rgb{150, 150, 150} : report::PaletteColor(0);
      s.thickness = 1;
      s.dashed = lifted;
      labelled[lifted] = true;
      a2.series.push_back(s);
    }
    i = j;
  }
  for (size_t g = 0; g < guide_lines_st.size(); ++g) {
    report::Series s;
    s.label = g == 0 ? "guide lines" : "";
    s.color = report::PaletteColor(1);
    s.dashed = true;
    for (const auto& p : guide_lines_st[g]) {
      s.x.push_back(1e3 * p.x());
      s.y.push_back(1e3 * p.y());
    }
    a2.series.push_back(s);
  }
  fp.SavePng(path);
}

// The optimiser's convergence: the best so far per iteration, and the cv of
// each feasible evaluation.
void WriteConvergence(const std::string& path, const std::vector<double>& history,
                      const std::vector<double>& evaluated, const std::string& title) {
  report::Figure fc(1, 1, 900, 420);
  fc.title = title + ": optimiser convergence";
  auto& a3 = fc.at(0, 0);
  a3.x_label = "iteration / evaluation";
  a3.y_label = "cv of removal";
  a3.log_y = true;  // the best is 10-100 x below the first and the worst evaluations
  if (!evaluated.empty()) {
    report::Series e;
    e.color = report::PaletteColor(0);
    e.markers = true;
    e.label = "cv of each feasible evaluation";
    for (size_t i = 0; i < evaluated.size(); ++i) {
      if (!std::isfinite(evaluated[i])) continue;
      e.x.push_back(static_cast<double>(i + 1));
      e.y.push_back(evaluated[i]);
    }
    a3.series.push_back(e);
  }
  report::Series s;
  s.color = report::PaletteColor(2);
  s.label = evaluated.empty() ? "" : "best so far";
  for (size_t i = 0; i < history.size(); ++i) {
    if (!std::isfinite(history[i])) continue;  // before the first feasible evaluation
    s.x.push_back(static_cast<double>(i + 1));
    s.y.push_back(history[i]);
  }
  a3.series.push_back(s);
  fc.SavePng(path);
}

}  // namespace

std::vector<std::string> WritePictures(const std::string& png, const polishing::SampleGrid& grid,
                                       const std::vector<double>& removal_m,
                                       const std::vector<polishing::PathRow>& rows,
                                       const std::vector<std::vector<Eigen::Vector2d>>& guide_lines_st,
                                       const std::vector<double>& history, const std::string& title,
                                       const std::vector<double>& evaluated) {
  const std::vector<std::string> files = PicturePaths(png, !history.empty());
  WriteHistogram(files[1], WriteRemovalMap(files[0], grid, removal_m, title), title);
  WritePathPicture(files[2], grid, rows, guide_lines_st, title);
  if (!history.empty()) WriteConvergence(files[3], history, evaluated, title);
  return files;
}

}  // namespace robomach::apps
