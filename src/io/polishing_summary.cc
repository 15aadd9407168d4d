#include "robomach/io/polishing_summary.h"

#include <algorithm>
#include <cmath>

#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"
#include "robomach/polishing/optimise.h"
#include "robomach/polishing/path_patterns.h"

namespace robomach::io {
namespace {

// `edge_overrun_m`: the one the evaluation's plan used (PlanFigures).
nlohmann::json FamilyJson(const polishing::PlanEvaluation& ev, double edge_overrun_m) {
  const bool c = ev.params.pattern == polishing::Pattern::kCycloid;
  nlohmann::json j = {
      {"pattern", polishing::PathPatternOf(ev.params.pattern).name()},
      {"guides", c ? polishing::FamilyName({ev.params.guides, ev.params.line_angle})
                   : polishing::FamilyName({polishing::GuideLines::kParallelLines, ev.params.line_angle})},
      {"offset_mm", 1e3 * ev.params.offset},
      {"line_angle_deg", ev.params.line_angle * 180.0 / kPi},
      {"edge_overrun_mm", 1e3 * edge_overrun_m},
      {"cv", ev.cv},
      {"mean_at_max_speed_um", 1e6 * ev.mean},
      {"coverage", ev.coverage},
      {"feasible", ev.feasible}};
  if (c) {
    j["radius_mm"] = 1e3 * ev.params.radius;
    j["pitch_mm"] = 1e3 * ev.params.pitch;
    j["stagger_loops"] = ev.params.stagger;
  }
  return j;
}

nlohmann::json OptimisationJson(const polishing::PlanOutcome& outcome, const PlanFigures& figures,
                                const polishing::PlanOptions& options) {
  const polishing::PlanOptimiseResult& opt = *outcome.optimisation;
  nlohmann::json j = {{"method", opt.method},
                      {"evaluations", opt.evaluations},
                      {"seconds", opt.seconds},
                      {"max_time_s", options.max_time_s},
                      {"status", robomach::ToString(opt.status)},
                      {"stop_reason", opt.stop_reason},
                      {"local_searches", opt.local_searches},
                      {"local_searches_converged", opt.local_converged},
                      {"sample_mm", options.opt_sample_mm},
                      {"best_cv", opt.best.cv},
                      {"feasible", opt.best.feasible},
                      {"best", FamilyJson(opt.best, figures.best_edge_overrun_m)}};
  j["history"] = outcome.history_best;   // best feasible cv so far (null before the first)
  j["history_cv"] = outcome.history_cv;  // each evaluation's cv (null: infeasible)
  if (outcome.params.pattern == polishing::Pattern::kCycloid) {
    j["bounds"] = {{"offset_mm", {1e3 * outcome.opt_offset_min, 1e3 * outcome.opt_offset_max}},
                   {"radius_over_offset", {0.5, 1.0}},
                   {"pitch_over_radius", {0.5, kPi}},
                   {"stagger_loops", {0.0, 1.0}},
                   {"edge_overrun_over_its_largest", {0.0, 1.0}}};
    nlohmann::json fams = nlohmann::json::array();
    for (size_t i = 0; i < opt.family_best.size(); ++i) {
      fams.push_back(FamilyJson(opt.family_best[i], figures.family_edge_overrun_m.at(i)));
    }
    j["families"] = fams;
    if (opt.best_parallel.valid) j["parallel"] = FamilyJson(opt.best_parallel, figures.parallel_edge_overrun_m);
  }
  if (!outcome.infeasible_message.empty()) j["message"] = outcome.infeasible_message;
  return j;
}

}  // namespace

nlohmann::json RemovalSummaryJson(const polishing::RemovalStats& s) {
  return {{"mean", 1e6 * s.mean}, {"std", 1e6 * s.std}, {"variance", 1e12 * s.variance}, {"cv", s.cv},
          {"min", 1e6 * s.min}, {"max", 1e6 * s.max}, {"peak_to_valley", 1e6 * s.peak_to_valley},
          {"coverage", s.coverage}};
}

nlohmann::json PathSummaryJson(const PathFigures& f) {
  return {{"length_mm", 1e3 * f.contact_length_m},
          {"lifts", f.lifts},
          {"time_s", f.time_s},
          {"rows", f.rows},
          {"max_speed_mm_per_s", 1e3 * f.max_speed_m_per_s}};
}

nlohmann::json RegionSummaryJson(const polishing::SampleGrid& grid, const polishing::RemovalStats& stats,
                                 double sample_mm, const polishing::PolishingProcess& process) {
  nlohmann::json j = {{"sample_mm", sample_mm}, {"points", grid.num_in_region()}, {"margin_mm", 1e3 * process.margin}};
  j["area_mm2"] = 1e6 * grid.region_area();
  j["unpolished_area_mm2"] = 1e6 * stats.unpolished_area;
  return j;
}

nlohmann::json PolishPlanSummaryJson(const polishing::PlanOutcome& outcome, const polishing::PlanningContext& ctx,
                                     const polishing::PlanOptions& options, const PlanFigures& figures) {
  const polishing::PathParameters& params = outcome.params;
  const polishing::PolishingProcess& process = ctx.process;
  const polishing::EvaluatedPlan& e = outcome.plan;
  const bool cyc = params.pattern == polishing::Pattern::kCycloid;
  nlohmann::json summary;
  if (outcome.comparison) {
    const polishing::PlanOutcome::Comparison& cmp = *outcome.comparison;
    const polishing::PathParameters& pp = cmp.parallel;
    summary["comparison"] = {{"cycloid_cv", e.stats.cv},
                             {"parallel_cv", cmp.parallel_stats.cv},
                             {"parallel_offset_mm", 1e3 * pp.offset},
                             {"parallel_line_angle_deg", pp.line_angle * 180.0 / kPi},
                             {"parallel_reaches_target", cmp.parallel_reaches_target},
                             {"better", cmp.zigzag_better ? "parallel" : "cycloid"}};
  }
  summary["removal_um"] = RemovalSummaryJson(e.stats);
  summary["path"] = PathSummaryJson(figures.path);
  // The zig-zag's rows are parallel lines whatever guides says.
  const std::string guides_used = polishing::ToString(cyc ? params.guides : polishing::GuideLines::kParallelLines);
  summary["parameters"] = {
      {"pattern", options.pattern},
      {"guides", guides_used},
      {"line_angle_deg", params.line_angle * 180.0 / kPi},
      {"stagger_loops", cyc ? params.stagger : 0.0},
      {"edge_overrun_mm", 1e3 * figures.edge_overrun_m},
      {"offset_mm", 1e3 * params.offset},
      {"radius_mm", cyc ? 1e3 * params.radius : 0.0},
      {"pitch_mm", cyc ? 1e3 * params.pitch : 0.0},
      {"omega_rad_per_s", cyc ? e.path.omega_rad_per_s : 0.0},
      {"centre_speed_mm_per_s", cyc ? 1e3 * e.path.centre_speed : 0.0}};
  summary["region"] = RegionSummaryJson(*ctx.grid, e.stats, options.sample_mm, process);
  if (ctx.surface != nullptr && ctx.surface->trim()) {
    // The guide lines follow the trimmed outline and the holes, and links
    // that would cross a hole are lifted; a row in contact off the face
    // would be a planner bug, or the developed plane's distortion on a
    // strongly doubly curved face (README "CAD faces").
    summary["region"]["face"] = ctx.surface->trim()->source;
    summary["region"]["rows_off_face"] = outcome.rows_off_face;
  }
  summary["contact"] = {{"width_across_mm", 1e3 * ctx.contact_width}};
  if (outcome.target_given) {
    nlohmann::json target = {{"removal_um", options.target_removal_um}, {"reached", outcome.target.reached}};
    if (!outcome.target.reached) target["message"] = outcome.target.message;
    summary["target"] = target;
  }
  if (outcome.optimisation) summary["optimisation"] = OptimisationJson(outcome, figures, options);
  return summary;
}

}  // namespace robomach::io
