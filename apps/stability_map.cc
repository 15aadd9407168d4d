// stability-map: chatter limits (mode coupling and regenerative) over a
// rectangle of the workspace or along a tool path, with IK per point.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <optional>
#include <cmath>
#include <iostream>
#include <iomanip>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/number_format.h"
#include "robomach/io/region_file.h"
#include "robomach/io/stability_map_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/stability/lobe_uncertainty.h"
#include "robomach/workflows/stability_map.h"
#include "robomach/report/heat_map.h"
#include "robomach/report/json.h"
#include "robomach/stability/stability_map.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "stability-map";

int Run(int argc, char** argv) {
  CLI::App app{
      "stability-map: critical axial depth of cut over a work region (grid of tool poses from a\n"
      "region file) or along a tool path: inverse kinematics per point seeded from the neighbour,\n"
      "mode-coupling chatter (eigenvalues of the posture's 3-D tool-tip dynamics under the\n"
      "cutting stiffness) and regenerative chatter (ZOA lobes at the cut's speed or the best\n"
      "speed of its range); optionally the rotation about the tool axis that maximises the depth."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp());
  std::string robot_path, cut_path, region_path, path_path, out_path, plot_path, safe_plot_path, summary_path;
  int threads = 0, speeds = 0, rotation_evals = 20;
  double max_depth_mm = 50.0;
  app.add_option("--robot", robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--cut", cut_path, "cut file YAML (config/cut_demo.yaml)")->required();
  app.add_option("--region", region_path, "region file YAML (config/region_demo.yaml)");
  app.add_option("--path", path_path, "tool-path CSV: x_mm,y_mm,z_mm,tool_i,tool_j,tool_k[,feed_i,feed_j,feed_k][,rotation_deg][,point_id]; the tool axis points from the tip to the spindle; rotation_deg is added to the region's rotation about the tool axis; the region file gives the seed posture");
  app.add_option("--out", out_path, "per-point CSV; stdout if omitted");
  app.add_option("--plot", plot_path, "heat map PNG of the critical depth [mm] (grid only)")->check(PngFileName());
  app.add_option("--summary", summary_path,
                 "summary JSON (docs/formats.md §4.1): inputs, point counts by status, the smallest and largest "
                 "critical depth and where; '-' = stdout");
  app.add_option("--threads", threads, "worker threads, 0 = all cores")->capture_default_str();
  app.add_option("--speeds", speeds, "speeds scanned for the best one (default: the cut file's spindle_speed_count)");
  app.add_option("--max-depth-mm", max_depth_mm, "largest depth searched for mode coupling [mm], at most 10000")->capture_default_str();
  app.add_option("--rotation-evals", rotation_evals, "evaluations per point when the rotation is free")->capture_default_str();
  UncertaintyCli unc;
  AddUncertaintyOptions(app, &unc,
                        "each point's critical depth gets its interval (critical_depth_mm_lower, the safe depth, "
                        "and _upper in --out); --safe-plot draws the safe depth");
  app.add_option("--safe-plot", safe_plot_path, "with --uncertainty: heat map PNG of the safe depth [mm] (grid only)")
      ->check(PngFileName());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    workflows::StabilityMapOptions o;
    o.robot_path = robot_path;
    o.cut_path = cut_path;
    o.region_path = region_path;
    o.path_path = path_path;
    o.threads = threads;
    o.speeds = speeds;
    o.max_depth_mm = max_depth_mm;
    o.rotation_evaluations = rotation_evals;
    const std::vector<FieldSource> fields = {
        {"region_path", "--region"}, {"path_path", "--path"},   {"max_depth_mm", "--max-depth-mm"},
        {"speeds", "--speeds"},      {"threads", "--threads"}, {"rotation_evaluations", "--rotation-evals"}};
    FromFields(fields, [&] { o.Validate(); });
    RequireReadableFile(robot_path, "robot config");
    RequireReadableFile(cut_path, "cut file");
    RequireReadableFile(region_path, "region file");
    CheckDistinctPaths({{"--robot", robot_path}, {"--cut", cut_path}, {"--region", region_path}, {"--path", path_path}},
                       {{"--out", out_path}, {"--plot", plot_path}, {"--summary", summary_path}});
    if (!path_path.empty()) RequireReadableFile(path_path, "tool-path file");
    unc.Finish();
    o.uncertainty_paths = unc.paths;
    o.uncertainty = unc.propagation;
    if (!safe_plot_path.empty() && unc.paths.empty() && io::LoadRobotConfig(robot_path).uncertainty_files.empty()) {
      throw UsageError("--safe-plot needs --uncertainty (or a robot config that names uncertainty files)");
    }
    StageProgressLines progress(kTool);
    progress.MinTotal("points' intervals", unc.method == "first-order" ? 200 : 1);
    const workflows::StabilityMapRun run = FromFields(
        fields, [&] { return workflows::RunStabilityMap(o, progress.Messages(MessagePrinter(kTool)), progress.Callback()); });
    progress.Finish();
    const std::vector<stability::MapPoint>& pts = run.map.points;
    const bool grid = run.points.grid;
    if (!plot_path.empty() && !grid) Warn(kTool, "--plot draws grids only; ignored with --path");
    if (!safe_plot_path.empty() && !grid) Warn(kTool, "--safe-plot draws grids only; ignored with --path");
    io::WriteStabilityMapCsv(out_path.empty() ? "-" : out_path, run.points, pts, run.num_joints,
                             run.intervals ? &run.intervals->depth : nullptr);
    auto heat_map = [&](const std::string& path, bool safe) {
      report::HeatMap hm;
      hm.title = safe ? "robomach stability-map: safe depth, the " + FormatNumber(100.0 * unc.propagation.confidence, 3) +
                            " % lower bound (" + cut_path + ")"
                      : "robomach stability-map: critical axial depth (" + cut_path + ")";
      hm.x_label = "u [mm] from the region origin";
      hm.y_label = "v [mm] from the region origin";
      hm.colorbar_label = "depth [mm]";
      hm.dx = hm.dy = MToMm(run.region.grid_step);
      hm.nx = run.points.cols;
      hm.ny = run.points.rows;
      hm.mark_label = "unreachable / joint limits";
      hm.nan_label = "no limit found";
      if (run.intervals) {  // the depth and the safe depth on one colour scale
        hm.range_min = INFINITY, hm.range_max = -INFINITY;
        for (size_t i = 0; i < pts.size(); ++i) {
          for (double v : {pts[i].stability.critical_depth, run.intervals->depth[i].lower}) {
            if (std::isfinite(v)) hm.range_min = std::min(hm.range_min, MToMm(v)), hm.range_max = std::max(hm.range_max, MToMm(v));
          }
        }
      }
      for (size_t i = 0; i < pts.size(); ++i) {
        const stability::MapPoint& p = pts[i];
        const bool out = p.status == stability::PointStatus::kUnreachable || p.status == stability::PointStatus::kJointLimits;
        const double depth = safe ? run.intervals->depth[i].lower : p.stability.critical_depth;
        hm.values.push_back(out ? NAN : MToMm(depth));
        hm.marks.push_back(out ? 1 : 0);
      }
      report::SaveHeatMapPng(hm, path);
    };
    if (!plot_path.empty() && grid) heat_map(plot_path, false);
    if (!safe_plot_path.empty() && grid) heat_map(safe_plot_path, true);
    // Warned before the summary is written: its `warnings` lists them.
    for (const Finding& f : run.map.verdict.findings) Warn(kTool, f.message);
    const int exit_code = ExitCodeFor(run.status());
    if (!summary_path.empty()) {
      nlohmann::json j = run.Summary(o);
      j["tool"] = kTool;
      j["points_csv"] = out_path.empty() ? "-" : out_path;
      j["exit_code"] = exit_code;
      io::WriteFileAtomically(summary_path, SummaryText(j));
    }
    return exit_code;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
