// drill-sim: a flexible-joint robot drilling a hole (seed 003): the robot
// holds a posture and feeds the drill along the hole axis; the drilling
// thrust, torque and tilt imbalance deflect the joints; a controller
// (PID, PD or PD with time-delay estimation) corrects. Writes the time series
// and summary of docs/formats.md §9.4 and a plot like the seed's Figs. 6-7.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/number_format.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/drilling/controller_kinds.h"
#include "robomach/drilling/controller_runs.h"
#include "robomach/drilling/drilling_sim.h"
#include "robomach/drilling/plausibility.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/drill_series_file.h"
#include "robomach/io/drilling_files.h"
#include "robomach/workflows/drilling_setup.h"
#include "robomach/io/number_format.h"
#include "robomach/report/plot.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "drill-sim";

// "run.csv" + "pd-tdc" -> "run_pd-tdc.csv" (several controllers: one file each).
std::string WithSuffix(const std::string& path, const std::string& name, bool several) {
  if (!several || path.empty() || path == "-") return path;  // "-": stdout, one after the other
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + "_" + name + p.extension().string())).string();
}

using Run = drilling::ControllerRun;

void Plot(const std::string& path, const std::vector<Run>& runs, int n) {
  const int panels = n + 3;
  const int rows = (panels + 1) / 2;
  report::Figure fig(rows, 2, 700, 300);
  fig.title = "drill-sim: joint errors, drill offset, thrust and torque";
  auto axes = [&](int k) -> report::Axes& { return fig.at(k / 2, k % 2); };
  for (int i = 0; i < n; ++i) {
    axes(i).title = "joint " + std::to_string(i + 1);
    axes(i).y_label = "e" + std::to_string(i + 1) + " [deg]";
  }
  axes(n).title = "drill offset from the hole axis";
  axes(n).y_label = "offset [deg]";
  axes(n + 1).title = "thrust";
  axes(n + 1).y_label = "thrust [N]";
  axes(n + 2).title = "torque";
  axes(n + 2).y_label = "torque [N m]";
  // Thrust and torque rise to a plateau at the top right: legend below it.
  axes(n + 1).legend = report::Axes::LegendPosition::kBottomRight;
  axes(n + 2).legend = report::Axes::LegendPosition::kBottomRight;
  for (int k = 0; k < panels; ++k) axes(k).x_label = "time [s]";
  int c = 0;
  for (const Run& run : runs) {
    const drilling::SimSeries& s = run.result.series;
    const report::Rgb color = report::PaletteColor(c++);
    const std::string label = run.parameters.kind;
    for (int i = 0; i < n; ++i) {
      report::Series se{.x = s.t, .label = label, .color = color};
      for (size_t k = 0; k < s.t.size(); ++k) se.y.push_back(RadToDeg(s.e(i, k)));
      axes(i).series.push_back(se);
    }
    report::Series so{.x = s.t, .label = label, .color = color};
    for (double v : s.offset) so.y.push_back(RadToDeg(v));
    axes(n).series.push_back(so);
    axes(n + 1).series.push_back({.x = s.t, .y = s.thrust, .label = label, .color = color});
    axes(n + 2).series.push_back({.x = s.t, .y = s.torque, .label = label, .color = color});
  }
  fig.SavePng(path);
}

}  // namespace

int RunDrillSim(int argc, char** argv) {
  CLI::App app{"drill-sim: flexible-joint robot drilling a hole (seed 003): joint deflection, "
               "drill tilt and forces under PID, PD or PD with time-delay estimation"};
  AddVersionFlag(app, kTool);
  app.footer("With several controllers each output gets the controller's name before its "
             "extension (run.csv -> run_pid.csv, run_pd-tdc.csv); the plot overlays them.\n" +
             ExitCodeHelp() +
             "\n3 here also: a drill diameter, feed, spindle or cutting speed, or material coefficient outside "
             "drilling practice (a unit mistake; docs/plausibility.md).");
  std::string robot_path, drill_path, material_path, out_path, summary_path, plot_path;
  std::string controllers = "pd-tdc";
  bool tune = false;
  int tune_evaluations = 30;
  double limit_Nm = 10.0;
  app.add_option("--robot", robot_path, "flexible-joint robot YAML (docs/formats.md 9.3)")->required();
  app.add_option("--drill", drill_path, "drill and process YAML (docs/formats.md 9.2) with process:")->required();
  app.add_option("--material", material_path, "material YAML written by drill-force-fit")->required();
  app.add_option("--controller", controllers, "comma-separated: pid, pd, pd-tdc")->capture_default_str();
  app.add_flag("--tune", tune, "tune every controller's gains with NLopt against one cost "
               "(time-weighted absolute joint error, motor torque limits); otherwise tuned defaults");
  app.add_option("--tune-evaluations", tune_evaluations, "simulations per controller when tuning")
      ->check(CLI::Range(5, 1000))->capture_default_str();
  app.add_option("--motor-torque-limit-Nm", limit_Nm, "motor torque limit, every joint [N m]")
      ->check(CLI::PositiveNumber)->capture_default_str();
  std::vector<std::string> gain_texts;
  app.add_option("--gains", gain_texts,
                 "gain parameters KIND=OMEGA,ZETA[,THIRD[,FILTER_S]] (repeatable): OMEGA [rad/s] and ZETA set "
                 "K_P, K_D per joint from the effective inertia; THIRD is r of K_I = K_P OMEGA / r "
                 "(pid) or the Mbar ratio (pd-tdc); FILTER_S the low-pass time constant [s] on e' (pid, pd) "
                 "or q'' (pd-tdc), default 0.005; the starting point of --tune");
  app.add_option("--out", out_path, "time series CSV (docs/formats.md 9.4); '-' = stdout");
  app.add_option("--summary", summary_path, "summary JSON (docs/formats.md 9.4); stdout if neither --out nor --summary");
  app.add_option("--plot", plot_path, "PNG: joint errors, drill offset, thrust, torque per controller")->check(PngFileName());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    std::vector<std::string> kinds;
    {
      std::stringstream ss(controllers);
      std::string k;
      while (std::getline(ss, k, ',')) {
        FromOption("--controller", [&] { drilling::FindControllerKind(k); });
        if (std::find(kinds.begin(), kinds.end(), k) != kinds.end()) {
          throw UsageError("--controller: \"" + k + "\" given twice");
        }
        kinds.push_back(k);
      }
    }
    if (kinds.empty()) throw UsageError("--controller: expected at least one controller");
    const bool several = kinds.size() > 1;
    std::vector<std::pair<std::string, std::string>> outs;
    for (const auto& k : kinds) {
      outs.push_back({"--out", WithSuffix(out_path, k, several)});
      outs.push_back({"--summary", WithSuffix(summary_path, k, several)});
    }
    outs.push_back({"--plot", plot_path});
    CheckDistinctPaths({{"--robot", robot_path}, {"--drill", drill_path}, {"--material", material_path}},
                       outs);
    RequireReadableFile(robot_path, "robot file");
    RequireReadableFile(drill_path, "drill file");
    RequireReadableFile(material_path, "material file");
    const workflows::DrillingSetup setup = workflows::LoadDrillingSetup(robot_path, drill_path, material_path, limit_Nm);
    for (const auto& u : setup.robot_file.unused_sections) {
      Warn(kTool, robot_path + ": section '" + u + "' is not used by drill-sim");
    }
    drilling::DrillingScenario* sc = setup.scenario.get();
    const int n = setup.robot->num_joints();
    const Eigen::VectorXd& limit = setup.motor_torque_limit;

    std::map<std::string, drilling::ControllerParameters> given;
    for (const std::string& text : gain_texts) {
      const auto eq = text.find('=');
      const std::string kind = text.substr(0, eq);
      if (eq == std::string::npos) {
        throw UsageError("--gains: expected KIND=OMEGA,ZETA[,THIRD] with KIND " + drilling::ControllerKindList() +
                         ", got \"" + text + "\"");
      }
      const std::vector<double> v = ParseNumberList("--gains", text.substr(eq + 1));
      given[kind] = FromOption("--gains " + text, [&] { return drilling::ParametersFromGains(kind, v); });
    }
    drilling::ControllerRunOptions ro;
    ro.kinds = kinds;
    ro.given = given;
    ro.tune = tune;
    ro.tune_evaluations = tune_evaluations;
    ro.motor_torque_limit = limit;
    std::optional<ProgressLine> progress;
    const std::vector<Run> runs = drilling::RunControllers(*sc, ro, [&](const drilling::ControllerRunProgress& p) {
      if (p.tuning) {
        std::cerr << kTool << ": tuning " << p.kind << " (" << p.total << " simulations)\n";
        return;
      }
      if (p.finished) {
        if (progress) progress->Finish();
        progress.reset();
        if (p.run && p.run->tde_condition_fails()) {
          Warn(kTool, "pd-tdc: the TDE stability condition ||I - M^-1 Mbar|| < 1 fails (" +
                          FormatNumber(p.run->tde_measure) + "); lower the Mbar ratio");
        }
        return;
      }
      if (!progress) progress.emplace(kTool, "simulating " + p.kind, p.total);
      progress->Update(p.done);
    });

    // All runs done: the result lines and the verdict (diverged runs, unit
    // plausibility: drilling/plausibility.h) first, so that every summary
    // lists its warnings; then every output (each atomically; exit 3 keeps them).
    for (const Run& run : runs) {
      const drilling::SimResult& r = run.result;
      const bool stopped = r.diverged;  // the last 10 % was never simulated
      std::ostringstream line;
      line << run.parameters.kind << ": settling "
           << (std::isnan(r.settling_time) ? std::string("never") : FormatNumber(r.settling_time) + " s")
           << ", max |e| " << FormatNumber(RadToDeg(r.max_abs_error.maxCoeff())) << " deg, last 10 % max |e| "
           << (stopped ? std::string("n/a (run stopped)") : FormatNumber(RadToDeg(r.max_abs_error_last_10pc.maxCoeff())) + " deg");
      std::cerr << kTool << ": " << line.str() << "\n";
    }
    const RunFindings verdict = drilling::JudgeControllerRuns(runs, setup.unit_findings);
    for (const Finding& f : verdict.findings) Warn(kTool, f.message);
    for (const Run& run : runs) {
      const std::string kind = run.parameters.kind;
      const nlohmann::json j = io::DrillRunSummaryJson(run, *sc, limit);
      if (!out_path.empty()) io::WriteFileAtomically(WithSuffix(out_path, kind, several), io::DrillSeriesCsv(run.result));
      if (!summary_path.empty()) {
        io::WriteFileAtomically(WithSuffix(summary_path, kind, several), SummaryText(j));
      } else if (out_path.empty()) {
        io::WriteFileAtomically("-", SummaryText(j));
      }
    }
    if (!plot_path.empty()) Plot(plot_path, runs, n);
    return ExitCodeFor(verdict.status());
  });
}

}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::RunDrillSim(argc, argv); }
