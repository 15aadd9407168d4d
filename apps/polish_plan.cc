// polish-plan: a polishing path (cycloid along guide lines, or the parallel
// zig-zag) on a NURBS patch, optionally optimised (NLopt or the seed's PSO)
// for uniform removal, with time stamps that reach a target mean removal
// within the speed limit; writes the path, the removal map, a summary and
// pictures (seed 004; formats.md §5-7).
#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
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
#include "robomach/io/robot_config.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/cad_face.h"
#include "robomach/polishing/face_check.h"
#include "robomach/polishing/optimise.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/removal.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "polish-plan";

struct Evaluated {
  polishing::PlannedPath path;
  std::vector<double> removal;
  polishing::RemovalStats stats;
};

// Plans and simulates; a contact that fails at a row becomes an InputError
// on the surface file naming the row and its position.
Evaluated Evaluate(const polishing::NurbsSurface& surface, const polishing::SampleGrid& grid,
                   const polishing::RemovalSimulator& sim, const polishing::PathParameters& params,
                   const polishing::PolishingProcess& process, const std::string& surface_path) {
  Evaluated e;
  e.path = polishing::PlanPath(surface, grid, params, process);
  try {
    e.removal = sim.Simulate(e.path.rows);
  } catch (const polishing::PathRowError& err) {
    const auto& r = e.path.rows[err.row()];
    std::ostringstream m;
    m << "planned path row " << err.row() + 1 << " at (" << 1e3 * r.p.x() << ", " << 1e3 * r.p.y() << ", "
      << 1e3 * r.p.z() << ") mm (u " << r.u << ", v " << r.v << "): " << err.what();
    throw InputError({surface_path, 0, 0}, m.str());
  }
  e.stats = polishing::ComputeRemovalStats(e.removal, grid.areas(), grid.in_region());
  return e;
}

std::string Short(double x) {
  std::ostringstream o;
  o.precision(4);
  o << x;
  return o.str();
}

std::string Short6(double x) {
  std::ostringstream o;
  o.precision(6);
  o << x;
  return o.str();
}

std::string CsvField(const std::string& x) {
  if (x.find_first_of(",\"\n") == std::string::npos) return x;
  std::string q = "\"";
  for (char c : x) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

// --list-faces: one CSV row per face of a STEP/IGES file (formats.md §5).
int ListFaces(const std::string& surface_path, const std::string& process_path, const std::string& out,
              const SurfaceChoice& choice, const std::string& pattern, double radius_mm, double sample_mm,
              double offset_mm, double pitch_mm, double row_step_mm) {
  if (!io::IsCadFile(surface_path)) {
    throw std::invalid_argument("--list-faces: " + surface_path + " is a NURBS YAML (one patch); --list-faces lists "
                                "the faces of a STEP/IGES file");
  }
  if (choice.face_given) throw std::invalid_argument("--list-faces lists every face; drop --face");
  const polishing::PolishingProcess process = io::ReadPolishingProcess(process_path);
  polishing::PathParameters params;
  params.pattern = pattern == "cycloid" ? polishing::Pattern::kCycloid : polishing::Pattern::kParallel;
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
        const polishing::Polishability p = polishing::CheckPolishable(s, process, params, po);
        return std::make_pair(p.polishable, p.reason);
      },
      options, &info, [&](int done, int total) {
        if (!progress) progress = std::make_unique<ProgressLine>(kTool, "faces", total);
        progress->Update(done);
      });
  if (progress) progress->Finish();
  if (!info.unit_warning.empty()) Warn(kTool, surface_path + ": " + info.unit_warning);
  std::ostringstream csv;
  csv << "face,surface_type,area_mm2,u_size_mm,v_size_mm,trimmed,holes,polishable,reason\n";
  for (const auto& r : rows) {
    csv << r.face << ',' << r.surface_type << ',' << Short6(r.area_mm2) << ',' << Short6(r.u_size_mm) << ','
        << Short6(r.v_size_mm) << ',' << (r.trimmed ? 1 : 0) << ','
        << r.holes << ',' << (r.polishable ? 1 : 0) << ',' << CsvField(r.reason) << '\n';
  }
  if (out.empty()) std::cout << csv.str();
  else io::WriteFileAtomically(out, csv.str());
  return kExitOk;
}

// Refuses a face too large to sample at --sample-mm (naming it, its size and
// the estimate), and warns with the estimate before long work.
void CheckFaceSize(const polishing::NurbsSurface& surface, const std::string& surface_path, double sample_mm,
                   const polishing::PathParameters& params) {
  const polishing::SurfaceSize size = polishing::MeasureSurface(surface);
  const double points = polishing::EstimateGridPoints(size, MmToM(sample_mm));
  const polishing::PolishableOptions limits;
  const double area = surface.trim() ? surface.trim()->area : size.length_u * size.length_v;
  const double rows = polishing::EstimatePathRows(area, params);
  std::ostringstream m;
  m.precision(3);
  m << polishing::SurfaceName(surface) << " (" << 1e3 * size.length_u << " x " << 1e3 * size.length_v
    << " mm, mean arc lengths along u and v; " << 1e6 * area << " mm^2)";
  const std::string what = m.str();
  m.str("");
  m << points << " grid points at --sample-mm " << sample_mm << " (~" << points * 90e-9 << " GB) and a path of ~" << rows
    << " rows";
  const std::string estimate = m.str();
  if (!(points <= limits.max_grid_points) || !(rows <= limits.max_path_rows)) {
    m.str("");
    m << what << " is too large to plan within the limits (" << limits.max_grid_points << " grid points, "
      << limits.max_path_rows << " path rows; about a minute and 2 GB): " << estimate
      << " (check the file's unit: --cad-unit-scale; or choose a smaller face, --list-faces)";
    throw InputError({surface_path, 0, 0}, m.str());
  }
  if (points > 2e5 || rows > 1e5) Warn(kTool, what + " is large: " + estimate + "; planning may take a minute");
}

int Run(int argc, char** argv) {
  CLI::App app{
      "polish-plan: a belt-grinding path on a NURBS patch (formats.md §5) - cycloids along guide lines\n"
      "(seed 004) or the direction-parallel zig-zag - with Hertz contact and Preston removal, optionally\n"
      "optimised for uniform removal (--optimise nlopt|pso), timed so that the mean removal over the\n"
      "polished region equals --target-removal-um within max_speed_mm_per_s. Writes the path (formats.md §6),\n"
      "the removal map and summary (§7) and PNG pictures (removal map, histogram, path, convergence)."};
  app.footer(ExitCodeHelp() +
             "\nExit 3 (outputs written, the reason on stderr): the target removal cannot be reached within the "
             "speed limit (the path runs at the limit); path rows in contact lie off a trimmed face; with --robot, "
             "rows are unreachable, outside the joint limits or after a joint jump > 0.5 rad.");
  std::string surface_path, process_path, pattern = "cycloid", guides = "offsets", optimise = "none", path_out,
                                          removal_out, summary_out, plot_out;
  SurfaceChoice choice;
  bool list_faces = false;
  std::string list_out;
  double target_um = 0.0, offset_mm = 8.0, radius_mm = 6.0, pitch_mm = 3.0, sample_mm = 0.5, row_step_mm = 0.5;
  double opt_sample_mm = 1.0, opt_offset_max_mm = 30.0, opt_offset_min_cw = 0.3, edge_inset_mm = -1.0;
  int seed = 20240404;
  RobotOptions robot;
  app.add_option("--surface", surface_path, "NURBS patch YAML, or STEP (.step/.stp) / IGES (.iges/.igs) file (formats.md §5)")->required();
  AddSurfaceChoiceOptions(&app, &choice);
  app.add_flag("--list-faces", list_faces,
               "list the faces of a STEP/IGES file as CSV (face, surface_type, area_mm2, u_size_mm, v_size_mm, "
               "trimmed, holes, polishable, reason; polishable with --process, --pattern and --radius-mm) and stop");
  app.add_option("--out", list_out, "with --list-faces: write the CSV here instead of stdout");
  app.add_option("--process", process_path, "process YAML (formats.md §7), e.g. config/polishing/belt_2N.yaml")->required();
  app.add_option("--pattern", pattern, "cycloid or parallel")->check(CLI::IsMember({"cycloid", "parallel"}))->capture_default_str();
  app.add_option("--guides", guides, "cycloid guide lines: offsets (of the region boundary, closed loops) or parallel")
      ->check(CLI::IsMember({"offsets", "parallel"}))->capture_default_str();
  app.add_option("--optimise", optimise, "none, nlopt (DIRECT-L then Subplex) or pso (seed eq. 18)")
      ->check(CLI::IsMember({"none", "nlopt", "pso"}))->capture_default_str();
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
  app.add_option("--seed", seed, "PSO random seed")->capture_default_str();
  robot.Add(&app);
  app.add_option("--path", path_out, "tool path CSV (formats.md §6)");
  app.add_option("--removal", removal_out, "removal map CSV x_mm,y_mm,z_mm,u,v,removal_um");
  app.add_option("--summary", summary_out, "summary JSON (formats.md §7 + contact, optimisation, target)");
  app.add_option("--plot", plot_out, "removal map PNG; also <stem>_histogram.png, <stem>_path.png, <stem>_convergence.png");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  const bool offset_given = app.count("--offset-mm") > 0;
  choice.face_given = app.count("--face") > 0;

  return RunGuarded(kTool, [&]() -> int {
    CheckOptionRange("--sample-mm", sample_mm, 0.05, 0.5);
    CheckOptionRange("--row-step-mm", row_step_mm, 0.05, 5.0);
    CheckOptionRange("--opt-sample-mm", opt_sample_mm, 0.1, 5.0);
    CheckOptionRange("--target-removal-um", target_um, 0.0, 1e6);
    CheckOptionRange("--offset-mm", offset_mm, 0.1, 1000);
    CheckOptionRange("--radius-mm", radius_mm, 0.05, 1000);
    CheckOptionRange("--pitch-mm", pitch_mm, 0.01, 1000);
    CheckOptionRange("--opt-offset-max-mm", opt_offset_max_mm, 1.0, 1000);
    CheckOptionRange("--opt-offset-min-contact-widths", opt_offset_min_cw, 0.2, 10.0);
    if (optimise != "none" && pattern == "parallel" && optimise == "pso") {
      throw std::invalid_argument("--optimise pso applies to the cycloid; the parallel pattern is optimised with --optimise nlopt");
    }
    RequireReadableFile(surface_path, "surface");
    RequireReadableFile(process_path, "process file");
    std::vector<std::pair<std::string, std::string>> outs = {
        {"--path", path_out}, {"--removal", removal_out}, {"--summary", summary_out}};
    robot.Prepare(&outs);
    if (!plot_out.empty()) {
      for (const auto& p : PicturePaths(plot_out, optimise != "none")) outs.push_back({"--plot", p});
    }
    CheckDistinctPaths({{"--surface", surface_path}, {"--process", process_path}, {"--robot", robot.robot_path()}}, outs);

    if (list_faces) return ListFaces(surface_path, process_path, list_out, choice, pattern, radius_mm, sample_mm, offset_mm,
                                     pitch_mm, row_step_mm);
    if (!list_out.empty()) throw std::invalid_argument("--out goes with --list-faces");
    const polishing::PolishingProcess process = io::ReadPolishingProcess(process_path);
    const polishing::NurbsSurface surface = LoadSurface(kTool, surface_path, choice);
    {
      polishing::PathParameters p;
      p.pattern = pattern == "cycloid" ? polishing::Pattern::kCycloid : polishing::Pattern::kParallel;
      p.offset = MmToM(offset_mm);
      p.radius = MmToM(radius_mm);
      p.pitch = MmToM(pitch_mm);
      p.row_step = MmToM(row_step_mm);
      CheckFaceSize(surface, surface_path, sample_mm, p);
    }
    auto build_grid = [&](double spacing) {
      try {
        return polishing::SampleGrid::Build(surface, MmToM(spacing), process.margin, process.flip_normal);
      } catch (const std::domain_error& e) {
        throw InputError({surface_path, 0, 0}, e.what());
      }
    };
    const polishing::SampleGrid grid = build_grid(sample_mm);
    if (grid.num_in_region() == 0) {
      throw InputError({process_path, 0, 0}, "process.margin_mm " + io::FormatDouble(1e3 * process.margin) +
                                                 " leaves no polished region on " + polishing::SurfaceName(surface) +
                                                 " (" + Short(1e3 * grid.length_s()) + " x " +
                                                 Short(1e3 * grid.length_t()) + " mm, mean arc lengths along u and v)");
    }
    double contact_width = 0;
    try {
      contact_width = polishing::ContactWidthAtCentre(surface, grid, process);
    } catch (const std::domain_error& e) {
      throw InputError({surface_path, 0, 0}, std::string("at the centre of the region: ") + e.what());
    }
    const double cell = 0.5 * contact_width;  // index cell ~ the contact semi-axis
    const polishing::RemovalSimulator sim(surface, process, grid.points(), grid.normals(), cell);

    polishing::PathParameters params;
    params.pattern = pattern == "cycloid" ? polishing::Pattern::kCycloid : polishing::Pattern::kParallel;
    params.guides = guides == "offsets" ? polishing::GuideLines::kBoundaryOffsets : polishing::GuideLines::kParallelLines;
    params.offset = params.pattern == polishing::Pattern::kParallel && !offset_given ? contact_width : MmToM(offset_mm);
    params.radius = MmToM(radius_mm);
    params.pitch = MmToM(pitch_mm);
    params.row_step = MmToM(row_step_mm);
    params.edge_inset = edge_inset_mm < 0 ? -1.0 : MmToM(edge_inset_mm);
    polishing::CheckValid(params);  // std::invalid_argument -> exit 64, naming the limit
    if (optimise == "none" && params.pattern == polishing::Pattern::kCycloid) {
      // A face too narrow for the circle is an error in the input (exit 65),
      // never rows clamped onto its edges (PlanPath checks it again).
      try {
        polishing::CheckCircleFits(surface, grid, polishing::DevelopedRegion::Build(surface, grid, process.margin), params,
                                   process);
      } catch (const polishing::FaceTooNarrowError& e) {
        throw InputError({surface_path, 0, 0}, e.what());
      }
    }

    nlohmann::json opt_json;
    std::vector<double> history;
    if (optimise != "none") {
      const polishing::SampleGrid coarse = build_grid(opt_sample_mm);
      const polishing::RemovalSimulator coarse_sim(surface, process, coarse.points(), coarse.normals(), cell);
      polishing::PathParameters base = params;
      base.row_step = std::max(params.row_step, MmToM(opt_sample_mm));
      auto objective = [&](const polishing::PathParameters& p) {
        try {
          const polishing::RemovalStats st = Evaluate(surface, coarse, coarse_sim, p, process, surface_path).stats;
          // Planned at the speed limit, the path removes st.mean; if that is
          // more than the target, no speed within the limit reaches the target
          // (the path is too long for the time the target allows): infeasible,
          // for both patterns alike, ranked by how far it misses. 2 % margin
          // for the difference between the optimiser's grid and the final one.
          const double target = MmToM(1e-3 * target_um);
          if (target > 0 && st.mean > 0.98 * target) return 10.0 + st.mean / target;
          return st.cv;
        } catch (const std::invalid_argument&) {
          return 1e6;  // outside the feasibility limits
        }
      };
      polishing::OptimiseOptions defaults;
      ProgressLine progress(kTool, optimise == "pso" ? "PSO iterations" : "optimiser evaluations",
                            optimise == "pso" ? defaults.pso_max_iterations
                            : params.pattern == polishing::Pattern::kParallel
                                ? 27
                                : defaults.global_evaluations + defaults.local_evaluations);
      if (params.pattern == polishing::Pattern::kParallel) {
        // One parameter, the row spacing: golden section on [0.3, 1.5] contact widths.
        int evals = 0;
        // In units of contact widths, so the bracket tolerance (1e-3) is relative.
        auto f = [&](double w_rel) {
          polishing::PathParameters p = base;
          p.offset = w_rel * contact_width;
          const double cv = objective(p);
          history.push_back(history.empty() ? cv : std::min(history.back(), cv));
          progress.Update(++evals);
          return -cv;
        };
        const auto [w, fw] = GoldenSectionMaximum(f, 0.3, 1.5, 25, 1e-3);
        params.offset = w * contact_width;
        opt_json = {{"method", "golden-section search of the row spacing on [0.3, 1.5] contact widths"},
                    {"evaluations", evals}, {"best_cv", -fw}, {"status", "converged"}};
      } else {
        polishing::OptimiseOptions oo;
        oo.method = optimise == "nlopt" ? polishing::Optimiser::kNlopt : polishing::Optimiser::kPso;
        oo.offset_min = std::max(opt_offset_min_cw * contact_width, MmToM(0.5));
        oo.offset_max = std::max(oo.offset_min * 1.5, MmToM(opt_offset_max_mm));
        oo.seed = static_cast<unsigned>(seed);
        oo.progress = [&](int n, double) { progress.Update(n); };
        if (params.offset < oo.offset_min || params.offset > oo.offset_max) params.offset = std::clamp(params.offset, oo.offset_min, oo.offset_max);
        const polishing::OptimiseResult r = polishing::OptimiseCycloid(objective, base, oo);
        params.offset = r.best.offset;
        params.radius = r.best.radius;
        params.pitch = r.best.pitch;
        history = r.history;
        opt_json = {{"method", r.method}, {"evaluations", r.evaluations}, {"best_cv", r.best_value},
                    {"status", r.status}, {"sample_mm", opt_sample_mm},
                    {"bounds", {{"offset_mm", {1e3 * oo.offset_min, 1e3 * oo.offset_max}},
                                {"radius_over_offset", {0.5, 1.0}}, {"pitch_over_radius", {0.5, kPi}}}}};
      }
      progress.Finish();
      opt_json["history"] = history;
    }

    Evaluated e = Evaluate(surface, grid, sim, params, process, surface_path);
    nlohmann::json target_json;
    bool flagged = false;
    if (target_um > 0) {
      const polishing::TargetResult t =
          polishing::ScaleToTargetRemoval(sim, grid, target_um * 1e-6, process.max_speed, &e.path);
      e.removal = t.removal;
      e.stats = polishing::ComputeRemovalStats(e.removal, grid.areas(), grid.in_region());
      target_json = {{"removal_um", target_um}, {"reached", t.reached}};
      if (!t.reached) {
        flagged = true;
        target_json["message"] = t.message;
        Warn(kTool, t.message);
      }
    }
    const bool cyc = params.pattern == polishing::Pattern::kCycloid;
    nlohmann::json summary;
    summary["removal_um"] = RemovalJson(e.stats);
    summary["path"] = PathJson(e.path.rows);
    summary["parameters"] = {{"pattern", pattern},
                             {"guides", cyc ? guides : "parallel"},
                             {"offset_mm", 1e3 * params.offset},
                             {"radius_mm", cyc ? 1e3 * params.radius : 0.0},
                             {"pitch_mm", cyc ? 1e3 * params.pitch : 0.0},
                             {"omega_rad_per_s", cyc ? e.path.omega_rad_per_s : 0.0},
                             {"centre_speed_mm_per_s", cyc ? 1e3 * e.path.centre_speed : 0.0}};
    summary["region"] = {{"sample_mm", sample_mm}, {"points", grid.num_in_region()}, {"margin_mm", 1e3 * process.margin}};
    ReportUnpolished(kTool, e.stats, grid, &summary["region"]);
    if (surface.trim()) {
      // The guide lines follow the trimmed outline and the holes, and links
      // that would cross a hole are lifted; a row in contact off the face
      // would be a planner bug, or the developed plane's distortion on a
      // strongly doubly curved face (README "CAD faces").
      const int off = RowsOffFace(surface, e.path.rows);
      summary["region"]["face"] = surface.trim()->source;
      summary["region"]["rows_off_face"] = off;
      if (off > 0) {
        flagged = true;
        Warn(kTool, std::to_string(off) + " path rows lie off the trimmed face (in a hole or outside its boundary)");
      }
    }
    summary["contact"] = {{"width_across_mm", 1e3 * contact_width}};
    if (!target_json.is_null()) summary["target"] = target_json;
    if (!opt_json.is_null()) summary["optimisation"] = opt_json;
    if (e.stats.coverage < 0.99) {
      Warn(kTool, "coverage " + io::FormatDouble(e.stats.coverage) + " < 0.99: parts of the region are barely polished");
    }

    if (robot.Check(kTool, process, e.path.rows, &summary)) flagged = true;
    std::vector<std::pair<std::string, std::string>> meta = {{"pattern", pattern}};
    meta.push_back({"offset_mm", io::FormatDouble(1e3 * params.offset)});
    if (cyc) {
      meta.push_back({"radius_mm", io::FormatDouble(1e3 * params.radius)});
      meta.push_back({"pitch_mm", io::FormatDouble(1e3 * params.pitch)});
    }
    if (!path_out.empty()) io::WritePolishPath(path_out, e.path.rows, meta);
    if (!removal_out.empty()) io::WriteRemovalMap(removal_out, grid, e.removal);
    robot.WriteJoints(e.path.rows);
    if (!plot_out.empty()) WritePictures(plot_out, grid, e.removal, e.path.rows, e.path.guide_lines_st, history, pattern);
    const std::string text = summary.dump(2) + "\n";
    if (!summary_out.empty()) io::WriteFileAtomically(summary_out, text);
    else std::cout << text;
    return flagged ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
