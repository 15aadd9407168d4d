#include "robomach/io/stability_map_file.h"

#include <cmath>
#include <map>
#include <ostream>

#include <Eigen/Geometry>

#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/lobes_file.h"

namespace robomach::io {

MapPoints MapPointsOfRegion(const RegionSpec& region, const Eigen::Vector3d& feed_B) {
  MapPoints m;
  m.grid = true;
  m.targets = region.Targets(feed_B);
  m.rows = region.num_v();
  m.cols = region.num_u();
  m.grid_step = region.grid_step;
  return m;
}

MapPoints MapPointsOfPathFile(const std::string& path, const Eigen::Vector3d& default_feed_B) {
  MapPoints m;
  m.grid = false;
  for (const PathPoint& p : ReadToolPathFile(path, default_feed_B)) {
    stability::ToolPoseTarget t = p.target;
    // A per-point rotation turns the reference x about the tool axis.
    t.x_ref = Eigen::AngleAxisd(p.rotation, t.z_T.normalized()) * t.x_ref;
    m.targets.push_back(t);
    m.ids.push_back(p.id);
    m.path_rotation.push_back(p.rotation);
  }
  m.rows = 1;
  m.cols = static_cast<int>(m.targets.size());
  return m;
}

void WriteStabilityMapCsv(const std::string& path, const MapPoints& points,
                          const std::vector<stability::MapPoint>& results, int num_joints,
                          const std::vector<dynamics::OutputInterval>* depth_intervals) {
  const int n = num_joints;
  const bool grid = points.grid;
  const int cols = points.cols;
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << (grid ? "row,col,x_mm,y_mm," : "point_id,") << "px_mm,py_mm,pz_mm,rotation_deg";
    for (int j = 0; j < n; ++j) os << ",q" << j + 1 << "_deg";
    os << ",depth_mode_coupling_mm,depth_closed_form_mm,deformation_ratio,depth_regenerative_mm,"
          "spindle_speed_rpm,critical_depth_mm,limiting_mechanism,chatter_freq_hz,jacobian_condition,status"
       << (depth_intervals ? ",critical_depth_mm_lower,critical_depth_mm_upper" : "") << '\n';
    for (size_t i = 0; i < results.size(); ++i) {
      const stability::MapPoint& p = results[i];
      const stability::PostureStability& s = p.stability;
      const stability::ToolPoseTarget& t = points.targets[i];
      const bool analysed = std::isfinite(s.critical_depth) || s.limiting != stability::Mechanism::kNone ||
                            s.mode_coupling.evaluations > 0;
      if (grid) {
        const int r = static_cast<int>(i) / cols, c = static_cast<int>(i) % cols;
        os << r << ',' << c << ',' << FormatCell(c * points.grid_step * 1e3) << ','
           << FormatCell(r * points.grid_step * 1e3) << ',';
      } else {
        os << points.ids[i] << ',';
      }
      os << FormatCell(t.p_BT.x() * 1e3) << ',' << FormatCell(t.p_BT.y() * 1e3) << ',' << FormatCell(t.p_BT.z() * 1e3)
         << ',' << FormatCell(RadToDeg(p.rotation + (grid ? 0.0 : points.path_rotation[i])));
      // An unreachable point has no posture: the IK's last iterate and its
      // Jacobian are not the robot's (issue #35), so both stay empty.
      const bool reached = p.status != stability::PointStatus::kUnreachable && p.q.size() == n;
      for (int j = 0; j < n; ++j) os << ',' << (reached ? FormatCell(RadToDeg(p.q(j))) : "");
      const bool mc = analysed && s.mode_coupling.status == stability::ModeCouplingStatus::kFound;
      const bool rg = analysed && s.regenerative.status == stability::LobeStatus::kOk;
      os << ',' << (mc ? FormatCell(s.mode_coupling.critical_depth * 1e3) : "") << ','
         << (analysed ? FormatCell(s.closed_form.critical_depth * 1e3) : "") << ','
         << (analysed ? FormatCell(s.closed_form.deformation_ratio) : "") << ','
         << (rg ? FormatCell(s.regenerative.critical_depth * 1e3) : "") << ','
         << (rg ? FormatCell(LobeSpeedRpm(s.regenerative.spindle_speed_rad_s)) : "") << ','
         << (analysed ? FormatCell(s.critical_depth * 1e3) : "") << ','
         << (analysed ? stability::ToString(s.limiting) : "") << ','
         << (analysed ? FormatCell(s.chatter_freq_hz) : "") << ',' << (reached ? FormatCell(p.jacobian_condition) : "")
         << ','
         << stability::ToString(p.status);
      if (depth_intervals) {
        os << ',' << FormatCell(MToMm((*depth_intervals)[i].lower)) << ',' << FormatCell(MToMm((*depth_intervals)[i].upper));
      }
      os << '\n';
    }
  });
}

nlohmann::json StabilityMapSummaryJson(const MapPoints& points, const stability::StabilityMapResult& map,
                                       const stability::CriticalDepthExtremes& e) {
  const std::vector<stability::MapPoint>& pts = map.points;
  nlohmann::json j;
  j["mode"] = points.grid ? "grid" : "path";
  j["points"] = pts.size();
  if (points.grid) {
    j["grid_rows"] = points.rows;
    j["grid_cols"] = points.cols;
  }
  j["points_reached"] = map.reached;
  j["points_flagged"] = map.flagged_points;
  std::map<std::string, int> by_status;
  for (const stability::MapPoint& p : pts) ++by_status[stability::ToString(p.status)];
  j["points_by_status"] = by_status;
  // The extremes of critical_depth_mm over the points that have one, with
  // the point as in the CSV (row,col or point_id).
  auto where = [&](long k) {
    const size_t i = static_cast<size_t>(k);
    nlohmann::json w;
    if (points.grid) {
      w["row"] = static_cast<int>(i) / points.cols;
      w["col"] = static_cast<int>(i) % points.cols;
    } else {
      w["point_id"] = points.ids[i];
    }
    w["px_mm"] = MToMm(points.targets[i].p_BT.x());
    w["py_mm"] = MToMm(points.targets[i].p_BT.y());
    w["pz_mm"] = MToMm(points.targets[i].p_BT.z());
    w["critical_depth_mm"] = MToMm(pts[i].stability.critical_depth);
    w["limiting_mechanism"] = stability::ToString(pts[i].stability.limiting);
    if (std::isfinite(pts[i].stability.chatter_freq_hz)) w["chatter_freq_hz"] = pts[i].stability.chatter_freq_hz;
    w["status"] = stability::ToString(pts[i].status);
    return w;
  };
  j["points_with_critical_depth"] = e.with_depth;
  if (e.with_depth > 0) {
    j["min_critical_depth_mm"] = MToMm(pts[static_cast<size_t>(e.min_index)].stability.critical_depth);
    j["max_critical_depth_mm"] = MToMm(pts[static_cast<size_t>(e.max_index)].stability.critical_depth);
    j["min_critical_depth_point"] = where(e.min_index);
    j["max_critical_depth_point"] = where(e.max_index);
  }
  return j;
}

}  // namespace robomach::io
