// stability-lobes: regenerative stability lobes (ZOA and/or first-order
// semi-discretization) of a tool tip given by the robot model at a
// posture, by a measured or predicted FRF file, or by a modal table.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>

#include "cli_support.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/lobes_file.h"
#include "robomach/report/lobes_plot.h"
#include "robomach/report/modal_fit_plot.h"
#include "robomach/report/plot.h"
#include "robomach/stability/semi_discretization.h"
#include "robomach/workflows/stability_lobes.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "stability-lobes";

// --fit-plot: each fitted direct FRF with its modal fit, magnitude and phase.
void PlotFits(const std::string& path, const std::string& frf_path, const std::vector<stability::TipDynamics>& tips) {
  int n = 0;
  for (const stability::TipDynamics& t : tips) n += static_cast<int>(t.fits.size());
  if (n == 0) return;
  report::Figure fig(2 * n, 1, 1000, 330);
  fig.title = "robomach stability-lobes: modal fits of " + std::filesystem::path(frf_path).filename().string();
  int row = 0;
  for (const stability::TipDynamics& t : tips) {
    for (const stability::DirectionFit& d : t.fits) {
      report::FillModalFitPanels(d.fit.measured, d.fit.noise, d.fit.fit, workflows::FitPanelTitle(d), &fig.at(row, 0),
                                 &fig.at(row + 1, 0));
      row += 2;
    }
  }
  fig.SavePng(path);
}

int Run(int argc, char** argv) {
  CLI::App app{
      "stability-lobes: regenerative chatter stability lobes (spindle speed against critical\n"
      "axial depth) by the zero-order approximation (Altintas-Budak) and/or first-order\n"
      "semi-discretization (Insperger-Stepan), for the robot model at postures, a measured\n"
      "FRF file (docs/formats.md §3) or a modal table (§4)."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             " Exit 3 when some speeds have no stability boundary, when a measured receptance is outside "
             "1e-12..1e-3 m/N (a unit mistake, e.g. a mobility read as receptance), when a measured FRF's modal fit is poor "
             "(misfit above 3 x the noise), finds no mode (then no SD lobes) or a mode at the edge of the usable "
             "band, when the FRF is not a passive driving point (Im H > 0 on more than 5 % of its usable lines), "
             "or when --method both finds the "
             "SD's and the ZOA's smallest depths more than 10 % apart at a radial immersion of 0.3 or more.");
  std::string robot_path, cut_path, postures_path, frf_path, frf_y_path, modal_path, out_path, plot_path,
      fit_plot_path, modes_out_path, summary_path, method = "zoa", tool_axis_text = "0,0,1";
  std::vector<std::string> pose_ids;
  int speeds = 0, sd_speeds = 60, sd_steps = 0, sd_modes = 3, threads = 0, max_lobe = 30;
  double sd_max_depth_mm = 20.0;
  const stability::SdOptions sd_defaults;
  double sd_steps_per_mode = sd_defaults.steps_per_mode_period;
  app.add_option("--cut", cut_path, "cut file YAML (config/cut_demo.yaml): tool, immersion, coefficients, speed range")->required();
  app.add_option("--robot", robot_path, "robot config YAML; with --postures and --posture");
  app.add_option("--postures", postures_path, "posture file CSV: pose_id,q1_deg..q6_deg");
  app.add_option("--posture", pose_ids, "pose_id to analyse (repeatable); all postures of the file if omitted");
  app.add_option("--frf", frf_path,
                 "tool-tip FRF file, CSV of docs/formats.md §3 or UFF58 (.uff/.unv; receptance, mobility or accelerance); "
                 "one direct FRF (any direction) = a symmetric tool, the same FRF in both in-plane directions of the cut");
  app.add_option("--frf-y", frf_y_path,
                 "with --frf: a second file with the one direct FRF normal to the feed in the cutting plane; --frf is "
                 "then the FRF along the feed (no cross terms)");
  app.add_option("--fit-plot", fit_plot_path,
                 "with --frf: PNG of each direct FRF with its modal fit (magnitude, phase, noise floor, usable band)")
      ->check(PngFileName());
  app.add_option("--modes-out", modes_out_path,
                 "with --frf: the modal table the SD used (docs/formats.md §4), in the frame of the FRF file; --modal-table "
                 "reads it back (with the same --tool-axis, and --sd-modes of at least its number of modes)");
  app.add_option("--modal-table", modal_path, "modal table CSV (docs/formats.md §4): freq_hz, damping_ratio, modal_mass_kg or modal_stiffness_N_per_m, ux,uy,uz");
  app.add_option("--tool-axis", tool_axis_text, "with --frf/--modal-table: tool axis from tip to spindle in the FRF frame, x,y,z (not used for a "
                 "file with one direct FRF, a symmetric tool, except for the frame of --modes-out)")->capture_default_str();
  app.add_option("--method", method, "zoa, sd or both")->check(OneOf({"zoa", "sd", "both"}))->capture_default_str();
  app.add_option("--out", out_path, "lobes CSV (spindle_speed_rpm, critical_depth_mm, chatter_freq_hz, lobe_index, method); stdout if omitted");
  app.add_option("--plot", plot_path, "lobe diagram PNG (speed [rpm] against depth [mm])")->check(PngFileName());
  app.add_option("--summary", summary_path,
                 "summary JSON (docs/formats.md §4.1): inputs, per posture and method the smallest and largest "
                 "critical depth and their speeds, status; '-' = stdout");
  app.add_option("--speeds", speeds, "ZOA: number of spindle speeds in the cut's range (default: the cut file's spindle_speed_count)");
  app.add_option("--max-lobe", max_lobe, "ZOA: highest lobe index traced")->capture_default_str();
  app.add_option("--sd-speeds", sd_speeds, "SD: number of spindle speeds in the cut's range")->capture_default_str();
  app.add_option("--sd-steps", sd_steps,
                 "SD: steps per tooth period at every speed; 0 = automatic (--sd-steps-per-mode-period steps per period of "
                 "the highest retained mode, at least " + std::to_string(sd_defaults.min_steps_per_period) +
                 " per tooth period, at most what keeps the monodromy matrix within " +
                 std::to_string(sd_defaults.max_monodromy_dimension) + " rows)")->capture_default_str();
  app.add_option("--sd-steps-per-mode-period", sd_steps_per_mode,
                 "SD, automatic steps: steps per period of the highest retained mode")->capture_default_str();
  app.add_option("--sd-modes", sd_modes,
                 "SD: number of modes kept (largest in-plane compliance); with --frf, per fitted direct FRF")
      ->capture_default_str();
  app.add_option("--sd-max-depth-mm", sd_max_depth_mm, "SD: largest depth searched [mm]")->capture_default_str();
  app.add_option("--threads", threads, "SD: worker threads, 0 = all cores")->capture_default_str();
  UncertaintyCli unc;
  AddUncertaintyOptions(app, &unc,
                        "with --robot: each ZOA speed's critical depth gets its interval (critical_depth_mm_lower, "
                        "the safe depth, and _upper in --out; a band in --plot)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }

  return RunGuarded(kTool, [&]() -> int {
    const std::optional<Eigen::Vector3d> axis = workflows::ParseToolAxis(tool_axis_text);
    if (!axis) throw UsageError("--tool-axis " + tool_axis_text + ": expected a non-zero vector x,y,z");
    unc.Finish();  // after the axis: the first bad option is named
    const workflows::StabilityLobesOptions o{
        .cut_path = cut_path, .robot_path = robot_path, .postures_path = postures_path, .frf_path = frf_path,
        .frf_y_path = frf_y_path, .modal_table_path = modal_path, .pose_ids = pose_ids, .tool_axis = *axis,
        .tool_axis_source = "--tool-axis " + tool_axis_text, .method = stability::ParseLobeMethod(method),
        .speeds = speeds, .max_lobe = max_lobe, .sd_speeds = sd_speeds, .sd_steps = sd_steps,
        .sd_steps_per_mode_period = sd_steps_per_mode, .sd_modes = sd_modes, .sd_max_depth_mm = sd_max_depth_mm,
        .threads = threads, .uncertainty_paths = unc.paths, .uncertainty = unc.propagation};
    ValidateOptions({{"robot_path", "--robot"}, {"postures_path", "--postures"}, {"frf_y_path", "--frf-y"},
                     {"frf_path", "--frf"}, {"modal_table_path", "--modal-table"}, {"tool_axis", "--tool-axis"},
                     {"speeds", "--speeds"}, {"max_lobe", "--max-lobe"}, {"sd_speeds", "--sd-speeds"},
                     {"sd_steps", "--sd-steps"}, {"sd_steps_per_mode_period", "--sd-steps-per-mode-period"},
                     {"sd_modes", "--sd-modes"}, {"sd_max_depth_mm", "--sd-max-depth-mm"}, {"threads", "--threads"},
                     {"uncertainty_paths", "--uncertainty"}},
                    [&] { o.Validate(); });
    if (frf_path.empty() && !fit_plot_path.empty()) throw UsageError("--fit-plot needs --frf");
    if (frf_path.empty() && !modes_out_path.empty()) throw UsageError("--modes-out needs --frf");
    RequireInputFile("--cut", cut_path, "cut file", {io::FileKind::kYaml}, io::kCutFileFormat);
    CheckDistinctPaths({{"--cut", cut_path}, {"--robot", robot_path}, {"--postures", postures_path},
                        {"--frf", frf_path}, {"--frf-y", frf_y_path}, {"--modal-table", modal_path}},
                       {{"--out", out_path}, {"--plot", plot_path}, {"--fit-plot", fit_plot_path},
                        {"--modes-out", modes_out_path}, {"--summary", summary_path}});
    for (const auto& [p, what] : {std::pair{robot_path, "robot config"}, {postures_path, "posture file"},
                                  {frf_path, "FRF file"}, {frf_y_path, "FRF file (--frf-y)"},
                                  {modal_path, "modal table"}}) {
      if (!p.empty()) RequireReadableFile(p, what);
    }
    if (!frf_path.empty()) {
      RequireInputFile("--frf", frf_path, "FRF file", {io::FileKind::kCsv, io::FileKind::kUff58}, io::kFrfFileFormat);
    }
    std::optional<ProgressLine> progress;
    const workflows::StabilityLobesRun run =
        workflows::RunStabilityLobes(o, MessagePrinter(kTool), [&](const stability::SdProgress& p) {
          // Counts the speeds themselves ("12/60"), from 20 speeds on.
          if (p.done == 0 && !p.finished) progress.emplace(kTool, "SD speeds of " + p.id, p.total, 20);
          if (!progress) return;
          if (p.finished) {
            progress->Finish();
            progress.reset();
          } else if (p.total > 0) {
            progress->Update(p.done);
          }
        });
    io::WriteLobesCsv(out_path.empty() ? "-" : out_path, run.lobes.rows, !run.bands.empty());
    if (!plot_path.empty()) {
      std::vector<report::LobeCurve> curves;
      for (const workflows::LobeDiagramCurve& c : run.DiagramCurves()) {
        curves.push_back({.label = c.label, .speed_rpm = c.speed_rpm, .depth_mm = c.depth_mm, .markers = c.markers,
                          .lower_mm = c.lower_mm, .upper_mm = c.upper_mm});
      }
      report::SaveLobesPlot(plot_path, "robomach stability-lobes: " + cut_path, run.CutDescription(), curves,
                            out_path.empty() || out_path == "-" ? std::string("the CSV")
                                                                : std::filesystem::path(out_path).filename().string(),
                            run.BandNote(o));
    }
    if (!modes_out_path.empty()) {
      std::vector<std::string> ids;
      std::vector<std::vector<dynamics::Mode>> modes;
      run.ModesInSourceFrame(&ids, &modes);
      io::WriteModalTableCsv(modes_out_path, ids, modes);
    }
    if (!fit_plot_path.empty()) PlotFits(fit_plot_path, frf_path, run.tips);
    const int exit_code = run.flagged() ? kExitFlagged : kExitOk;
    if (!summary_path.empty()) {
      nlohmann::json j = run.Summary(o);
      j["lobes_csv"] = out_path.empty() ? "-" : out_path;
      WriteToolSummary(summary_path, kTool, j, exit_code);
    }
    return exit_code;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
