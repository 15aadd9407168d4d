// axis-accuracy: ISO 230-2 positioning accuracy and repeatability per axis
// from positioning runs (docs/formats.md §8.6), as JSON and the standard chart.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/machine_files.h"
#include "robomach/machine/iso230.h"
#include "robomach/workflows/iso_evaluation.h"
#include "robomach/report/plot.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "axis-accuracy";

// A chart caption's number: 4 significant digits ("0.009985", "1.2e-05").
std::string Short(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

int MinRuns(const machine::Iso230Result& r) {
  int n = 1 << 30;
  for (const auto& t : r.targets) n = std::min({n, t.runs_up, t.runs_down});
  return n;
}

int Run(int argc, char** argv) {
  CLI::App app{
      "axis-accuracy: ISO 230-2 figures per axis (A, A_up, A_down, E, E_up, E_down, M, R, R_up, R_down, B,\n"
      "B_mean, in the file's unit) and per target from positioning runs (docs/formats.md §8.6), with the standard\n"
      "chart: mean deviation and +-2s bands per approach direction over the targets."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() + "\n3 here: deviations too large for positioning errors (a unit mistake, e.g. um "
                              "under _mm headers; docs/plausibility.md).");
  std::string runs_path, out_path, plot_path;
  app.add_option("--runs", runs_path, "runs CSV axis,target_mm,run,direction,measured_mm (or _deg)")->required();
  app.add_option("--out,--summary", out_path, "ISO 230-2 JSON, the tool's summary (stdout if omitted or '-')");
  app.add_option("--plot", plot_path, "PNG chart, one panel per axis")->check(PngFileName());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    RequireReadableFile(runs_path, "runs file");
    CheckDistinctPaths({{"--runs", runs_path}}, {{"--out", out_path}, {"--plot", plot_path}});
    const workflows::IsoEvaluation eval = workflows::EvaluateIsoRunsFile(runs_path);
    const io::IsoRuns& runs = eval.runs;
    const std::string unit = runs.rotary ? "deg" : "mm";
    const nlohmann::json j = workflows::IsoSummaryJson(eval);
    const auto& results = eval.results;
    const int min_runs = eval.min_runs;
    if (!plot_path.empty()) {
      report::Figure fig(static_cast<int>(results.size()), 1, 900, 380);
      fig.title = "ISO 230-2: mean deviation and +-2s per direction";
      for (size_t p = 0; p < results.size(); ++p) {
        const auto& [axis, r] = results[p];
        auto& ax = fig.at(static_cast<int>(p), 0);
        ax.title = "axis " + axis + ":  A = " + Short(r.A) + " " + unit + ",  R = " + Short(r.R) + " " + unit +
                   ",  B = " + Short(r.B) + " " + unit + "  (" + std::to_string(MinRuns(r)) + " runs each way)";
        ax.x_label = "target [" + unit + "]";
        ax.y_label = "deviation [" + unit + "]";
        std::vector<double> x, mu, mu_p, mu_m, md, md_p, md_m;
        for (const auto& t : r.targets) {
          x.push_back(t.target);
          mu.push_back(t.mean_up);
          mu_p.push_back(t.mean_up + 2 * t.s_up);
          mu_m.push_back(t.mean_up - 2 * t.s_up);
          md.push_back(t.mean_down);
          md_p.push_back(t.mean_down + 2 * t.s_down);
          md_m.push_back(t.mean_down - 2 * t.s_down);
        }
        ax.series.push_back({x, mu, "mean, + approach", report::PaletteColor(0), 2, false, false});
        ax.series.push_back({x, mu, "", report::PaletteColor(0), 2, false, true});  // the targets
        ax.series.push_back({x, mu_p, "+-2s, + approach", report::PaletteColor(0), 1, true, false});
        ax.series.push_back({x, mu_m, "", report::PaletteColor(0), 1, true, false});
        ax.series.push_back({x, md, "mean, - approach", report::PaletteColor(1), 2, false, false});
        ax.series.push_back({x, md, "", report::PaletteColor(1), 2, false, true});
        ax.series.push_back({x, md_p, "+-2s, - approach", report::PaletteColor(1), 1, true, false});
        ax.series.push_back({x, md_m, "", report::PaletteColor(1), 1, true, false});
        // The legend (top right, 4 entries: about 85 of the 304 px of the
        // plot) gets a free band above the curves instead of covering them;
        // the targets at the ends keep a margin from the frame.
        double lo = 0.0, hi = 0.0;  // the chart always shows the zero line
        for (const auto* v : {&mu_p, &mu_m, &md_p, &md_m}) {
          for (double y : *v) {
            lo = std::min(lo, y);
            hi = std::max(hi, y);
          }
        }
        const double span = hi > lo ? hi - lo : 1e-3;
        ax.y_min = lo - 0.08 * span;
        ax.y_max = hi + 0.5 * span;
        const double x_span = x.back() > x.front() ? x.back() - x.front() : 1.0;
        ax.x_min = x.front() - 0.03 * x_span;
        ax.x_max = x.back() + 0.03 * x_span;
      }
      fig.SavePng(plot_path);
    }
    // Warned before the summary is made: its `warnings` lists them.
    if (min_runs < 5) Warn(kTool, "fewer than the 5 runs per target and direction ISO 230-2 asks for (" + std::to_string(min_runs) + ")");
    for (const Finding& f : eval.verdict.findings) Warn(kTool, f.message);
    const std::string text = SummaryText(j);
    io::WriteFileAtomically(out_path.empty() ? "-" : out_path, text);
    return ExitCodeFor(eval.status());
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
