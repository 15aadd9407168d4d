#include "robomach/report/audit_patterns_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "robomach/common/units.h"
#include "robomach/io/number_format.h"
#include "robomach/report/heat_map.h"
#include "robomach/report/html.h"
#include "robomach/report/plot.h"

namespace robomach::report {
namespace {

using nlohmann::json;

std::string Fixed(double v, int digits) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

json JsonNumber(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::string Dir(const dynamics::FrfKey& k) { return std::string(1, AxisName(k.response)) + AxisName(k.excitation); }

// A descriptor as shown: joint angles in degrees, the rest in SI.
struct Shown {
  std::string name;
  std::string unit;
  double scale{1.0};
  std::string key() const { return name + "_" + unit; }
};

Shown Display(const std::string& name, const std::string& unit) {
  if (unit == "rad") return {name, "deg", RadToDeg(1.0)};
  return {name, unit, 1.0};
}

// The descriptors trends.png draws (issue #35: ten panels of the same
// errors against q1 … gravity_torque_j3 looked alike and told nothing):
// those whose correlation is defined (the value varies over the postures),
// strongest first by the larger of |r| before and after, significant ones
// before the others, at most kMaxTrendPanels. The table in index.html and
// trends.csv keep every descriptor.
constexpr size_t kMaxTrendPanels = 4;

std::vector<size_t> TrendsToDraw(const audit::ErrorTrends& t) {
  std::vector<size_t> idx;
  for (size_t i = 0; i < t.trends.size(); ++i) {
    if (std::isfinite(t.trends[i].correlation_before)) idx.push_back(i);
  }
  const auto strength = [&](size_t i) {
    const audit::Trend& tr = t.trends[i];
    double r = std::abs(tr.correlation_before);
    if (std::isfinite(tr.correlation_after)) r = std::max(r, std::abs(tr.correlation_after));
    return r;
  };
  std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) {
    const bool sa = t.trends[a].significant_before || t.trends[a].significant_after;
    const bool sb = t.trends[b].significant_before || t.trends[b].significant_after;
    if (sa != sb) return sa;
    return strength(a) > strength(b);
  });
  if (idx.size() > kMaxTrendPanels) idx.resize(kMaxTrendPanels);
  return idx;
}

// One panel: the error per posture against one descriptor, its
// least-squares line (Pearson's r measures how well that line fits), and the
// noise floor where the errors come near it. The y axis is fitted to these
// errors, not started at 0: a trend of 70 → 75 noise units is what the
// panel is for, and on 0 … 80 it would be a flat row of points.
void TrendPanel(Axes* ax, const std::vector<double>& x, const Eigen::VectorXd& err, double r, bool significant,
                const std::string& title, const std::string& x_label, Rgb colour, double noise_floor) {
  ax->title = title + ": r = " + Fixed(r, 2) + (significant ? " (significant)" : "");
  ax->x_label = x_label;
  ax->y_label = "error per posture [-]";
  Series points, fit, floor;
  points.markers = true;
  points.color = colour;
  points.label = "postures";
  double sx = 0, sy = 0, n = 0, ylo = INFINITY, yhi = -INFINITY, xlo = INFINITY, xhi = -INFINITY;
  for (size_t k = 0; k < x.size(); ++k) {
    const double y = err(static_cast<Eigen::Index>(k));
    if (!std::isfinite(y) || !std::isfinite(x[k])) continue;
    points.x.push_back(x[k]);
    points.y.push_back(y);
    sx += x[k], sy += y, n += 1;
    ylo = std::min(ylo, y), yhi = std::max(yhi, y), xlo = std::min(xlo, x[k]), xhi = std::max(xhi, x[k]);
  }
  if (n >= 2 && xhi > xlo) {
    double sxx = 0, sxy = 0;
    for (size_t k = 0; k < points.x.size(); ++k) {
      sxx += (points.x[k] - sx / n) * (points.x[k] - sx / n);
      sxy += (points.x[k] - sx / n) * (points.y[k] - sy / n);
    }
    const double slope = sxy / sxx, y0 = sy / n - slope * sx / n;
    fit.x = {xlo, xhi};
    fit.y = {y0 + slope * xlo, y0 + slope * xhi};
    fit.color = colour;
    fit.thickness = 1;
    fit.label = "least-squares line";
  }
  if (std::isfinite(xlo)) {
    // A point on the axis's end would be cut in half by the frame.
    const double pad = xhi > xlo ? 0.05 * (xhi - xlo) : std::max(1.0, 0.05 * std::abs(xlo));
    ax->x_min = xlo - pad;
    ax->x_max = xhi + pad;
  }
  ax->series.push_back(std::move(points));
  if (!fit.x.empty()) ax->series.push_back(std::move(fit));
  // The floor is drawn where the errors come within 3 x of it (after a
  // change that explains the failure); far below them it would squeeze
  // the points into one row.
  if (std::isfinite(noise_floor) && std::isfinite(ylo) && ylo < 3.0 * noise_floor) {
    const double pad = xhi > xlo ? 0.05 * (xhi - xlo) : 1.0;
    floor.x = {xlo - pad, xhi + pad};
    floor.y = {noise_floor, noise_floor};
    floor.label = "noise floor";
    floor.color = {120, 120, 120};
    floor.dashed = true;
    floor.thickness = 1;
    ylo = std::min(ylo, noise_floor), yhi = std::max(yhi, noise_floor);
    ax->series.push_back(std::move(floor));
  }
  if (std::isfinite(ylo)) {
    // The spread of the points, at least 2 % of their level (so that
    // equal errors do not blow rounding up to the panel's height), with
    // room above for the legend.
    const double span = std::max(yhi - ylo, 0.02 * std::max(std::abs(yhi), 1e-12));
    ax->y_min = std::max(0.0, ylo - 0.15 * span);
    ax->y_max = yhi + 0.9 * span;
  }
}

std::vector<unsigned char> TrendsPng(const audit::ErrorPatterns& p, const std::vector<size_t>& drawn,
                                     double noise_floor, const std::string& title) {
  const audit::ErrorTrends& t = p.trends;
  const bool has_after = t.error_after.size() > 0;
  const int cols = has_after ? 2 : 1, rows = std::max<int>(1, static_cast<int>(drawn.size()));
  Figure fig(rows, cols, 620, 300);
  fig.title = title;
  if (drawn.empty()) {
    fig.at(0, 0).title = "no descriptor varies over these postures: nothing to draw";
    return fig.EncodePng();
  }
  for (size_t row = 0; row < drawn.size(); ++row) {
    const audit::Trend& tr = t.trends[drawn[row]];
    const Shown s = Display(tr.descriptor, tr.unit);
    std::vector<double> x;
    for (int k = 0; k < t.n; ++k) x.push_back(s.scale * tr.values(k));
    const std::string x_label = s.name + " [" + s.unit + "]";
    TrendPanel(&fig.at(static_cast<int>(row), 0), x, t.error_before, tr.correlation_before, tr.significant_before,
               tr.descriptor + ", current model", x_label, PaletteColor(1), noise_floor);
    if (has_after) {
      TrendPanel(&fig.at(static_cast<int>(row), 1), x, t.error_after, tr.correlation_after, tr.significant_after,
                 tr.descriptor + ", after the best candidate", x_label, PaletteColor(2), noise_floor);
    }
  }
  return fig.EncodePng();
}

std::vector<unsigned char> ModeMapPng(const audit::ModeErrorMap& m, const std::string& title) {
  if (m.modes.empty() || m.pose_ids.empty()) return {};
  auto make = [&](const Eigen::MatrixXd& values, const std::string& what) {
    HeatMap h;
    h.title = title + ": " + what;
    h.x_label = "model mode (ascending frequency)";
    h.y_label = "posture";
    h.colorbar_label = "error [%]";
    h.nan_label = "no match (mode not seen or not matched)";
    h.nx = static_cast<int>(m.modes.size());
    h.ny = static_cast<int>(m.pose_ids.size());
    for (int r = 0; r < h.ny; ++r) {
      for (int c = 0; c < h.nx; ++c) h.values.push_back(100.0 * values(r, c));
    }
    for (int mode : m.modes) h.x_tick_labels.push_back(std::to_string(mode));
    h.y_tick_labels = m.pose_ids;
    h.first_row_at_top = h.annotate = h.symmetric_range = true;
    h.width_px = std::clamp(300 + 90 * h.nx, 760, 1100);
    h.height_px = 150 + std::clamp(40 * h.ny, 160, 600);
    return h;
  };
  return EncodeHeatMapsPng({make(m.freq_error, "natural frequency, 100 (f_model / f_measured - 1)"),
                            make(m.peak_error, "peak amplitude, 100 (|H|_model / |H|_measured - 1)")});
}

// ---- trends: one row per descriptor, its correlation with the error per
// posture before and after the best candidate (trends.csv and the JSON).
void AddTrends(const audit::ErrorTrends& t, AuditPatternsReport* out) {
  const bool has_after = t.error_after.size() > 0;
  out->trends = json::array();
  std::ostringstream tcsv;
  tcsv << "descriptor,unit,n,critical_correlation,correlation_before,significant_before,correlation_after,"
          "significant_after\n";
  for (const audit::Trend& tr : t.trends) {
    const Shown s = Display(tr.descriptor, tr.unit);
    out->trends.push_back({{"descriptor", tr.descriptor},
                           {"unit", s.unit},
                           {"correlation", JsonNumber(tr.correlation_before)},
                           {"significant", tr.significant_before},
                           {"n", t.n},
                           {"critical_correlation", JsonNumber(t.critical_correlation)},
                           {"correlation_after", JsonNumber(tr.correlation_after)},
                           {"significant_after", has_after ? json(tr.significant_after) : json(nullptr)}});
    tcsv << tr.descriptor << ',' << s.unit << ',' << t.n << ',' << FormatCell(t.critical_correlation) << ','
         << FormatCell(tr.correlation_before) << ',' << (tr.significant_before ? "yes" : "no") << ','
         << FormatCell(tr.correlation_after) << ',' << (has_after ? (tr.significant_after ? "yes" : "no") : "") << '\n';
  }
  out->trends_csv = tcsv.str();
}

// ---- per-posture descriptors and errors: the data each trend is computed
// from, one row per posture.
void AddPostureDescriptors(const audit::ErrorTrends& t, AuditPatternsReport* out) {
  const bool has_after = t.error_after.size() > 0;
  std::ostringstream dcsv;
  dcsv << "pose_id,error_before,error_after";
  for (const audit::Trend& tr : t.trends) dcsv << ',' << Display(tr.descriptor, tr.unit).key();
  dcsv << '\n';
  out->posture_descriptors = json::object();
  for (int k = 0; k < t.n; ++k) {
    const std::string& id = t.pose_ids[k];
    dcsv << id << ',' << FormatCell(t.error_before(k)) << ',' << (has_after ? FormatCell(t.error_after(k)) : "");
    json d = json::object();
    for (const audit::Trend& tr : t.trends) {
      const Shown s = Display(tr.descriptor, tr.unit);
      dcsv << ',' << FormatCell(s.scale * tr.values(k));
      d[s.key()] = JsonNumber(s.scale * tr.values(k));
    }
    dcsv << '\n';
    out->posture_descriptors[id] = d;
  }
  out->posture_descriptors_csv = dcsv.str();
}

// ---- mode error map: the relative frequency and peak errors per posture
// and model mode, with the matched pair behind each cell in the CSV.
void AddModeErrorMap(const audit::ModeErrorMap& m, AuditPatternsReport* out) {
  json fe = json::array(), pe = json::array();
  std::ostringstream mcsv;
  mcsv << "pose_id,model_mode,response,excitation,model_freq_hz,measured_freq_hz,freq_error_rel,model_peak_m_per_N,"
          "measured_peak_m_per_N,peak_error_rel\n";
  for (size_t r = 0; r < m.pose_ids.size(); ++r) {
    json fr = json::array(), pr = json::array();
    for (size_t c = 0; c < m.modes.size(); ++c) {
      const auto ri = static_cast<Eigen::Index>(r), ci = static_cast<Eigen::Index>(c);
      fr.push_back(JsonNumber(m.freq_error(ri, ci)));
      pr.push_back(JsonNumber(m.peak_error(ri, ci)));
      mcsv << m.pose_ids[r] << ',' << m.modes[c] << ',';
      const int k = m.match(ri, ci);
      if (k < 0 || k >= static_cast<int>(m.matches.size())) {
        mcsv << ",,,,,,,\n";
        continue;
      }
      const calibration::ModeMatch& mm = m.matches[k];
      mcsv << AxisName(mm.key.response) << ',' << AxisName(mm.key.excitation) << ',' << FormatCell(mm.model_freq_hz) << ','
           << FormatCell(mm.measured_freq_hz) << ',' << FormatCell(mm.freq_error()) << ',' << FormatCell(mm.model_peak) << ','
           << FormatCell(mm.measured_peak) << ',' << FormatCell(mm.peak_error()) << '\n';
    }
    fe.push_back(fr);
    pe.push_back(pr);
  }
  out->mode_error_map = {{"poses", m.pose_ids}, {"modes", m.modes}, {"freq_error_rel", fe}, {"peak_error_rel", pe}};
  out->mode_errors_csv = mcsv.str();
}

// ---- unmatched modes: model modes and measured modes with no counterpart
// (model ones first in the CSV).
void AddUnmatchedModes(const audit::ErrorPatterns& p, AuditPatternsReport* out) {
  out->unmatched_model_modes = json::array();
  out->unmatched_measured_modes = json::array();
  std::ostringstream ucsv;
  ucsv << "side,pose_id,response,excitation,model_mode,freq_hz,damping_ratio,relative_visibility\n";
  for (const audit::UnmatchedMode& u : p.unmatched_model) {
    out->unmatched_model_modes.push_back({{"pose", u.key.pose_id},
                                          {"direction", Dir(u.key)},
                                          {"frequency_hz", u.freq_hz},
                                          {"model_mode", u.model_mode + 1},
                                          {"damping_ratio", u.damping_ratio},
                                          {"relative_visibility", JsonNumber(u.relative_visibility)}});
    ucsv << "model," << u.key.pose_id << ',' << AxisName(u.key.response) << ',' << AxisName(u.key.excitation) << ','
         << u.model_mode + 1 << ',' << FormatCell(u.freq_hz) << ',' << FormatCell(u.damping_ratio) << ','
         << FormatCell(u.relative_visibility) << '\n';
  }
  for (const audit::UnmatchedMode& u : p.unmatched_measured) {
    out->unmatched_measured_modes.push_back({{"pose", u.key.pose_id},
                                             {"direction", Dir(u.key)},
                                             {"frequency_hz", u.freq_hz},
                                             {"damping_ratio", u.damping_ratio},
                                             {"relative_visibility", JsonNumber(u.relative_visibility)}});
    ucsv << "measured," << u.key.pose_id << ',' << AxisName(u.key.response) << ',' << AxisName(u.key.excitation)
         << ",," << FormatCell(u.freq_hz) << ',' << FormatCell(u.damping_ratio) << ',' << FormatCell(u.relative_visibility) << '\n';
  }
  out->unmatched_modes_csv = ucsv.str();
}

// The title of trends.png: which descriptors it draws, n, and the
// significance threshold (or that there are too few postures for one).
std::string TrendsFigureTitle(const audit::ErrorTrends& t, const std::vector<size_t>& drawn, const std::string& title) {
  std::string figure_title = title + ": error per posture against the " +
                             (drawn.size() == 1 ? std::string("most correlated descriptor")
                                                : std::to_string(drawn.size()) + " most correlated descriptors") +
                             " (n = " + std::to_string(t.n);
  if (std::isfinite(t.critical_correlation)) {
    figure_title += "; significant at " + Fixed(100 * t.significance_level, 0) + " %: |r| > " +
                    Fixed(t.critical_correlation, 2) + ")";
  } else {
    figure_title += "; too few postures for a test)";
  }
  return figure_title;
}

// ---- HTML, first section: the correlations, their table and trends.png
// with what it shows.
void WriteTrendsHtml(std::ostringstream& h, const audit::ErrorTrends& t, const AuditPatternsReport& out,
                     const AuditPatternFiles& files) {
  const bool has_after = t.error_after.size() > 0;
  h << "<h2>Error against posture descriptors</h2>\n<p>Pearson correlation r of the rms log-magnitude error per "
       "posture with each posture descriptor over n = "
    << t.n << " postures. ";
  if (std::isfinite(t.critical_correlation)) {
    h << "|r| must exceed " << Fixed(t.critical_correlation, 3) << " to be significant at "
      << Fixed(100 * t.significance_level, 0)
      << " % (two-sided t-test, n − 2 degrees of freedom). With few postures a trend is only indicative: one "
         "posture can make or break it.";
  } else {
    h << "At least 3 postures are needed for a significance test; these correlations mean nothing.";
  }
  if (!t.failing_before) {
    h << " The errors are consistent with the noise floor at every posture: there is no failure whose pattern "
         "could be flagged.";
  }
  if (has_after && !t.failing_after) {
    h << " After the best candidate the errors are at the noise floor everywhere: the correlations after it "
         "describe noise and are never flagged.";
  }
  h << " Data: <a href=\"" << HtmlEscape(files.trends_csv) << "\">" << HtmlEscape(files.trends_csv) << "</a>, <a href=\""
    << HtmlEscape(files.posture_descriptors_csv) << "\">" << HtmlEscape(files.posture_descriptors_csv) << "</a>.</p>\n";
  h << "<table><tr><th>descriptor</th><th>unit</th><th>r before</th>" << (has_after ? "<th>r after</th>" : "")
    << "<th>significant</th></tr>\n";
  for (const audit::Trend& tr : t.trends) {
    h << "<tr><td>" << HtmlEscape(tr.descriptor) << "</td><td>" << HtmlEscape(Display(tr.descriptor, tr.unit).unit)
      << "</td><td>" << Fixed(tr.correlation_before, 3) << "</td>";
    if (has_after) h << "<td>" << Fixed(tr.correlation_after, 3) << "</td>";
    h << "<td>" << (tr.significant_before ? "<b>yes</b>" : "no")
      << (has_after ? std::string(" / ") + (tr.significant_after ? "<b>yes</b>" : "no") + " after" : "")
      << "</td></tr>\n";
  }
  h << "</table>\n<p><img src=\"" << HtmlEscape(files.trends_png) << "\" alt=\"error against posture descriptors\"><br>";
  if (out.trends_png_descriptors.empty()) {
    h << "No descriptor varies over these postures: there is no trend to draw.";
  } else {
    h << "The picture: the error per posture against ";
    for (size_t i = 0; i < out.trends_png_descriptors.size(); ++i) {
      h << (i == 0 ? "" : i + 1 == out.trends_png_descriptors.size() ? " and " : ", ")
        << HtmlEscape(out.trends_png_descriptors[i]);
    }
    h << " (the strongest correlations" << (t.trends.size() > out.trends_png_descriptors.size() ? "; the table has them all" : "")
      << "), " << (has_after ? "the current model on the left and after the best candidate on the right, " : "")
      << "each panel with its own error scale and the least-squares line whose fit r measures.";
  }
  h << "</p>\n";
}

// ---- HTML, second section: the error map (or that nothing matched).
void WriteModeMapHtml(std::ostringstream& h, const AuditPatternsReport& out, const AuditPatternFiles& files) {
  h << "<h2>Error map: postures against model modes</h2>\n";
  if (out.mode_error_map_png.empty()) {
    h << "<p>No measured mode was matched to a model mode: nothing to map.</p>\n";
  } else {
    h << "<p>Relative error of the calibrated current model per posture and model mode (numbered in ascending "
         "frequency), where a measured mode matched it; where it matched in several FRFs, the one with the largest "
         "measured peak. Table: <a href=\""
      << HtmlEscape(files.mode_errors_csv) << "\">" << HtmlEscape(files.mode_errors_csv) << "</a>.</p>\n<p><img src=\""
      << HtmlEscape(files.mode_error_map_png) << "\" alt=\"error map postures x modes\"></p>\n";
  }
}

// ---- HTML, third section: the modes without a counterpart, measured ones
// first, and the FRFs where the modal fit found none.
void WriteUnmatchedHtml(std::ostringstream& h, const audit::ErrorPatterns& p, const AuditPatternFiles& files) {
  h << "<h2>Modes without a counterpart</h2>\n<p>Per FRF: measured modes with no model mode near them (the model "
       "lacks them), and model modes that should show in the FRF (peak contribution |p<sub>r</sub> p<sub>e</sub>|"
       "/(2ζω²) at least 10 % of the largest model mode in the FRF's band) with no measured mode near them. "
       "\"Near\" is the matching's rule (frequency within its window, cost |ln f ratio| + w |ln visibility "
       "ratio|, one to one); modes too weak for the matching to try are paired by the same rule without the "
       "visibility threshold ("
    << p.weak_pairs << " such weak pairs, not listed). Table: <a href=\"" << HtmlEscape(files.unmatched_modes_csv) << "\">"
    << HtmlEscape(files.unmatched_modes_csv) << "</a>.</p>\n";
  auto table = [&](const std::vector<audit::UnmatchedMode>& list, const std::string& what, bool model) {
    h << "<h3>" << what << ": " << list.size() << "</h3>\n";
    if (list.empty()) return;
    h << "<table><tr><th>posture</th><th>FRF</th>" << (model ? "<th>model mode</th>" : "")
      << "<th>frequency [Hz]</th><th>damping ratio</th><th>relative visibility</th></tr>\n";
    for (const audit::UnmatchedMode& u : list) {
      h << "<tr><td>" << HtmlEscape(u.key.pose_id) << "</td><td>H" << Dir(u.key) << "</td>";
      if (model) h << "<td>" << u.model_mode + 1 << "</td>";
      h << "<td>" << Fixed(u.freq_hz, 2) << "</td><td>" << Fixed(u.damping_ratio, 4) << "</td><td>"
        << Fixed(u.relative_visibility, 2) << "</td></tr>\n";
    }
    h << "</table>\n";
  };
  table(p.unmatched_measured, "Measured modes without a model mode", false);
  table(p.unmatched_model, "Model modes without a measured mode", true);
  if (!p.frfs_without_modal_fit.empty()) {
    h << "<p>The modal fit found no mode in";
    for (const auto& k : p.frfs_without_modal_fit) h << ' ' << HtmlEscape(k.pose_id) << " H" << Dir(k);
    h << "; model modes are not checked there.</p>\n";
  }
}

}  // namespace

AuditPatternsReport MakeAuditPatternsReport(const audit::ErrorPatterns& p, double noise_floor,
                                            const std::string& title, const AuditPatternFiles& files) {
  AuditPatternsReport out;
  const audit::ErrorTrends& t = p.trends;

  AddTrends(t, &out);
  AddPostureDescriptors(t, &out);
  AddModeErrorMap(p.mode_map, &out);
  AddUnmatchedModes(p, &out);

  // ---- pictures
  const std::vector<size_t> drawn = TrendsToDraw(t);
  for (size_t i : drawn) out.trends_png_descriptors.push_back(t.trends[i].descriptor);
  out.trends_png = TrendsPng(p, drawn, noise_floor, TrendsFigureTitle(t, drawn, title));
  out.mode_error_map_png = ModeMapPng(p.mode_map, title);

  // ---- HTML
  std::ostringstream h;
  WriteTrendsHtml(h, t, out, files);
  WriteModeMapHtml(h, out, files);
  WriteUnmatchedHtml(h, p, files);
  out.html = h.str();
  return out;
}

}  // namespace robomach::report
