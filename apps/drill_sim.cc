// drill-sim: a flexible-joint robot drilling a hole (seed 003): the robot
// holds a posture and feeds the drill along the hole axis; the drilling
// thrust, torque and tilt imbalance deflect the joints; a controller
// (PID, PD or PD with time-delay estimation) corrects. Writes the time series
// and summary of docs/formats.md §9.4 and a plot like the seed's Figs. 6-7.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/drill_series_file.h"
#include "robomach/report/plot.h"
#include "robomach/workflows/drilling_setup.h"

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
  app.add_option("--motor-torque-limit-Nm", limit_Nm, "motor torque limit, every joint [N m], > 0")
      ->capture_default_str();
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
    workflows::DrillSimOptions o;
    o.robot_path = robot_path;
    o.drill_path = drill_path;
    o.material_path = material_path;
    o.controllers.clear();
    std::stringstream ss(controllers);
    for (std::string k; std::getline(ss, k, ',');) o.controllers.push_back(k);
    o.gains = gain_texts;
    o.tune = tune;
    o.tune_evaluations = tune_evaluations;
    o.motor_torque_limit_Nm = limit_Nm;
    const std::vector<FieldSource> fields = {
        {"controllers", "--controller"}, {"gains", "--gains"}, {"tune_evaluations", "--tune-evaluations"},
        {"motor_torque_limit_Nm", "--motor-torque-limit-Nm"}};
    FromFields(fields, [&] { o.Validate(); });
    const bool several = o.controllers.size() > 1;
    std::vector<std::pair<std::string, std::string>> outs;
    for (const auto& k : o.controllers) {
      outs.push_back({"--out", WithSuffix(out_path, k, several)});
      outs.push_back({"--summary", WithSuffix(summary_path, k, several)});
    }
    outs.push_back({"--plot", plot_path});
    CheckDistinctPaths({{"--robot", robot_path}, {"--drill", drill_path}, {"--material", material_path}},
                       outs);
    RequireReadableFile(robot_path, "robot file");
    RequireReadableFile(drill_path, "drill file");
    RequireReadableFile(material_path, "material file");
    // The result lines and the verdict are told when all runs are done, so
    // that every summary lists the warnings; then every output (each
    // atomically; exit 3 keeps them).
    StageProgressLines progress(kTool);
    const workflows::DrillSimRun run = FromFields(
        fields, [&] { return workflows::RunDrillSim(o, progress.Messages(MessagePrinter(kTool)), progress.Callback()); });
    progress.Finish();
    for (const Run& r : run.runs) {
      const std::string kind = r.parameters.kind;
      const nlohmann::json j = run.Summary(r);
      if (!out_path.empty()) io::WriteFileAtomically(WithSuffix(out_path, kind, several), io::DrillSeriesCsv(r.result));
      if (!summary_path.empty()) {
        io::WriteFileAtomically(WithSuffix(summary_path, kind, several), SummaryText(j));
      } else if (out_path.empty()) {
        io::WriteFileAtomically("-", SummaryText(j));
      }
    }
    if (!plot_path.empty()) Plot(plot_path, run.runs, run.setup.robot->num_joints());
    return ExitCodeFor(run.status());
  });
}

}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::RunDrillSim(argc, argv); }
