#include "robomach/workflows/polish_simulation.h"

#include "robomach/io/csv_table.h"
#include "robomach/io/polishing_summary.h"

#include <algorithm>
#include <cmath>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/polishing/optimise.h"
#include "robomach/polishing/paths.h"

namespace robomach::workflows {

PolishSimulation SimulatePolishPathFile(const polishing::NurbsSurface& surface,
                                        const polishing::PolishingProcess& process, const std::string& path_file,
                                        double sample_spacing, const std::string& surface_source,
                                        const std::string& process_source) {
  PolishSimulation s;
  s.file = io::ReadPolishPath(path_file);
  s.grid = AtLocation<std::domain_error>({surface_source, 0, 0}, "", [&] {
    return std::make_shared<const polishing::SampleGrid>(
        polishing::SampleGrid::Build(surface, sample_spacing, process.margin, process.flip_normal));
  });
  if (s.grid->num_in_region() == 0) {
    throw InputError({process_source, 0, 0}, "process.margin_mm leaves no polished region on the patch");
  }
  try {
    polishing::AttachToSurface(surface, *s.grid, process.flip_normal, &s.file.rows);
    const polishing::RemovalSimulator sim(surface, process, s.grid->points(), s.grid->normals(), 0.0015);
    s.removal = sim.Simulate(s.file.rows);
  } catch (const polishing::PathRowError& e) {
    throw InputError({s.file.path, s.file.lines[e.row()], 0}, "path row " + std::to_string(e.row() + 1) + ": " + e.what());
  }
  s.max_speed = polishing::MaxSpeed(s.file.rows);
  // Flag a segment only if it is too fast even when its length is read as
  // short as the file's rounding allows: polish-plan writes positions to
  // 1e-4 mm, so each end may be off by 0.5e-7 m per coordinate (a path
  // timed exactly at the limit read 50.01 mm/s on 0.5 mm rows).
  constexpr double kRounding = 2 * 0.5e-7 * 1.7320508075688772;  // [m]
  double v_sure = 0.0;
  for (size_t i = 1; i < s.file.rows.size(); ++i) {
    const double len = (s.file.rows[i].p - s.file.rows[i - 1].p).norm();
    v_sure = std::max(v_sure, std::max(0.0, len - kRounding) / (s.file.rows[i].t - s.file.rows[i - 1].t));
  }
  s.speed_limit_exceeded = v_sure > process.max_speed * (1 + 1e-6);
  if (s.speed_limit_exceeded) {
    s.verdict.Flag("the path's traverse speed reaches " + FormatDouble(1e3 * s.max_speed) + " mm/s, above max_speed_mm_per_s " +
           FormatDouble(1e3 * process.max_speed));
  }
  // Times in milliseconds under the t_s header (issue #35: the planner's
  // path with t in ms removed 2.3 mm on average, exit 0): no segment then
  // moves faster than a thousandth of what the process allows.
  if (s.max_speed > 0.0 && s.max_speed < 1e-2 * process.max_speed &&
      1e3 * s.max_speed <= process.max_speed * (1 + 1e-6)) {
    s.verdict.Flag("implausible (unit mistake?): " + s.file.path + ": the tool never moves faster than " +
           FormatNumber(1e3 * s.max_speed, 3) + " mm/s, under 1 % of max_speed_mm_per_s " +
           FormatNumber(1e3 * process.max_speed, 3) + " (the path takes " + FormatNumber(s.file.rows.back().t, 4) +
           " s): times in ms under the t_s header? (A deliberately slow path is flagged too.)");
  }
  s.stats = polishing::ComputeRemovalStats(s.removal, s.grid->areas(), s.grid->in_region());
  // A path that cannot be this surface's (issue #35: a path in metres under
  // the _mm headers polished nothing, exit 0): its extent against the
  // region's, and a region left untouched.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo, glo = lo, ghi = -lo;
  for (const auto& row : s.file.rows) {
    lo = lo.cwiseMin(row.p);
    hi = hi.cwiseMax(row.p);
  }
  const std::vector<Eigen::Vector3d>& pts = s.grid->points();
  const auto& in_region = s.grid->in_region();
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!in_region.empty() && !in_region[i]) continue;
    glo = glo.cwiseMin(pts[i]);
    ghi = ghi.cwiseMax(pts[i]);
  }
  const double path_span = s.file.rows.empty() ? 0.0 : (hi - lo).norm(), region_span = (ghi - glo).norm();
  if (s.file.rows.size() >= 2 && region_span > 0.0 && path_span < 0.01 * region_span) {
    s.verdict.Flag("implausible (unit mistake?): " + s.file.path + ": the path spans " + FormatNumber(1e3 * path_span, 3) +
           " mm, under 1 % of the " + FormatNumber(1e3 * region_span, 4) + " mm across the surface " + surface_source +
           ": positions in m under the _mm headers (or a path for another part)? (A spot or dwell test this "
           "small is flagged too.)");
  } else if (!(s.stats.coverage > 0.0)) {
    s.verdict.Flag(s.file.path + ": the path polishes none of the region of " + surface_source +
           " (coverage 0): a path for another part, or in another frame?");
  }
  return s;
}

io::PathFigures PathFiguresOf(const std::vector<polishing::PathRow>& rows) {
  io::PathFigures f;
  f.contact_length_m = polishing::ContactLength(rows);
  f.lifts = polishing::CountLifts(rows);
  f.time_s = rows.empty() ? 0.0 : rows.back().t - rows.front().t;
  f.rows = rows.size();
  f.max_speed_m_per_s = polishing::MaxSpeed(rows);
  return f;
}

double EdgeOverrunUsed(const polishing::PathParameters& params, const polishing::PolishingProcess& process) {
  return std::min(params.edge_overrun, polishing::MaxEdgeOverrun(params, process));
}

io::PlanFigures PlanFiguresOf(const polishing::PlanOutcome& outcome, const polishing::PolishingProcess& process) {
  io::PlanFigures f;
  f.path = PathFiguresOf(outcome.plan.path.rows);
  f.edge_overrun_m = EdgeOverrunUsed(outcome.params, process);
  if (outcome.optimisation) {
    const polishing::PlanOptimiseResult& opt = *outcome.optimisation;
    f.best_edge_overrun_m = EdgeOverrunUsed(opt.best.params, process);
    for (const polishing::PlanEvaluation& e : opt.family_best) {
      f.family_edge_overrun_m.push_back(EdgeOverrunUsed(e.params, process));
    }
    if (opt.best_parallel.valid) f.parallel_edge_overrun_m = EdgeOverrunUsed(opt.best_parallel.params, process);
  }
  return f;
}

std::vector<std::pair<std::string, std::string>> PlannedPathMetadata(const polishing::PathParameters& params,
                                                                     const polishing::PolishingProcess& process) {
  return io::PlannedPathMetadata(params, EdgeOverrunUsed(params, process));
}

nlohmann::json PolishSimSummaryJson(const PolishSimulation& sim, const polishing::PolishingProcess& process,
                                    double sample_mm) {
  const io::PolishPathFile& file = sim.file;
  nlohmann::json summary;
  summary["removal_um"] = io::RemovalSummaryJson(sim.stats);
  summary["path"] = io::PathSummaryJson(PathFiguresOf(file.rows));
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
  summary["region"] = io::RegionSummaryJson(*sim.grid, sim.stats, sample_mm, process);
  summary["speed_limit_exceeded"] = sim.speed_limit_exceeded;
  return summary;
}

}  // namespace robomach::workflows
