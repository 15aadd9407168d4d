#include "robomach/workflows/stability_map.h"

#include <cmath>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::workflows {

void StabilityMapOptions::Validate() const {
  if (region_path.empty()) {
    throw OptionError("region_path", "region_path is required (with path_path it gives the seed posture and rotation)");
  }
  ValidateSettings();
}

void StabilityMapOptions::ValidateSettings() const {
  // 10 m of depth of cut is no cut (and a search up to 1e30 mm loses the
  // boundary in its bisection); stability-lobes bounds sd_max_depth_mm alike.
  if (!(max_depth_mm > 0.0 && max_depth_mm <= 1e4)) {
    throw OptionError("max_depth_mm", "max_depth_mm " + FormatNumber(max_depth_mm) +
                                          ": expected a depth > 0 and at most 10000 mm");
  }
  // Bounds that keep a typo from spawning 1e5 threads or hours of work.
  if (speeds < 0 || speeds > 100000) {
    throw OptionError("speeds", "speeds " + std::to_string(speeds) + ": expected 0 to 100000");
  }
  if (rotation_evaluations < 8) {
    throw OptionError("rotation_evaluations",
                      "rotation_evaluations " + std::to_string(rotation_evaluations) + ": expected >= 8");
  }
  if (threads < 0 || threads > 256) {
    throw OptionError("threads", "threads " + std::to_string(threads) + ": expected 0 to 256");
  }
  uncertainty.Validate();  // its fields are the tool's (confidence ...): unprefixed
}

std::string StabilityMapRun::Where(long k) const {
  return points.grid ? "row " + std::to_string(k / points.cols) + ", col " + std::to_string(k % points.cols)
                     : "point " + std::to_string(k + 1) + " of the path";
}

StabilityMapRun RunStabilityMap(const StabilityMapOptions& o, const MessageSink& tell, const StageProgress& progress) {
  o.Validate();
  StabilityMapRun r;
  r.config = workflows::LoadRobotConfigChecked(o.robot_path);
  for (const std::string& w : r.config.implausible) {
    Tell(tell, Message::Kind::kWarning, w);
    r.input_findings.push_back(w);
  }
  r.uncertainty_files = o.uncertainty_paths.empty() ? r.config.uncertainty_files : o.uncertainty_paths;
  const std::optional<dynamics::ParameterUncertainty> uncertainty =
      UseUncertaintyFiles(r.uncertainty_files, {}, &r.config, tell);
  const auto model = r.config.Build();
  r.num_joints = model->num_joints();
  r.cut = io::ReadCutFile(o.cut_path);
  for (const std::string& w : r.cut.implausible) {
    Tell(tell, Message::Kind::kWarning, w);
    r.input_findings.push_back(w);
  }
  r.region = io::ReadRegionFile(o.region_path, model->num_joints());
  for (const std::string& w : r.region.implausible) {
    Tell(tell, Message::Kind::kWarning, w);
    r.input_findings.push_back(w);
  }

  stability::MapOptions opt;
  opt.seed_q = r.region.seed_q;
  opt.rotation = r.region.rotation_fixed;
  opt.optimise_rotation = r.region.rotation_free;
  opt.rotation_min = r.region.rotation_min;
  opt.rotation_max = r.region.rotation_max;
  opt.rotation_evaluations = o.rotation_evaluations;
  opt.threads = o.threads;
  opt.analysis.spindle_speed_rad_s = r.cut.spindle_speed_rad_s ? r.cut.SpeedGrid() : r.cut.SpeedRange(o.speeds);
  opt.analysis.mode_coupling.max_depth = MmToM(o.max_depth_mm);

  const bool grid = o.path_path.empty();
  r.points = grid ? io::MapPointsOfRegion(r.region, r.cut.feed_direction_B)
                  : io::MapPointsOfPathFile(o.path_path, r.cut.feed_direction_B);
  const std::vector<stability::ToolPoseTarget>& targets = r.points.targets;
  if (stability::FirstFeedAlongToolAxis(targets) >= 0) {
    throw InputError({o.cut_path, r.cut.feed_line, r.cut.feed_column},
                     "feed_direction is parallel to the tool axis of the " + std::string(grid ? "region" : "path") +
                         "; choose a feed in the work plane");
  }
  const long n = static_cast<long>(targets.size());
  if (progress) {
    progress("points", 0, n);
    opt.progress = [&](long done, long) { progress("points", done, n); };
  }
  r.map = stability::ComputeStabilityMap(model, targets, r.points.rows, r.points.cols, r.cut.process, opt);
  const std::vector<stability::MapPoint>& pts = r.map.points;
  if (r.map.reached == 0) {
    throw InputError(
        {grid ? o.region_path : o.path_path, grid ? r.region.origin_line : 0, grid ? r.region.origin_column : 0},
        grid ? "no point of the region is reachable by the robot from seed_posture_deg within its joint limits "
               "(origin, axes and size place it out of reach)"
             : "no pose of the path is reachable by the robot from the region's seed_posture_deg");
  }
  // How far the seed's simplified closed form agrees with the eigenvalue
  // criterion (issue #6 asks to report it).
  if (const stability::ClosedFormAgreement a = stability::CompareClosedForm(pts); a.points > 0) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "mode coupling: the seed's simplified closed form (2 DOF, no damping; depth_closed_form_mm) gives "
        << a.median << " times the eigenvalue criterion's depth at the median of " << a.points << " points (" << a.min
        << " to " << a.max << " times): an indicator, not a limit; the map uses the eigenvalue criterion "
        << "(docs/stability.md)";
    Tell(tell, Message::Kind::kInfo, msg.str());
  }
  if (!uncertainty) return r;
  // Monte Carlo takes about half a second per point: what first order would
  // cost instead.
  const dynamics::PropagationMethod method = o.uncertainty.method;
  const std::string method_name = dynamics::ToString(method);
  if (method != dynamics::PropagationMethod::kFirstOrder && n > 50) {
    Tell(tell, Message::Kind::kNote,
         "--uncertainty-method " + method_name + ": " +
             (method == dynamics::PropagationMethod::kAuto
                  ? "a linearity check at each of the " + std::to_string(n) +
                        " points and Monte Carlo (about 0.5 s a point) where the depth bends within its interval"
                  : "Monte Carlo at each of the " + std::to_string(n) + " points (about 0.5 s a point)") +
             "; --uncertainty-method first-order takes about 2.4 times the map's time (docs/uncertainty.md)");
  }
  if (progress) progress("points' intervals", 0, n);
  r.intervals = stability::StabilityMapIntervals(r.config.description, r.config.parameters, targets, pts, r.cut.process,
                                                 opt.analysis, *uncertainty, o.uncertainty, o.threads,
                                                 [&](long done, long) {
                                                   if (progress) progress("points' intervals", done, n);
                                                 });
  const std::string level = FormatNumber(100.0 * o.uncertainty.confidence, 3);
  Tell(tell, Message::Kind::kInfo,
       "intervals at " + level + " %: " + std::to_string(r.intervals->first_order) + " points first order, " +
           std::to_string(r.intervals->monte_carlo) + " Monte Carlo (" + r.intervals->example_reason + ")");
  if (const long k = r.intervals->SmallestLower(); k >= 0) {
    Tell(tell, Message::Kind::kInfo,
         "the smallest safe depth (" + level + " % lower bound) is " +
             FormatNumber(MToMm(r.intervals->depth[static_cast<size_t>(k)].lower), 4) + " mm, at " + r.Where(k));
  }
  return r;
}

nlohmann::json StabilityMapRun::Summary(const StabilityMapOptions& o) const {
  nlohmann::json j = io::StabilityMapSummaryJson(points, map, stability::FindCriticalDepthExtremes(map.points));
  j["robot"] = o.robot_path;
  j["cut"] = o.cut_path;
  if (!o.region_path.empty()) j["region"] = o.region_path;
  if (!o.path_path.empty()) j["path"] = o.path_path;
  if (intervals) {
    const long k = intervals->SmallestLower();
    const double safe_min = k >= 0 ? intervals->depth[static_cast<size_t>(k)].lower : NAN;
    j["uncertainty"] = {{"files", uncertainty_files},
                        {"confidence", o.uncertainty.confidence},
                        {"points_first_order", intervals->first_order},
                        {"points_monte_carlo", intervals->monte_carlo},
                        {"reason", intervals->example_reason},
                        {"smallest_safe_depth_mm", std::isfinite(safe_min) ? MToMm(safe_min) : NAN}};
  }
  return j;
}

}  // namespace robomach::workflows
