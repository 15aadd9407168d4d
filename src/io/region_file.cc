#include "robomach/io/region_file.h"

#include <cmath>

#include <Eigen/Geometry>

#include "plausible.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {

namespace {

Eigen::Vector3d Vec3(const YamlDoc& node) {
  const std::vector<double> v = node.Numbers(3);
  return {v[0], v[1], v[2]};
}

Eigen::Vector3d Direction(const YamlDoc& node) {
  const Eigen::Vector3d e = Vec3(node);
  if (!(e.norm() > 1e-9)) throw node.Error("expected a non-zero direction [x, y, z]");
  return e.normalized();
}

// A reference x for the rotation about z: the base axis least parallel to z,
// made orthogonal.
Eigen::Vector3d ReferenceX(const Eigen::Vector3d& z) {
  Eigen::Vector3d a = Eigen::Vector3d::UnitX();
  if (std::abs(z.x()) > 0.9) a = Eigen::Vector3d::UnitY();
  return (a - a.dot(z) * z).normalized();
}

}  // namespace

int RegionSpec::num_u() const { return static_cast<int>(std::floor(size_u / grid_step + 1e-9)) + 1; }
int RegionSpec::num_v() const { return static_cast<int>(std::floor(size_v / grid_step + 1e-9)) + 1; }

Eigen::Vector3d RegionSpec::ToolDirection() const {
  const Eigen::Vector3d n = u_B.cross(v_B);
  return (Eigen::AngleAxisd(tilt, u_B) * Eigen::AngleAxisd(lead, v_B) * (-n)).normalized();
}

std::vector<stability::ToolPoseTarget> RegionSpec::Targets(const Eigen::Vector3d& feed_B) const {
  std::vector<stability::ToolPoseTarget> out;
  const Eigen::Vector3d z = ToolDirection();
  const Eigen::Vector3d x_ref = (u_B - u_B.dot(z) * z).normalized();
  for (int r = 0; r < num_v(); ++r) {
    for (int c = 0; c < num_u(); ++c) {
      stability::ToolPoseTarget t;
      t.p_BT = origin_B + c * grid_step * u_B + r * grid_step * v_B;
      t.z_T = z;
      t.x_ref = x_ref;
      t.feed_B = feed_B;
      out.push_back(t);
    }
  }
  return out;
}

RegionSpec ReadRegionFile(const std::string& path, int num_joints) {
  const YamlDoc doc = YamlDoc::LoadFile(path);
  if (!doc.IsMap()) throw doc.Error("expected a map (see config/region_demo.yaml)");
  RegionSpec r;
  r.path = path;
  {
    const YamlDoc o = doc["origin_mm"];
    r.origin_B = Vec3(o) * 1e-3;
    r.origin_line = o.location().line;
    r.origin_column = o.location().column;
    // A machining region is where the tool reaches: 50 mm to 20 m from the
    // base (as the tracker file's target distance). The demo's corner is
    // 2.1 m out; in metres it would be 2.1 "mm".
    const double d_mm = 1e3 * r.origin_B.norm();
    if (d_mm < kMinPlausibleRegionDistanceMm || d_mm > kMaxPlausibleRegionDistanceMm) {
      r.implausible.push_back(ImplausibleMessage(
          o, "at " + (d_mm >= 10.0 ? std::to_string(std::lround(d_mm)) : robomach::FormatNumber(d_mm, 4)),
          {kMinPlausibleRegionDistanceMm, kMaxPlausibleRegionDistanceMm, "mm",
           "a robot's machining regions (their corner 0.05 - 20 m from the base)", "a position in m typed in the mm field?",
           "a position in um typed in the mm field?"},
          d_mm < kMinPlausibleRegionDistanceMm));
    }
  }
  r.u_B = Direction(doc["u_axis"]);
  {
    const YamlDoc vn = doc["v_axis"];
    const Eigen::Vector3d v = Direction(vn);
    const Eigen::Vector3d v_ortho = v - v.dot(r.u_B) * r.u_B;
    // Below sin = 1e-3 (0.06°) the plane is not defined by the two axes.
    if (v_ortho.norm() < 1e-3) throw vn.Error("v_axis is parallel to u_axis; the plane is undefined");
    r.v_B = v_ortho.normalized();
  }
  {
    const YamlDoc s = doc["size_mm"];
    const std::vector<double> v = s.Numbers(2);
    if (!(v[0] >= 0.0 && v[1] >= 0.0)) throw s.Error("expected two sizes >= 0 [along u, along v]");
    r.size_u = MmToM(v[0]);
    r.size_v = MmToM(v[1]);
  }
  {
    const YamlDoc g = doc["grid_step_mm"];
    r.grid_step = MmToM(g.PositiveNumber());
    const double n = (std::floor(r.size_u / r.grid_step) + 1) * (std::floor(r.size_v / r.grid_step) + 1);
    if (n > 4e6) throw g.Error("the grid would have " + std::to_string(static_cast<long>(n)) + " points; use a larger step");
  }
  if (doc.Has("tool_axis")) {
    const YamlDoc t = doc["tool_axis"];
    if (t.Has("lead_deg")) r.lead = DegToRad(t["lead_deg"].NumberInRange(-89.0, 89.0));
    if (t.Has("tilt_deg")) r.tilt = DegToRad(t["tilt_deg"].NumberInRange(-89.0, 89.0));
    t.MarkUsed("lead_deg");
    t.MarkUsed("tilt_deg");
    t.RejectUnknownKeys();
  }
  doc.MarkUsed("tool_axis");
  if (doc.Has("rotation_about_tool_axis")) {
    const YamlDoc rot = doc["rotation_about_tool_axis"];
    if (rot.Has("fixed_deg") == rot.Has("free")) {
      throw rot.Error("give either fixed_deg: <angle> or free: {min_deg: .., max_deg: ..}");
    }
    if (rot.Has("fixed_deg")) {
      r.rotation_fixed = DegToRad(rot["fixed_deg"].NumberInRange(-360.0, 360.0));
    } else {
      const YamlDoc f = rot["free"];
      const YamlDoc lo = f["min_deg"];
      const YamlDoc hi = f["max_deg"];
      r.rotation_min = DegToRad(lo.NumberInRange(-360.0, 360.0));
      r.rotation_max = DegToRad(hi.NumberInRange(-360.0, 360.0));
      if (!(r.rotation_max > r.rotation_min)) throw hi.Error("expected max_deg > min_deg");
      f.RejectUnknownKeys();
      r.rotation_free = true;
    }
    rot.MarkUsed("fixed_deg");
    rot.MarkUsed("free");
    rot.RejectUnknownKeys();
  }
  doc.MarkUsed("rotation_about_tool_axis");
  {
    const YamlDoc s = doc["seed_posture_deg"];
    const std::vector<double> q = s.Numbers(num_joints);
    r.seed_q.resize(num_joints);
    for (int j = 0; j < num_joints; ++j) r.seed_q(j) = DegToRad(q[j]);
    std::vector<TypedAngle> angles;
    for (int j = 0; j < num_joints; ++j) angles.push_back({s.at(j), q[j]});
    CheckDegreesNotRadians(angles, &r.implausible);
  }
  doc.RejectUnknownKeys();
  return r;
}

std::vector<PathPoint> ReadToolPathFile(const std::string& path, const Eigen::Vector3d& default_feed_B) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"x_mm", "y_mm", "z_mm", "tool_i", "tool_j", "tool_k"}) t.RequireColumn(c, "path");
  const bool has_feed = t.HasColumn("feed_i") || t.HasColumn("feed_j") || t.HasColumn("feed_k");
  if (has_feed) {
    for (const char* c : {"feed_i", "feed_j", "feed_k"}) t.RequireColumn(c, "path");
  }
  std::vector<PathPoint> out;
  for (int r = 0; r < t.num_rows(); ++r) {
    PathPoint p;
    p.line = t.line(r);
    p.id = t.HasColumn("point_id") ? t.Text(r, "point_id") : std::to_string(r + 1);
    p.target.p_BT = Eigen::Vector3d(t.Number(r, "x_mm"), t.Number(r, "y_mm"), t.Number(r, "z_mm")) * 1e-3;
    const Eigen::Vector3d axis(t.Number(r, "tool_i"), t.Number(r, "tool_j"), t.Number(r, "tool_k"));
    if (!(axis.norm() > 1e-9)) throw t.ErrorAt(r, "tool_i", "expected a non-zero tool axis (tool_i, tool_j, tool_k)");
    p.target.z_T = -axis.normalized();
    p.target.x_ref = ReferenceX(p.target.z_T);
    p.target.feed_B = default_feed_B;
    if (has_feed) {
      const Eigen::Vector3d f(t.Number(r, "feed_i"), t.Number(r, "feed_j"), t.Number(r, "feed_k"));
      const Eigen::Vector3d f_plane = f - f.dot(p.target.z_T) * p.target.z_T;
      if (!(f_plane.norm() > 1e-6 * std::max(1.0, f.norm()))) {
        throw t.ErrorAt(r, "feed_i", "expected a feed direction not parallel to the tool axis");
      }
      p.target.feed_B = f.normalized();
      p.has_feed = true;
    }
    if (t.HasColumn("rotation_deg")) p.rotation = DegToRad(t.Number(r, "rotation_deg"));
    out.push_back(p);
  }
  if (out.empty()) throw InputError({path, 0, 0}, "no tool poses (the file has a header only)");
  return out;
}

}  // namespace robomach::io
