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
#include "robomach/workflows/frf_predict.h"
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
  app.add_option("--max-depth-mm", max_depth_mm, "largest depth searched for mode coupling [mm]")->capture_default_str();
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
    if (region_path.empty()) {
      throw UsageError("--region is required (with --path it gives the seed posture and rotation)");
    }
    if (!(max_depth_mm > 0.0) || speeds < 0 || rotation_evals < 8) {
      throw UsageError("expected --max-depth-mm > 0, --speeds >= 0, --rotation-evals >= 8");
    }
    // Bounds that keep a typo from spawning 1e5 threads or hours of work.
    CheckOptionRange("--threads", threads, 0, 256);
    CheckOptionRange("--speeds", speeds, 0, 100000);
    RequireReadableFile(robot_path, "robot config");
    RequireReadableFile(cut_path, "cut file");
    RequireReadableFile(region_path, "region file");
    CheckDistinctPaths({{"--robot", robot_path}, {"--cut", cut_path}, {"--region", region_path}, {"--path", path_path}},
                       {{"--out", out_path}, {"--plot", plot_path}, {"--summary", summary_path}});
    if (!path_path.empty()) RequireReadableFile(path_path, "tool-path file");
    unc.Finish();
    io::RobotConfig cfg = LoadRobotConfigWarned(kTool, robot_path);
    if (!safe_plot_path.empty() && unc.PathsFor(cfg).empty()) {
      throw UsageError("--safe-plot needs --uncertainty (or a robot config that names uncertainty files)");
    }
    const std::optional<dynamics::ParameterUncertainty> uncertainty =
        workflows::UseUncertaintyFiles(unc.PathsFor(cfg), {}, &cfg, MessagePrinter(kTool));
    const auto model = cfg.Build();
    const io::CutSpec cut = io::ReadCutFile(cut_path);
    for (const std::string& w : cut.implausible) Warn(kTool, w);
    const io::RegionSpec region = io::ReadRegionFile(region_path, model->num_joints());
    for (const std::string& w : region.implausible) Warn(kTool, w);
    const bool implausible = !cut.implausible.empty() || !cfg.implausible.empty() || !region.implausible.empty();

    stability::MapOptions opt;
    opt.seed_q = region.seed_q;
    opt.rotation = region.rotation_fixed;
    opt.optimise_rotation = region.rotation_free;
    opt.rotation_min = region.rotation_min;
    opt.rotation_max = region.rotation_max;
    opt.rotation_evaluations = rotation_evals;
    opt.threads = threads;
    opt.analysis.spindle_speed_rad_s =
        cut.spindle_speed_rad_s ? cut.SpeedGrid() : cut.SpeedRange(speeds);
    opt.analysis.mode_coupling.max_depth = MmToM(max_depth_mm);

    const bool grid = path_path.empty();
    const io::MapPoints points = grid ? io::MapPointsOfRegion(region, cut.feed_direction_B)
                                      : io::MapPointsOfPathFile(path_path, cut.feed_direction_B);
    const std::vector<stability::ToolPoseTarget>& targets = points.targets;
    if (stability::FirstFeedAlongToolAxis(targets) >= 0) {
      throw InputError({cut_path, cut.feed_line, cut.feed_column}, "feed_direction is parallel to the tool axis of the " +
                                                                       std::string(grid ? "region" : "path") +
                                                                       "; choose a feed in the work plane");
    }
    ProgressLine progress(kTool, "points", static_cast<long>(targets.size()));
    opt.progress = [&](long done, long) { progress.Update(done); };
    const stability::StabilityMapResult map =
        stability::ComputeStabilityMap(model, targets, points.rows, points.cols, cut.process, opt);
    const std::vector<stability::MapPoint>& pts = map.points;
    progress.Finish();
    if (map.reached == 0) {
      throw InputError({grid ? region_path : path_path, grid ? region.origin_line : 0, grid ? region.origin_column : 0},
                       grid ? "no point of the region is reachable by the robot from seed_posture_deg within its joint limits "
                              "(origin, axes and size place it out of reach)"
                            : "no pose of the path is reachable by the robot from the region's seed_posture_deg");
    }

    // How far the seed's simplified closed form agrees with the eigenvalue
    // criterion (issue #6 asks to report it).
    if (const stability::ClosedFormAgreement a = stability::CompareClosedForm(pts); a.points > 0) {
      std::ostringstream msg;
      msg << kTool << ": mode coupling: the seed's simplified closed form (2 DOF, no damping; depth_closed_form_mm) "
          << "gives " << std::setprecision(3) << a.median << " times the eigenvalue criterion's depth at the median of "
          << a.points << " points (" << a.min << " to " << a.max << " times): an indicator, not a limit; the map "
          << "uses the eigenvalue criterion (docs/stability.md)\n";
      std::cerr << msg.str();
    }
    std::optional<stability::MapDepthIntervals> intervals;
    if (uncertainty) {
      // Monte Carlo takes about half a second per point: progress from the
      // first point (the auto map of 187 points ran 51 s without a line),
      // and what first order would cost instead.
      if (unc.method != "first-order" && targets.size() > 50) {
        Note(kTool, "--uncertainty-method " + unc.method + ": " +
                        (unc.method == "auto" ? "a linearity check at each of the " + std::to_string(targets.size()) +
                                                    " points and Monte Carlo (about 0.5 s a point) where the depth "
                                                    "bends within its interval"
                                              : "Monte Carlo at each of the " + std::to_string(targets.size()) +
                                                    " points (about 0.5 s a point)") +
                        "; --uncertainty-method first-order takes about 2.4 times the map's time (docs/uncertainty.md)");
      }
      ProgressLine up(kTool, "points' intervals", static_cast<long>(targets.size()),
                      unc.method == "first-order" ? 200 : 1);
      intervals = stability::StabilityMapIntervals(cfg.description, cfg.parameters, targets, pts, cut.process,
                                                   opt.analysis, *uncertainty, unc.propagation, threads,
                                                   [&](long done, long) { up.Update(done); });
      up.Finish();
      std::cerr << kTool << ": intervals at " << FormatNumber(100.0 * unc.propagation.confidence, 3) << " %: "
                << intervals->first_order << " points first order, " << intervals->monte_carlo
                << " Monte Carlo (" << intervals->example_reason << ")\n";
      if (const long k = intervals->SmallestLower(); k >= 0) {
        std::cerr << kTool << ": the smallest safe depth (" << FormatNumber(100.0 * unc.propagation.confidence, 3)
                  << " % lower bound) is " << FormatNumber(MToMm(intervals->depth[k].lower), 4) << " mm, at "
                  << (grid ? "row " + std::to_string(k / points.cols) + ", col " + std::to_string(k % points.cols)
                           : "point " + std::to_string(k + 1) + " of the path")
                  << "\n";
      }
    }
    if (!plot_path.empty() && !grid) Warn(kTool, "--plot draws grids only; ignored with --path");
    if (!safe_plot_path.empty() && !grid) Warn(kTool, "--safe-plot draws grids only; ignored with --path");
    io::WriteStabilityMapCsv(out_path.empty() ? "-" : out_path, points, pts, model->num_joints(),
                             intervals ? &intervals->depth : nullptr);
    auto heat_map = [&](const std::string& path, bool safe) {
      report::HeatMap hm;
      hm.title = safe ? "robomach stability-map: safe depth, the " + FormatNumber(100.0 * unc.propagation.confidence, 3) +
                            " % lower bound (" + cut_path + ")"
                      : "robomach stability-map: critical axial depth (" + cut_path + ")";
      hm.x_label = "u [mm] from the region origin";
      hm.y_label = "v [mm] from the region origin";
      hm.colorbar_label = "depth [mm]";
      hm.dx = hm.dy = MToMm(region.grid_step);
      hm.nx = points.cols;
      hm.ny = points.rows;
      hm.mark_label = "unreachable / joint limits";
      hm.nan_label = "no limit found";
      if (intervals) {  // the depth and the safe depth on one colour scale
        hm.range_min = INFINITY, hm.range_max = -INFINITY;
        for (size_t i = 0; i < pts.size(); ++i) {
          for (double v : {pts[i].stability.critical_depth, intervals->depth[i].lower}) {
            if (std::isfinite(v)) hm.range_min = std::min(hm.range_min, MToMm(v)), hm.range_max = std::max(hm.range_max, MToMm(v));
          }
        }
      }
      for (size_t i = 0; i < pts.size(); ++i) {
        const stability::MapPoint& p = pts[i];
        const bool out = p.status == stability::PointStatus::kUnreachable || p.status == stability::PointStatus::kJointLimits;
        const double depth = safe ? intervals->depth[i].lower : p.stability.critical_depth;
        hm.values.push_back(out ? NAN : MToMm(depth));
        hm.marks.push_back(out ? 1 : 0);
      }
      report::SaveHeatMapPng(hm, path);
    };
    if (!plot_path.empty() && grid) heat_map(plot_path, false);
    if (!safe_plot_path.empty() && grid) heat_map(safe_plot_path, true);
    // Warned before the summary is written: its `warnings` lists them.
    for (const Finding& f : map.findings) Warn(kTool, f.message);
    if (!summary_path.empty()) {
      nlohmann::json j = io::StabilityMapSummaryJson(points, map, stability::FindCriticalDepthExtremes(map.points));
      j["tool"] = kTool;
      j["robot"] = robot_path;
      j["cut"] = cut_path;
      if (!region_path.empty()) j["region"] = region_path;
      if (!path_path.empty()) j["path"] = path_path;
      j["points_csv"] = out_path.empty() ? "-" : out_path;
      if (intervals) {
        const long k = intervals->SmallestLower();
        const double safe_min = k >= 0 ? intervals->depth[static_cast<size_t>(k)].lower : NAN;
        j["uncertainty"] = {{"files", unc.PathsFor(cfg)},
                            {"confidence", unc.propagation.confidence},
                            {"points_first_order", intervals->first_order},
                            {"points_monte_carlo", intervals->monte_carlo},
                            {"reason", intervals->example_reason},
                            {"smallest_safe_depth_mm", std::isfinite(safe_min) ? MToMm(safe_min) : NAN}};
      }
      j["exit_code"] = !implausible ? ExitCodeFor(map.status()) : kExitFlagged;
      io::WriteFileAtomically(summary_path, SummaryText(j));
    }
    return !implausible ? ExitCodeFor(map.status()) : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
