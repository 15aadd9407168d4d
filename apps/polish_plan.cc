// polish-plan: a polishing path (cycloid along guide lines, or the parallel
// zig-zag) on a NURBS patch, optionally optimised (NLopt or the seed's PSO)
// for uniform removal, with time stamps that reach a target mean removal
// within the speed limit; writes the path, the removal map, a summary and
// pictures (seed 004; docs/formats.md §5-7).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "polish_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/golden_section.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"
#include "robomach/io/polishing_files.h"
#include "robomach/io/polishing_summary.h"
#include "robomach/io/robot_config.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/cad_face.h"
#include "robomach/polishing/face_check.h"
#include "robomach/polishing/optimise.h"
#include "robomach/polishing/path_patterns.h"
#include "robomach/polishing/plan_workflow.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/removal.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "polish-plan";

// --list-faces: one CSV row per face of a STEP/IGES file (docs/formats.md §5).
int ListFaces(const std::string& surface_path, const std::string& process_path, const std::string& out,
              const SurfaceChoice& choice, const std::string& pattern, double radius_mm, double sample_mm,
              double offset_mm, double pitch_mm, double row_step_mm) {
  if (!io::IsCadFile(surface_path)) {
    throw UsageError("--list-faces: " + surface_path + " is a NURBS YAML (one patch); --list-faces lists "
                     "the faces of a STEP/IGES file");
  }
  if (choice.face_given) throw UsageError("--list-faces lists every face; drop --face");
  // Listing needs nothing but the file (issue #35); with --process each face
  // is also checked against the contact.
  std::optional<polishing::PolishingProcess> process;
  if (!process_path.empty()) process = io::ReadPolishingProcess(process_path);
  polishing::PathParameters params;
  params.pattern = polishing::FindPathPattern(pattern).id();
  params.radius = MmToM(radius_mm);
  params.offset = MmToM(offset_mm);
  params.pitch = MmToM(pitch_mm);
  params.row_step = MmToM(row_step_mm);
  polishing::PolishableOptions po;
  po.sample_spacing = MmToM(sample_mm);
  io::CadReadOptions options;
  options.unit_scale = choice.cad_unit_scale;
  io::CadPartInfo info;
  std::unique_ptr<ProgressLine> progress;
  const auto rows = io::ListCadFaces(
      surface_path,
      [&](const polishing::NurbsSurface& s) {
        if (!process) return std::make_pair(true, std::string("contact not checked (give --process)"));
        const polishing::Polishability p = polishing::CheckPolishable(s, *process, params, po);
        return std::make_pair(p.polishable, p.reason);
      },
      options, &info, [&](int done, int total) {
        if (!progress) progress = std::make_unique<ProgressLine>(kTool, "faces", total);
        progress->Update(done);
      });
  if (progress) progress->Finish();
  if (!info.unit_warning.empty()) Warn(kTool, surface_path + ": " + info.unit_warning);
  io::WriteFileAtomically(out.empty() ? "-" : out, io::CadFaceListCsv(rows));
  return kExitOk;
}

// Refuses a face too large to sample at --sample-mm (naming it, its size and
// the estimate), and warns with the estimate before long work.
void CheckFaceSize(const polishing::NurbsSurface& surface, const std::string& surface_path, double sample_mm,
                   const polishing::PathParameters& params) {
  const polishing::PolishableOptions limits;
  const polishing::PlanSize size = polishing::EstimatePlanSize(surface, MmToM(sample_mm), params, limits);
  if (size.too_large) {
    throw InputError({surface_path, 0, 0}, size.too_large_message + " (check the file's unit: --cad-unit-scale; or "
                                                                    "choose a smaller face, --list-faces)");
  }
  if (size.large) Warn(kTool, size.what + " is large: " + size.estimate + "; planning may take a minute");
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
  std::string surface_path, process_path, path_out, removal_out, summary_out, plot_out;
  SurfaceChoice choice;
  bool list_faces = false;
  std::string list_out;
  // The planning options with the library's defaults (polishing::PlanOptions).
  polishing::PlanOptions po;
  std::string &pattern = po.pattern, &guides = po.guides, &optimise = po.optimise;
  double offset_mm = 8.0, sample_mm = 0.5;
  double &target_um = po.target_removal_um, &radius_mm = po.radius_mm, &pitch_mm = po.pitch_mm,
         &row_step_mm = po.row_step_mm, &opt_sample_mm = po.opt_sample_mm, &opt_offset_max_mm = po.opt_offset_max_mm,
         &opt_offset_min_cw = po.opt_offset_min_contact_widths, &edge_inset_mm = po.edge_inset_mm,
         &max_time_s = po.max_time_s, &stagger_loops = po.stagger_loops, &line_angle_deg = po.line_angle_deg,
         &edge_overrun_mm = po.edge_overrun_mm;
  int& threads = po.threads;
  int seed = static_cast<int>(po.seed);
  RobotOptions robot;
  app.add_option("--surface", surface_path, "NURBS patch YAML, or STEP (.step/.stp) / IGES (.iges/.igs) file (docs/formats.md §5)")->required();
  AddSurfaceChoiceOptions(&app, &choice);
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
  app.add_option("--guides", guides, "cycloid guide lines: offsets (of the region boundary, closed loops) or parallel")
      ->check(OneOf({"offsets", "parallel"}))->capture_default_str();
  app.add_option("--optimise", optimise, "none, nlopt (grid, then COBYLA multi-start with the target as a constraint; "
                                        "guide family chosen unless --guides is given) or pso (seed eq. 18)")
      ->check(OneOf({"none", "nlopt", "pso"}))->capture_default_str();
  app.add_option("--target-removal-um", target_um, "mean removal over the region [um]; sets the speed (0: run at max speed)")->capture_default_str();
  app.add_option("--offset-mm", offset_mm, "guide-line spacing d [mm] (parallel pattern: row spacing; default there: one contact width)");
  app.add_option("--radius-mm", radius_mm, "cycloid radius r [mm]")->capture_default_str();
  app.add_option("--pitch-mm", pitch_mm, "advance of the cycloid centre per loop [mm] (= 2 pi v / omega)")->capture_default_str();
  app.add_option("--edge-inset-mm", edge_inset_mm, "cycloid on offsets: distance of the outermost guide loop from the "
                                                   "region boundary [mm] (< 0: on it, or r - margin_mm inside if the margin is narrower than r)")
      ->capture_default_str();
  app.add_option("--sample-mm", sample_mm, "removal map sampling in arc length [mm], <= 0.5")->capture_default_str();
  app.add_option("--row-step-mm", row_step_mm, "largest distance between path rows [mm]")->capture_default_str();
  app.add_option("--opt-sample-mm", opt_sample_mm, "sampling used inside the optimiser [mm]")->capture_default_str();
  app.add_option("--opt-offset-max-mm", opt_offset_max_mm, "largest guide-line spacing the optimiser tries [mm]")->capture_default_str();
  app.add_option("--opt-offset-min-contact-widths", opt_offset_min_cw,
                 "smallest guide-line spacing the optimiser tries, in contact widths (closer rows lengthen the path)")
      ->capture_default_str();
  app.add_option("--stagger-loops", stagger_loops, "cycloid: phase of adjacent rows, in loops, [0, 1] (0.5: a loop faces "
                                                  "the gap between two loops of the next row)")->capture_default_str();
  app.add_option("--line-angle-deg", line_angle_deg, "direction of the parallel guide lines / zig-zag rows in the developed "
                                                    "plane [deg], 0: along u (s), 90: along v (t)")->capture_default_str();
  app.add_option("--edge-overrun-mm", edge_overrun_mm, "plain patches: how far guide lines / zig-zag rows run beyond the "
                                                      "polished region into the margin [mm] (at most margin_mm - r, zig-zag margin_mm)")
      ->capture_default_str();
  app.add_option("--max-time-s", max_time_s, "time budget of --optimise [s]; it stops earlier on convergence")->capture_default_str();
  app.add_option("--threads", threads, "threads of --optimise")->capture_default_str();
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
  const bool offset_given = app.count("--offset-mm") > 0;
  const bool guides_given = app.count("--guides") > 0;
  choice.face_given = app.count("--face") > 0;

  return RunGuarded(kTool, [&]() -> int {
    po.sample_mm = sample_mm;
    if (offset_given) po.offset_mm = offset_mm;
    // The library's ranges, under the command line's names.
    for (const polishing::PlanOptionRange& r : polishing::PlanOptionRanges(po)) {
      std::string option = "--" + r.name;
      std::replace(option.begin(), option.end(), '_', '-');
      CheckOptionRange(option, r.value, r.lo, r.hi);
    }
    if (optimise != "none" && pattern == "parallel" && optimise == "pso") {
      throw UsageError("--optimise pso applies to the cycloid; the parallel pattern is optimised with --optimise nlopt");
    }
    RequireReadableFile(surface_path, "surface");
    if (process_path.empty() && !list_faces) throw UsageError("--process is required (except with --list-faces)");
    if (!process_path.empty()) RequireReadableFile(process_path, "process file");
    std::vector<std::pair<std::string, std::string>> outs = {
        {"--path", path_out}, {"--removal", removal_out}, {"--summary", summary_out}, {"--out", list_out}};
    robot.Prepare(&outs);
    if (!plot_out.empty()) {
      for (const auto& p : PicturePaths(plot_out, optimise != "none")) outs.push_back({"--plot", p});
    }
    CheckDistinctPaths({{"--surface", surface_path}, {"--process", process_path}, {"--robot", robot.robot_path()}}, outs);

    if (list_faces) return ListFaces(surface_path, process_path, list_out, choice, pattern, radius_mm, sample_mm, offset_mm,
                                     pitch_mm, row_step_mm);
    if (!list_out.empty()) throw UsageError("--out goes with --list-faces (the face list); the planned path is written with --path, the removal with --removal");
    std::vector<std::string> implausible;  // unit findings of the process file
    const polishing::PolishingProcess process = io::ReadPolishingProcess(process_path, &implausible);
    // The one angle option: radians typed under _deg (1.5708 for 90 deg).
    if (const std::string w = RadiansInDegreeOption("--line-angle-deg", po.line_angle_deg); !w.empty()) {
      implausible.push_back(w);
    }
    for (std::string w : polishing::ImplausiblePlanOptions(po)) {
      // Under the command line's names.
      if (w.find("target_removal_um") != std::string::npos) {
        w.replace(w.find("target_removal_um"), 17, "--target-removal-um");
      }
      implausible.push_back(w);
    }
    for (const std::string& w : implausible) Warn(kTool, w);
    const polishing::NurbsSurface surface = LoadSurface(kTool, surface_path, choice);
    {
      polishing::PathParameters p;
      p.pattern = polishing::FindPathPattern(pattern).id();
      p.offset = MmToM(offset_mm);
      p.radius = MmToM(radius_mm);
      p.pitch = MmToM(pitch_mm);
      p.row_step = MmToM(row_step_mm);
      CheckFaceSize(surface, surface_path, sample_mm, p);
    }
    const polishing::PlanningContext ctx =
        polishing::PreparePlanning(surface, process, MmToM(po.sample_mm), surface_path, process_path);
    const polishing::SampleGrid& grid = *ctx.grid;

    po.guides_given = guides_given;
    po.seed = static_cast<unsigned>(seed);
    // Every parameter comes from an option: a value out of its limits is exit 64.
    polishing::PlanRequest req;
    FromOption("path parameters", [&] { req = polishing::ToPlanRequest(po, ctx); });
    polishing::PathParameters params = req.params;
    // The progress line counts per mille of the time budget (the optimiser
    // stops on convergence, usually before it).
    std::optional<ProgressLine> progress;
    if (req.optimise) {
      progress.emplace(kTool, "optimiser, per mille of --max-time-s", 1000);
      req.progress = [&](int n, double best, double elapsed) {
        std::ostringstream d;
        d << n << " evaluations, best feasible cv " << (std::isfinite(best) ? io::FormatDouble(best) : "none yet");
        progress->Update(std::min(1000L, static_cast<long>(1000 * elapsed / max_time_s)), d.str());
      };
    }
    polishing::PlanOutcome outcome = polishing::PlanPolishing(ctx, req);
    if (progress) progress->Finish();
    params = outcome.params;
    const polishing::EvaluatedPlan& e = outcome.plan;
    for (const Finding& f : outcome.findings) Warn(kTool, f.message);
    bool flagged = outcome.flagged() || !implausible.empty();
    if (outcome.optimisation && outcome.optimisation->status == "max_time") {
      Note(kTool, "the optimiser stopped at --max-time-s " + io::FormatDouble(max_time_s) +
                      " before its local searches converged; the best plan so far is written");
    }
    if (outcome.comparison && outcome.comparison->zigzag_better) {
      const polishing::PathParameters& pp = outcome.comparison->parallel;
      Note(kTool, "to plan the zig-zag: --pattern parallel --offset-mm " + io::FormatDouble(1e3 * pp.offset) +
                      " --line-angle-deg " + io::FormatDouble(pp.line_angle * 180.0 / kPi) + " --edge-overrun-mm " +
                      io::FormatDouble(1e3 * pp.edge_overrun));
    }
    const std::string unpolished = polishing::DescribeUnpolished(e.stats, grid.region_area(), pattern);
    if (!unpolished.empty()) Warn(kTool, unpolished);
    if (e.stats.coverage < 0.99) {
      Warn(kTool, "coverage " + FormatNumber(e.stats.coverage, 3) + " < 0.99: parts of the region get less than a "
                  "tenth of the mean removal" + (req.optimise ? "" : " (--optimise, or a smaller --offset-mm, covers them)"));
    }
    // An uneven removal is the plan's own result, not a fault of the input:
    // a note that says what evens it (docs/polishing.md).
    if (!req.optimise && e.stats.cv > 0.3) {
      Note(kTool, "the removal varies by " + FormatNumber(100 * e.stats.cv, 2) + " % (CV) over the region: --optimise "
                  "chooses the pattern's parameters for the most even removal (docs/polishing.md)");
    }
    nlohmann::json summary = io::PolishPlanSummaryJson(outcome, ctx, po);

    if (robot.Check(kTool, process, e.path.rows, &summary)) flagged = true;
    const auto meta = io::PlannedPathMetadata(params, process);
    if (!path_out.empty()) io::WritePolishPath(path_out, e.path.rows, meta);
    if (!removal_out.empty()) io::WriteRemovalMap(removal_out, grid, e.removal);
    robot.WriteJoints(e.path.rows);
    if (!plot_out.empty()) {
      WritePictures(plot_out, grid, e.removal, e.path.rows, e.path.guide_lines_st, outcome.history_best, pattern,
                    outcome.history_cv);
    }
    io::WriteFileAtomically(summary_out.empty() ? "-" : summary_out, SummaryText(summary));
    return flagged ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
