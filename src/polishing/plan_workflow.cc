#include "robomach/polishing/plan_workflow.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/common/named_registry.h"
#include "robomach/common/number_format.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/units.h"
#include "robomach/polishing/face_check.h"
#include "robomach/polishing/path_patterns.h"
#include "robomach/polishing/region_outline.h"

namespace robomach::polishing {
namespace {

std::shared_ptr<const SampleGrid> BuildGrid(const NurbsSurface& surface, const PolishingProcess& process,
                                            double spacing, const std::string& surface_source) {
  return AtLocation<std::domain_error>({surface_source, 0, 0}, "", [&] {
    return std::make_shared<const SampleGrid>(SampleGrid::Build(surface, spacing, process.margin, process.flip_normal));
  });
}

// The pattern runs its tool around a circle (the cycloid): it needs room
// at the face's edge, and it is the one compared with the zig-zag.
bool PathPatternCircles(const PathParameters& p) { return PathPatternOf(p.pattern).circle_radius(p) > 0.0; }

}  // namespace

int RowsOffFace(const NurbsSurface& surface, const std::vector<PathRow>& rows) {
  int n = 0;
  for (const auto& r : rows) n += r.force != 0.0 && !surface.OnFace(r.u, r.v);  // lifted rows may cross holes
  return n;
}

PlanningContext PreparePlanning(const NurbsSurface& surface, const PolishingProcess& process, double sample_spacing,
                                const std::string& surface_source, const std::string& process_source) {
  PlanningContext c;
  c.surface = &surface;
  c.process = process;
  c.sample_spacing = sample_spacing;
  c.surface_source = surface_source;
  c.process_source = process_source;
  c.grid = BuildGrid(surface, process, sample_spacing, surface_source);
  if (c.grid->num_in_region() == 0) {
    throw InputError({process_source, 0, 0}, "process.margin_mm " + FormatDouble(1e3 * process.margin) +
                                                 " leaves no polished region on " + SurfaceName(surface) + " (" +
                                                 FormatNumber(1e3 * c.grid->length_s(), 4) + " x " +
                                                 FormatNumber(1e3 * c.grid->length_t(), 4) + " mm, mean arc lengths along u and v)");
  }
  try {
    c.contact_width = ContactWidthAtCentre(surface, *c.grid, process);
  } catch (const std::domain_error& e) {
    // A spot too concave for the wheel is the surface's.
    if (std::string(e.what()).find("exceeds belt_width_mm") == std::string::npos) {
      throw InputError({surface_source, 0, 0}, std::string("at the centre of the region: ") + e.what());
    }
    // The process presses the contact wider than its belt: the process
    // file's numbers are the cause, not the surface (issue #35).
    throw InputError({process_source, 0, 0},
                     "process.force_N " + FormatNumber(process.force, 6) + " N on a pad of pad_modulus_MPa " +
                         FormatNumber(1e-6 * process.pad_modulus, 6) +
                         " presses a contact wider than the belt at the centre of the region of " + surface_source +
                         " (" + e.what() + "): a force too large for this belt (kN or mN typed in the N field? belts press 1 - 200 N), "
                         "a pad modulus too small (kPa typed for MPa?), or the belt's width mistyped");
  }
  const double cell = 0.5 * c.contact_width;  // index cell ~ the contact semi-axis
  c.simulator = std::make_shared<const RemovalSimulator>(surface, process, c.grid->points(), c.grid->normals(), cell);
  return c;
}

EvaluatedPlan EvaluatePlanOnGrid(const PlanningContext& c, const PathParameters& params) {
  EvaluatedPlan e;
  e.path = PlanPath(*c.surface, *c.grid, params, c.process);
  try {
    e.removal = c.simulator->Simulate(e.path.rows);
  } catch (const PathRowError& err) {
    const auto& r = e.path.rows[err.row()];
    std::ostringstream m;
    m << "planned path row " << err.row() + 1 << " at (" << 1e3 * r.p.x() << ", " << 1e3 * r.p.y() << ", "
      << 1e3 * r.p.z() << ") mm (u " << r.u << ", v " << r.v << "): " << err.what();
    throw InputError({c.surface_source, 0, 0}, m.str());
  }
  e.stats = ComputeRemovalStats(e.removal, c.grid->areas(), c.grid->in_region());
  return e;
}

std::vector<PlanOptionRange> PlanOptionRanges(const PlanOptions& o) {
  return {{"sample_mm", o.sample_mm, 0.05, 0.5},
          {"row_step_mm", o.row_step_mm, 0.05, 5.0},
          {"opt_sample_mm", o.opt_sample_mm, 0.1, 5.0},
          {"target_removal_um", o.target_removal_um, 0.0, 1e6},
          {"offset_mm", o.offset_mm.value_or(8.0), 0.1, 1000},
          {"radius_mm", o.radius_mm, 0.05, 1000},
          {"pitch_mm", o.pitch_mm, 0.01, 1000},
          {"opt_offset_max_mm", o.opt_offset_max_mm, 1.0, 1000},
          {"opt_offset_min_contact_widths", o.opt_offset_min_contact_widths, 0.2, 10.0},
          {"stagger_loops", o.stagger_loops, 0.0, 1.0},
          {"edge_overrun_mm", o.edge_overrun_mm, 0.0, 1000.0},
          {"line_angle_deg", o.line_angle_deg, -360.0, 360.0},
          {"max_time_s", o.max_time_s, 1.0, 86400.0},
          {"threads", static_cast<double>(o.threads), 1, 64}};
}

void CheckRanges(const PlanOptions& o) {
  for (const PlanOptionRange& r : PlanOptionRanges(o)) {
    CheckOptionRange(r.name, r.value, r.lo, r.hi);
  }
}

std::vector<std::string> ImplausiblePlanOptions(const PlanOptions& o) {
  std::vector<std::string> out;
  // The one angle option: radians typed under _deg (1.5708 for 90 deg), as
  // the files' _deg fields are checked (a value within one turn, not whole).
  if (const double a = o.line_angle_deg; a != 0.0 && std::abs(a) <= 2 * kPi && a != std::floor(a)) {
    out.push_back("implausible (unit mistake?): line_angle_deg " + FormatNumber(a, 7) +
                  " deg is within 2 pi = 6.28 and not whole, as radians are: radians typed in the deg option? (" +
                  FormatNumber(a, 7) + " rad is " + FormatNumber(a * 180.0 / kPi, 4) + " deg)");
  }
  const double t = o.target_removal_um;
  if (t != 0.0 && !(t >= kMinPlausibleTargetRemovalUm && t <= kMaxPlausibleTargetRemovalUm)) {
    out.push_back("implausible (unit mistake?): target_removal_um " + FormatNumber(t, 7) +
                  " um is outside the " + FormatNumber(kMinPlausibleTargetRemovalUm, 7) + " to " +
                  FormatNumber(kMaxPlausibleTargetRemovalUm, 7) +
                  " um of one polishing or belt-grinding pass (polishing 0.1 - 10 um, belt grinding up to 500 um): " +
                  (t > kMaxPlausibleTargetRemovalUm ? "a removal in nm typed in the um option (5 um is 5, not 5000)?"
                                                    : "a removal in mm typed in the um option (5 um is 5, not 0.005)?"));
  }
  return out;
}

void PlanOptions::Validate() const {
  // A name parser's refusal as the option's error (the same message).
  const auto as_option = [](const std::string& field, const auto& parse) {
    try {
      parse();
    } catch (const std::invalid_argument& e) {
      throw OptionError(field, e.what());
    }
  };
  as_option("guides", [&] { ParseGuideLines(guides); });
  // "none" or a name of the enum's one list (optimise.h: kOptimisers).
  std::vector<std::string> optimisers{"none"};
  for (Optimiser m : kOptimisers) optimisers.push_back(ToString(m));
  if (std::find(optimisers.begin(), optimisers.end(), optimise) == optimisers.end()) {
    throw OptionError("optimise", "optimise: expected " + NameListOf(optimisers) + ", got " + optimise);
  }
  as_option("pattern", [&] { ParsePattern(pattern); });
  if (optimise == ToString(Optimiser::kPso) && ParsePattern(pattern) != Pattern::kCycloid) {
    throw OptionError("optimise", "optimise pso applies to the cycloid; the parallel pattern is optimised with nlopt");
  }
  CheckRanges(*this);
}

PlanRequest ToPlanRequest(const PlanOptions& o, const PlanningContext& c) {
  o.Validate();
  PlanRequest req;
  PathParameters& params = req.params;
  params.pattern = ParsePattern(o.pattern);
  params.guides = ParseGuideLines(o.guides);
  params.offset = o.offset_mm ? MmToM(*o.offset_mm) : params.pattern == Pattern::kParallel ? c.contact_width : MmToM(8.0);
  params.radius = MmToM(o.radius_mm);
  params.pitch = MmToM(o.pitch_mm);
  params.row_step = MmToM(o.row_step_mm);
  params.edge_inset = o.edge_inset_mm < 0 ? -1.0 : MmToM(o.edge_inset_mm);
  params.stagger = o.stagger_loops;
  params.edge_overrun = MmToM(o.edge_overrun_mm);
  params.line_angle = o.line_angle_deg * kPi / 180.0;
  CheckValid(params);
  req.target_removal = o.target_removal_um * 1e-6;  // [um] -> [m]
  if (o.optimise != "none") req.optimise = ParseOptimiser(o.optimise);
  req.guides_given = o.guides_given;
  req.opt_sample_spacing = MmToM(o.opt_sample_mm);
  req.opt_offset_min_contact_widths = o.opt_offset_min_contact_widths;
  req.opt_offset_max = MmToM(o.opt_offset_max_mm);
  req.max_time_s = o.max_time_s;
  req.threads = o.threads;
  req.seed = o.seed;
  return req;
}

PlanOutcome PlanPolishing(const PlanningContext& c, const PlanRequest& req) {
  const NurbsSurface& surface = *c.surface;
  const SampleGrid& grid = *c.grid;
  PlanOutcome out;
  PathParameters params = req.params;
  if (!req.optimise && PathPatternCircles(params)) {
    // A face too narrow for the circle is an error in the input, never
    // rows clamped onto its edges (PlanPath checks it again).
    AtLocation<FaceTooNarrowError>({c.surface_source, 0, 0}, "", [&] {
      CheckCircleFits(surface, grid, DevelopedRegion::Build(surface, grid, c.process.margin), params, c.process);
    });
  }

  if (req.optimise) {
    const std::shared_ptr<const SampleGrid> coarse = BuildGrid(surface, c.process, req.opt_sample_spacing, c.surface_source);
    const RemovalSimulator coarse_sim(surface, c.process, coarse->points(), coarse->normals(), 0.5 * c.contact_width);
    PathParameters base = params;
    base.row_step = std::max(params.row_step, req.opt_sample_spacing);
    PlanProblem pb;
    pb.surface = &surface;
    pb.grid = coarse.get();
    pb.sim = &coarse_sim;
    pb.process = &c.process;
    pb.target = req.target_removal;
    pb.contact_width = c.contact_width;
    PlanOptimiseOptions oo;
    oo.method = *req.optimise;
    oo.pattern = params.pattern;
    if (req.guides_given) {
      // The user chose the family: offsets, or parallel lines (both directions).
      if (params.guides == GuideLines::kBoundaryOffsets) oo.families = {{params.guides, 0.0}};
      else oo.families = {{params.guides, 0.0}, {params.guides, kPi / 2}};
    }
    oo.offset_min = std::max(req.opt_offset_min_contact_widths * c.contact_width, MmToM(0.5));
    oo.offset_max = std::max(oo.offset_min * 1.5, req.opt_offset_max);
    oo.max_time_s = req.max_time_s;
    oo.threads = req.threads;
    oo.seed = req.seed;
    oo.progress = req.progress;
    if (params.offset < oo.offset_min || params.offset > oo.offset_max) {
      base.offset = std::clamp(base.offset, oo.offset_min, oo.offset_max);
      base.radius = std::clamp(base.radius, 0.5 * base.offset, base.offset);
    }
    out.opt_offset_min = oo.offset_min;
    out.opt_offset_max = oo.offset_max;
    PlanOptimiseResult opt = AtLocation<PathRowError>({c.surface_source, 0, 0}, "while optimising: ",
                                                      [&] { return OptimisePlan(pb, base, oo); });
    if (!opt.best.valid) throw std::runtime_error("the optimiser found no plan that fits the region: " + opt.best.error);
    const double row_step = params.row_step;
    params = opt.best.params;
    params.row_step = row_step;
    // The convergence history: the optimised pattern's evaluations only (the
    // zig-zag's, made for the comparison, are in the counts).
    double best_so_far = std::numeric_limits<double>::quiet_NaN();
    for (size_t i = 0; i < opt.cv_history.size(); ++i) {
      const bool par = opt.history_parallel[i] != 0;
      if (par != (params.pattern == Pattern::kParallel)) continue;
      const double cv = opt.cv_history[i];
      if (std::isfinite(cv) && !(cv >= best_so_far)) best_so_far = cv;
      out.history_cv.push_back(cv);
      out.history_best.push_back(best_so_far);
    }
    if (!opt.best.feasible) {
      out.infeasible_message =
          req.target_removal > 0
              ? "no plan the optimiser saw reaches the target removal " + FormatNumber(1e6 * req.target_removal, 12) +
                    " um within max_speed_mm_per_s and covers the region: every covering one removes more at the "
                    "limit (written: the least infeasible, " + FormatDouble(1e6 * opt.best.mean) +
                    " um at the limit, coverage " + FormatDouble(opt.best.coverage) + ")"
              : "the optimiser found no feasible plan";
      out.verdict.Flag(out.infeasible_message);
    }
    out.optimisation = std::move(opt);
  }

  out.params = params;
  out.plan = EvaluatePlanOnGrid(c, params);
  if (req.target_removal > 0) {
    out.target_given = true;
    out.target = ScaleToTargetRemoval(*c.simulator, grid, req.target_removal, c.process.max_speed, &out.plan.path);
    out.plan.removal = out.target.removal;
    out.plan.stats = ComputeRemovalStats(out.plan.removal, grid.areas(), grid.in_region());
    if (!out.target.reached) out.verdict.Flag(out.target.message);
  }
  if (PathPatternCircles(params) && out.optimisation && out.optimisation->best_parallel.valid) {
    // The cycloid against the optimised zig-zag, both on the final grid
    // and timed for the target as the written path is (issue 19).
    PlanOutcome::Comparison cmp;
    cmp.parallel = out.optimisation->best_parallel.params;
    cmp.parallel.row_step = params.row_step;
    EvaluatedPlan z = EvaluatePlanOnGrid(c, cmp.parallel);
    cmp.parallel_stats = z.stats;
    if (req.target_removal > 0) {
      const TargetResult t = ScaleToTargetRemoval(*c.simulator, grid, req.target_removal, c.process.max_speed, &z.path);
      cmp.parallel_stats = ComputeRemovalStats(t.removal, grid.areas(), grid.in_region());
      cmp.parallel_reaches_target = t.reached;
    }
    const bool cycloid_ok = !out.target_given || out.target.reached;
    cmp.zigzag_better = (cmp.parallel_reaches_target && !cycloid_ok) ||
                        (cmp.parallel_reaches_target == cycloid_ok && cmp.parallel_stats.cv < out.plan.stats.cv);
    if (cmp.zigzag_better) {
      const polishing::PathParameters& pp = cmp.parallel;
      out.verdict.Flag("the optimised zig-zag is better than the optimised cycloid: cv " + FormatDouble(cmp.parallel_stats.cv) +
               (cmp.parallel_reaches_target ? "" : " (target not reached)") + " against " +
               FormatDouble(out.plan.stats.cv) + (cycloid_ok ? "" : " (target not reached)") +
               "; plan it as pattern parallel, offset " + FormatDouble(1e3 * pp.offset) + " mm, line angle " +
               FormatDouble(pp.line_angle * 180.0 / kPi) + " deg, edge overrun " + FormatDouble(1e3 * pp.edge_overrun) +
               " mm");
    }
    out.comparison = cmp;
  }
  if (surface.trim()) {
    out.rows_off_face = RowsOffFace(surface, out.plan.path.rows);
    if (out.rows_off_face > 0) {
      out.verdict.Flag(std::to_string(out.rows_off_face) +
               " path rows lie off the trimmed face (in a hole or outside its boundary)");
    }
  }
  return out;
}

}  // namespace robomach::polishing
