// polish-plan: a polishing path (cycloid along guide lines, or the parallel
// zig-zag) on a NURBS patch, optionally optimised (NLopt or the seed's PSO)
// for uniform removal, with time stamps that reach a target mean removal
// within the speed limit; writes the path, the removal map, a summary and
// pictures (seed 004; docs/formats.md §5-7).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "cli_support.h"
#include "polish_support.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/cad_face.h"
#include "robomach/io/number_format.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/path_patterns.h"
#include "robomach/workflows/polish_plan.h"
#include "robomach/workflows/polish_simulation.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "polish-plan";

// The library's option findings name its fields ("line_angle_deg"); the tool's warnings, its options.
MessageSink OptionNames(MessageSink sink) {
  return [sink](Message m) {
    for (const std::string f : {"line_angle_deg", "target_removal_um"}) {
      const std::string head = "implausible (unit mistake?): ";
      if (m.kind == Message::Kind::kWarning && m.text.rfind(head + f + " ", 0) == 0) {
        m.text.replace(head.size(), f.size(), f == "line_angle_deg" ? "--line-angle-deg" : "--target-removal-um");
      }
    }
    sink(m);
  };
}

int Run(int argc, char** argv) {
  CLI::App app{
      "polish-plan: a belt-grinding path on a NURBS patch (docs/formats.md §5) - cycloids along guide lines\n"
      "(seed 004) or the direction-parallel zig-zag - with Hertz contact and Preston removal, optionally\n"
      "optimised for uniform removal (--optimise nlopt|pso), timed so that the mean removal over the\n"
      "polished region equals --target-removal-um within max_speed_mm_per_s. Writes the path (docs/formats.md §6),\n"
      "the removal map and summary (§7) and PNG pictures (removal map, histogram, path, convergence)."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             "\nExit 3 (outputs written, the reason on stderr): the target removal cannot be reached within the "
             "speed limit (the path runs at the limit), or --optimise found no plan that reaches it; the optimised zig-zag "
             "is more uniform than the optimised cycloid (the message names it); path rows in contact lie off a trimmed face; with --robot, "
             "rows are unreachable, outside the joint limits or after a joint jump > 0.5 rad.");
  std::string path_out, removal_out, summary_out, plot_out, list_out;
  bool list_faces = false;
  // The planning options with the library's defaults (polishing::PlanOptions).
  workflows::PolishPlanOptions o;
  std::string &surface_path = o.surface_path, &process_path = o.process_path, &pattern = o.pattern;
  double offset_mm = 8.0;
  int seed = static_cast<int>(o.seed);
  RobotOptions robot;
  app.add_option("--surface", surface_path, "NURBS patch YAML, or STEP (.step/.stp) / IGES (.iges/.igs) file (docs/formats.md §5)")->required();
  AddSurfaceChoiceOptions(&app, &o.surface_choice);
  app.add_flag("--list-faces", list_faces,
               "list the faces of a STEP/IGES file as CSV (face, surface_type, area_mm2, u_size_mm, v_size_mm, "
               "trimmed, holes, polishable, reason; polishable with --process, --pattern and --radius-mm) and stop");
  app.add_option("--out", list_out, "with --list-faces: write the CSV here instead of stdout");
  app.add_option("--process", process_path,
                 "process YAML (docs/formats.md §7), e.g. config/polishing/belt_2N.yaml; required except with "
                 "--list-faces");
  {
    std::string help;
    std::vector<std::string> names;
    for (const polishing::PathPattern* p : polishing::PathPatterns()) {
      help += (help.empty() ? "" : "; ") + p->description();
      names.push_back(p->name());
    }
    app.add_option("--pattern", pattern, help)->check(OneOf(names, {{"zigzag", "parallel"}, {"zig-zag", "parallel"}, {"zig_zag", "parallel"},
                                                                {"raster", "parallel"}, {"trochoid", "cycloid"},
                                                                {"trochoidal", "cycloid"}}))->capture_default_str();
  }
  app.add_option("--guides", o.guides, "cycloid guide lines: offsets (of the region boundary, closed loops) or parallel")
      ->check(OneOf({"offsets", "parallel"}))->capture_default_str();
  app.add_option("--optimise", o.optimise, "none, nlopt (grid, then COBYLA multi-start with the target as a constraint; "
                                        "guide family chosen unless --guides is given) or pso (seed eq. 18)")
      ->check(OneOf({"none", "nlopt", "pso"}))->capture_default_str();
  app.add_option("--target-removal-um", o.target_removal_um, "mean removal over the region [um]; sets the speed (0: run at max speed)")->capture_default_str();
  app.add_option("--offset-mm", offset_mm, "guide-line spacing d [mm] (parallel pattern: row spacing; default there: one contact width)");
  app.add_option("--radius-mm", o.radius_mm, "cycloid radius r [mm]")->capture_default_str();
  app.add_option("--pitch-mm", o.pitch_mm, "advance of the cycloid centre per loop [mm] (= 2 pi v / omega)")->capture_default_str();
  app.add_option("--edge-inset-mm", o.edge_inset_mm, "cycloid on offsets: distance of the outermost guide loop from the "
                                                   "region boundary [mm], at most 10000 either way (< 0: on it, or r - margin_mm inside if the margin is narrower than r)")
      ->capture_default_str();
  app.add_option("--sample-mm", o.sample_mm, "removal map sampling in arc length [mm], <= 0.5")->capture_default_str();
  app.add_option("--row-step-mm", o.row_step_mm, "largest distance between path rows [mm]")->capture_default_str();
  app.add_option("--opt-sample-mm", o.opt_sample_mm, "sampling used inside the optimiser [mm]")->capture_default_str();
  app.add_option("--opt-offset-max-mm", o.opt_offset_max_mm, "largest guide-line spacing the optimiser tries [mm]")->capture_default_str();
  app.add_option("--opt-offset-min-contact-widths", o.opt_offset_min_contact_widths,
                 "smallest guide-line spacing the optimiser tries, in contact widths (closer rows lengthen the path)")
      ->capture_default_str();
  app.add_option("--stagger-loops", o.stagger_loops, "cycloid: phase of adjacent rows, in loops, [0, 1] (0.5: a loop faces "
                                                  "the gap between two loops of the next row)")->capture_default_str();
  app.add_option("--line-angle-deg", o.line_angle_deg, "direction of the parallel guide lines / zig-zag rows in the developed "
                                                    "plane [deg], 0: along u (s), 90: along v (t)")->capture_default_str();
  app.add_option("--edge-overrun-mm", o.edge_overrun_mm, "plain patches: how far guide lines / zig-zag rows run beyond the "
                                                      "polished region into the margin [mm] (at most margin_mm - r, zig-zag margin_mm)")
      ->capture_default_str();
  app.add_option("--max-time-s", o.max_time_s, "time budget of --optimise [s]; it stops earlier on convergence")->capture_default_str();
  app.add_option("--threads", o.threads, "threads of --optimise")->capture_default_str();
  app.add_option("--seed", seed, "PSO random seed")->capture_default_str();
  robot.Add(&app);
  app.add_option("--path", path_out, "tool path CSV (docs/formats.md §6)");
  app.add_option("--removal", removal_out, "removal map CSV x_mm,y_mm,z_mm,u,v,removal_um");
  app.add_option("--summary", summary_out, "summary JSON (docs/formats.md §7 + contact, optimisation, target)");
  app.add_option("--plot", plot_out, "removal map PNG; also <stem>_histogram.png, <stem>_path.png, <stem>_convergence.png")->check(PngFileName());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  if (app.count("--offset-mm") > 0) o.offset_mm = offset_mm;
  o.guides_given = app.count("--guides") > 0;
  o.seed = static_cast<unsigned>(seed);
  o.surface_choice.cad_face_given = app.count("--face") > 0;

  return RunGuarded(kTool, [&]() -> int {
    // The library's ranges, under the command line's names.
    std::vector<FieldSource> fields = {{"optimise", "--optimise"}, {"cad_face", "--face"}, {"cad_unit_scale", "--cad-unit-scale"}};
    for (const polishing::PlanOptionRange& r : polishing::PlanOptionRanges(o)) {
      std::string option = "--" + r.name;
      std::replace(option.begin(), option.end(), '_', '-');
      fields.push_back({r.name, option});
    }
    FromFields(fields, [&] { o.Validate(); o.surface_choice.Validate(); });
    CheckOptionRange("--edge-inset-mm", o.edge_inset_mm, -1e4, 1e4);  // a finite inset, < 10 m: any part
    RequireReadableFile(surface_path, "surface");
    if (process_path.empty() && !list_faces) throw UsageError("--process is required (except with --list-faces)");
    if (!process_path.empty()) RequireReadableFile(process_path, "process file");
    std::vector<std::pair<std::string, std::string>> outs = {
        {"--path", path_out}, {"--removal", removal_out}, {"--summary", summary_out}, {"--out", list_out}};
    robot.Prepare(&outs);
    if (!plot_out.empty()) {
      for (const auto& p : PicturePaths(plot_out, o.optimise != "none")) outs.push_back({"--plot", p});
    }
    CheckDistinctPaths({{"--surface", surface_path}, {"--process", process_path}, {"--robot", robot.robot_path()}}, outs);

    if (list_faces) {  // one CSV row per face of a STEP/IGES file (docs/formats.md §5)
      if (!io::IsCadFile(surface_path)) {
        throw UsageError("--list-faces: " + surface_path + " is a NURBS YAML (one patch); --list-faces lists "
                         "the faces of a STEP/IGES file");
      }
      if (o.surface_choice.cad_face_given) throw UsageError("--list-faces lists every face; drop --face");
      StageProgressLines progress(kTool);
      const auto rows = workflows::ListPolishFaces(o, progress.Messages(MessagePrinter(kTool)), progress.Callback());
      progress.Finish();
      io::WriteFileAtomically(list_out.empty() ? "-" : list_out, io::CadFaceListCsv(rows));
      return kExitOk;
    }
    if (!list_out.empty()) throw UsageError("--out goes with --list-faces (the face list); the planned path is written with --path, the removal with --removal");
    // The progress line counts per mille of the time budget (the optimiser
    // stops on convergence, usually before it); a message ends it.
    std::optional<ProgressLine> progress;
    const MessageSink printer = OptionNames(MessagePrinter(kTool));
    const auto tell = [&](const Message& m) {
      if (progress) progress->Finish(), progress.reset();
      printer(m);
    };
    const auto on_progress = [&](int n, double best, double elapsed) {
      if (!progress) progress.emplace(kTool, "optimiser, per mille of --max-time-s", 1000);
      std::ostringstream d;
      d << n << " evaluations, best feasible cv " << (std::isfinite(best) ? io::FormatDouble(best) : "none yet");
      progress->Update(std::min(1000L, static_cast<long>(1000 * elapsed / o.max_time_s)), d.str());
    };
    const workflows::PolishPlanRun run =
        FromFields({{"cad_face", "--face"}, {"cad_unit_scale", "--cad-unit-scale"}, {"path_parameters", "path parameters"}},
                   [&] { return workflows::RunPolishPlan(o, tell, on_progress); });
    if (progress) progress->Finish();
    const polishing::EvaluatedPlan& e = run.outcome.plan;
    nlohmann::json summary = run.Summary(o);
    const bool flagged = robot.Check(kTool, run.process, e.path.rows, &summary) || run.flagged();
    const auto meta = workflows::PlannedPathMetadata(run.outcome.params, run.process);
    if (!path_out.empty()) io::WritePolishPath(path_out, e.path.rows, meta);
    if (!removal_out.empty()) io::WriteRemovalMap(removal_out, *run.context.grid, e.removal);
    robot.WriteJoints(e.path.rows);
    if (!plot_out.empty()) {
      WritePictures(plot_out, *run.context.grid, e.removal, e.path.rows, e.path.guide_lines_st,
                    run.outcome.history_best, pattern, run.outcome.history_cv);
    }
    io::WriteFileAtomically(summary_out.empty() ? "-" : summary_out, SummaryText(summary));
    return flagged ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
