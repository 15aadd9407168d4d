// polish-sim: the removal a given tool path (docs/formats.md §6; from CAM, a teach
// pendant or polish-plan) produces on a NURBS patch with the process of
// docs/formats.md §7: removal map, summary and pictures.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "polish_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/removal.h"
#include "robomach/report/posture_json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "polish-sim";

int Run(int argc, char** argv) {
  CLI::App app{
      "polish-sim: simulate the Preston removal of a tool path (docs/formats.md §6) on a NURBS patch\n"
      "(docs/formats.md §5) with Hertz contact (docs/formats.md §7); writes the removal map, a summary and pictures."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             "\nExit 3 (outputs written, the reason on stderr): the path's traverse speed exceeds "
             "max_speed_mm_per_s; with --robot, rows are unreachable, outside the joint limits or after a joint "
             "jump > 0.5 rad.");
  std::string surface_path, process_path, path_in, removal_out, summary_out, plot_out;
  double sample_mm = 0.5;
  app.add_option("--surface", surface_path, "NURBS patch YAML, or STEP (.step/.stp) / IGES (.iges/.igs) file (docs/formats.md §5)")->required();
  SurfaceChoice choice;
  AddSurfaceChoiceOptions(&app, &choice);
  app.add_option("--process", process_path, "process YAML (docs/formats.md §7)")->required();
  app.add_option("--path", path_in, "tool path CSV (docs/formats.md §6)")->required();
  app.add_option("--sample-mm", sample_mm, "removal map sampling in arc length [mm], <= 0.5")->capture_default_str();
  app.add_option("--removal", removal_out, "removal map CSV x_mm,y_mm,z_mm,u,v,removal_um");
  app.add_option("--summary", summary_out, "summary JSON (docs/formats.md §7); stdout if omitted");
  app.add_option("--plot", plot_out, "removal map PNG; also <stem>_histogram.png and <stem>_path.png")->check(PngFileName());
  RobotOptions robot;
  robot.Add(&app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  choice.face_given = app.count("--face") > 0;
  return RunGuarded(kTool, [&]() -> int {
    CheckOptionRange("--sample-mm", sample_mm, 0.05, 0.5);
    RequireReadableFile(surface_path, "surface");
    RequireReadableFile(process_path, "process file");
    RequireReadableFile(path_in, "tool path");
    std::vector<std::pair<std::string, std::string>> outs = {{"--removal", removal_out}, {"--summary", summary_out}};
    if (!plot_out.empty())
      for (const auto& p : PicturePaths(plot_out, false)) outs.push_back({"--plot", p});
    robot.Prepare(&outs);
    CheckDistinctPaths({{"--surface", surface_path}, {"--process", process_path}, {"--path", path_in},
                        {"--robot", robot.robot_path()}},
                       outs);

    const polishing::NurbsSurface surface = LoadSurface(kTool, surface_path, choice);
    const polishing::PolishingProcess process = io::ReadPolishingProcess(process_path);
    io::PolishPathFile file = io::ReadPolishPath(path_in);
    polishing::SampleGrid grid = [&] {
      try {
        return polishing::SampleGrid::Build(surface, MmToM(sample_mm), process.margin, process.flip_normal);
      } catch (const std::domain_error& e) {
        throw InputError({surface_path, 0, 0}, e.what());
      }
    }();
    if (grid.num_in_region() == 0) {
      throw InputError({process_path, 0, 0}, "process.margin_mm leaves no polished region on the patch");
    }
    auto row_error = [&](const polishing::PathRowError& e) {
      return InputError({file.path, file.lines[e.row()], 0}, "path row " + std::to_string(e.row() + 1) + ": " + e.what());
    };
    std::vector<double> removal;
    try {
      polishing::AttachToSurface(surface, grid, process.flip_normal, &file.rows);
      const polishing::RemovalSimulator sim(surface, process, grid.points(), grid.normals(), 0.0015);
      removal = sim.Simulate(file.rows);
    } catch (const polishing::PathRowError& e) {
      throw row_error(e);
    }
    const double vmax = polishing::MaxSpeed(file.rows);
    // Flag a segment only if it is too fast even when its length is read as
    // short as the file's rounding allows: polish-plan writes positions to
    // 1e-4 mm, so each end may be off by 0.5e-7 m per coordinate (a path
    // timed exactly at the limit read 50.01 mm/s on 0.5 mm rows).
    constexpr double kRounding = 2 * 0.5e-7 * 1.7320508075688772;  // [m]
    double v_sure = 0.0;
    for (size_t i = 1; i < file.rows.size(); ++i) {
      const double len = (file.rows[i].p - file.rows[i - 1].p).norm();
      v_sure = std::max(v_sure, std::max(0.0, len - kRounding) / (file.rows[i].t - file.rows[i - 1].t));
    }
    bool flagged = false;
    if (v_sure > process.max_speed * (1 + 1e-6)) {
      flagged = true;
      Warn(kTool, "the path's traverse speed reaches " + io::FormatDouble(1e3 * vmax) +
                      " mm/s, above max_speed_mm_per_s " + io::FormatDouble(1e3 * process.max_speed));
    }
    const polishing::RemovalStats stats = polishing::ComputeRemovalStats(removal, grid.areas(), grid.in_region());
    nlohmann::json summary;
    summary["removal_um"] = RemovalJson(stats);
    summary["path"] = PathJson(file.rows);
    auto meta = [&](const char* k) {
      const auto it = file.metadata.find(k);
      double v = 0;
      return it != file.metadata.end() && io::ParseFiniteNumber(it->second, &v) ? v : 0.0;
    };
    const auto pat = file.metadata.find("pattern");
    const std::string pattern = pat != file.metadata.end() ? pat->second : std::string("unknown");
    summary["parameters"] = {{"pattern", pattern},
                             {"offset_mm", meta("offset_mm")}, {"radius_mm", meta("radius_mm")},
                             {"pitch_mm", meta("pitch_mm")}, {"omega_rad_per_s", 0.0},
                             {"centre_speed_mm_per_s", 0.0}};
    summary["region"] = {{"sample_mm", sample_mm}, {"points", grid.num_in_region()}, {"margin_mm", 1e3 * process.margin}};
    ReportUnpolished(kTool, stats, grid, &summary["region"]);
    summary["speed_limit_exceeded"] = flagged;
    if (robot.Check(kTool, process, file.rows, &summary)) flagged = true;
    if (!removal_out.empty()) io::WriteRemovalMap(removal_out, grid, removal);
    robot.WriteJoints(file.rows);
    if (!plot_out.empty()) WritePictures(plot_out, grid, removal, file.rows, {}, {}, "polish-sim");
    const std::string text = report::DumpJson(summary);
    io::WriteFileAtomically(summary_out.empty() ? "-" : summary_out, text);
    return flagged ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
