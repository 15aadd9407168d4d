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
#include "robomach/workflows/polish_plan.h"
#include "robomach/workflows/polish_simulation.h"
#include "robomach/io/polishing_summary.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/removal.h"
#include "robomach/report/json.h"

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
  choice.cad_face_given = app.count("--face") > 0;
  return RunGuarded(kTool, [&]() -> int {
    CheckOptionRange("--sample-mm", sample_mm, 0.05, 0.5);
    FromFields({{"cad_face", "--face"}, {"cad_unit_scale", "--cad-unit-scale"}}, [&] { choice.Validate(); });
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

    const polishing::NurbsSurface surface =
        FromFields({{"cad_face", "--face"}, {"cad_unit_scale", "--cad-unit-scale"}},
                   [&] { return workflows::LoadPolishSurface(surface_path, choice, MessagePrinter(kTool)); });
    std::vector<std::string> implausible;  // unit findings of the process file
    const polishing::PolishingProcess process = io::ReadPolishingProcess(process_path, &implausible);
    for (const std::string& w : implausible) Warn(kTool, w);
    workflows::PolishSimulation sim =
        workflows::SimulatePolishPathFile(surface, process, path_in, MmToM(sample_mm), surface_path, process_path);
    io::PolishPathFile& file = sim.file;
    const polishing::SampleGrid& grid = *sim.grid;
    const std::vector<double>& removal = sim.removal;
    const polishing::RemovalStats& stats = sim.stats;
    for (const Finding& f : sim.verdict.findings) Warn(kTool, f.message);
    bool flagged = sim.verdict.flagged() || !implausible.empty();
    const std::string unpolished = polishing::DescribeUnpolished(
        stats, grid.region_area(), file.metadata.count("pattern") > 0 ? file.metadata.at("pattern") : std::string());
    if (!unpolished.empty()) Warn(kTool, unpolished);
    nlohmann::json summary = workflows::PolishSimSummaryJson(sim, process, sample_mm);
    if (robot.Check(kTool, process, file.rows, &summary)) flagged = true;
    if (!removal_out.empty()) io::WriteRemovalMap(removal_out, grid, removal);
    robot.WriteJoints(file.rows);
    if (!plot_out.empty()) WritePictures(plot_out, grid, removal, file.rows, {}, {}, "polish-sim");
    const std::string text = SummaryText(summary);
    io::WriteFileAtomically(summary_out.empty() ? "-" : summary_out, text);
    return flagged ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
