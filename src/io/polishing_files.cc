#include "robomach/io/polishing_files.h"

#include "plausible.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <sstream>

#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"
#include "robomach/io/yaml_doc.h"
#include "robomach/polishing/path_patterns.h"

namespace robomach::io {
namespace {

std::vector<double> Knots(const YamlDoc& node, int n, int degree, const char* n_name) {
  std::vector<double> k = node.Numbers();
  const int expected = n + degree + 1;
  if (static_cast<int>(k.size()) != expected) {
    throw node.Error("expected " + std::to_string(expected) + " knots (" + n_name + " " + std::to_string(n) +
                     " + degree " + std::to_string(degree) + " + 1), got " + std::to_string(k.size()) +
                     "; the counts must agree: len(knots) = n + degree + 1");
  }
  for (size_t i = 1; i < k.size(); ++i) {
    if (k[i] < k[i - 1]) {
      throw node.at(static_cast<int>(i)).Error("knots must be non-decreasing, got " + FormatDouble(k[i]) + " after " +
                                               FormatDouble(k[i - 1]));
    }
  }
  return k;
}

}  // namespace

polishing::NurbsSurface ReadNurbsYaml(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path);
  const YamlDoc root = doc["nurbs"];
  doc.RejectUnknownKeys();
  const int p = root["degree_u"].IntInRange(1, 15);
  const int q = root["degree_v"].IntInRange(1, 15);
  const YamlDoc cp = root["control_points_mm"];
  if (!cp.IsSequence() || cp.size() < 1) throw cp.Error("expected n_u rows of n_v points [x, y, z]");
  const int n_u = cp.size();
  std::vector<std::vector<Eigen::Vector3d>> P(n_u);
  int n_v = -1;
  for (int i = 0; i < n_u; ++i) {
    const YamlDoc row = cp.at(i);
    if (!row.IsSequence()) throw row.Error("expected a row of points [x, y, z]");
    if (n_v < 0) n_v = row.size();
    if (row.size() != n_v) {
      throw row.Error("row " + std::to_string(i + 1) + " has " + std::to_string(row.size()) + " points, row 1 has " +
                      std::to_string(n_v));
    }
    for (int j = 0; j < n_v; ++j) {
      const std::vector<double> x = row.at(j).Numbers(3);
      P[i].emplace_back(MmToM(x[0]), MmToM(x[1]), MmToM(x[2]));
    }
  }
  if (n_u < p + 1) throw cp.Error("expected at least degree_u + 1 = " + std::to_string(p + 1) + " rows, got " + std::to_string(n_u));
  if (n_v < q + 1) throw cp.Error("expected at least degree_v + 1 = " + std::to_string(q + 1) + " points per row, got " + std::to_string(n_v));
  std::vector<double> ku = Knots(root["knots_u"], n_u, p, "n_u");
  std::vector<double> kv = Knots(root["knots_v"], n_v, q, "n_v");
  std::vector<std::vector<double>> W;
  if (root.Has("weights")) {
    const YamlDoc w = root["weights"];
    if (!w.IsSequence() || w.size() != n_u) throw w.Error("expected " + std::to_string(n_u) + " rows of " + std::to_string(n_v) + " weights");
    for (int i = 0; i < n_u; ++i) {
      const YamlDoc row = w.at(i);
      W.push_back(row.Numbers(n_v));
      for (int j = 0; j < n_v; ++j) {
        if (!(W[i][j] > 0.0)) {
          throw row.at(j).Error("weight of control point (" + std::to_string(i + 1) + ", " + std::to_string(j + 1) +
                                "): expected a number > 0, got " + FormatDouble(W[i][j]));
        }
      }
    }
  } else {
    root.MarkUsed("weights");
  }
  root.RejectUnknownKeys();
  return root.Checked(
      [&] { return polishing::NurbsSurface::Create(p, q, std::move(ku), std::move(kv), std::move(P), std::move(W)); });
}

polishing::PolishingProcess ReadPolishingProcess(const std::string& path, std::vector<std::string>* implausible) {
  const YamlDoc doc = YamlDoc::LoadFile(path);
  polishing::PolishingProcess p;
  const YamlDoc tool = doc["tool"], work = doc["workpiece"], proc = doc["process"];
  // A positive value checked against its plausible range (plausibility.md).
  const auto value = [&](const YamlDoc& node, const PlausibleRange& r) {
    const double v = node.PositiveNumber();
    CheckPlausible(node, v, r, implausible);
    return v;
  };
  const std::string m_in_mm = "a length in m typed in the mm field?", um_in_mm = "a length in um typed in the mm field?";
  p.wheel_radius = MmToM(value(tool["wheel_radius_mm"], {kMinPlausibleWheelRadiusMm, kMaxPlausibleWheelRadiusMm,
                                                         "mm", "contact wheels (25 to 250 mm)", m_in_mm, um_in_mm}));
  p.crown_radius = MmToM(value(tool["crown_radius_mm"], {kMinPlausibleCrownRadiusMm, kMaxPlausibleCrownRadiusMm,
                                                         "mm", "wheel crowns", m_in_mm, um_in_mm}));
  p.belt_width = MmToM(value(tool["belt_width_mm"], {kMinPlausibleBeltWidthMm, kMaxPlausibleBeltWidthMm, "mm",
                                                     "abrasive belts (10 to 300 mm)", m_in_mm, um_in_mm}));
  p.pad_modulus = value(tool["pad_modulus_MPa"], {kMinPlausiblePadModulusMPa, kMaxPlausiblePadModulusMPa, "MPa",
                                                  "pad rubbers (1 to 100 MPa)", "a modulus in GPa typed in the MPa field?",
                                                  "a modulus in kPa or Pa typed in the MPa field?"}) *
                  1e6;
  p.pad_poisson = tool["pad_poisson"].NumberInRange(0.0, 0.5, true, false);
  p.belt_speed = value(tool["belt_speed_m_per_s"],
                       {kMinPlausibleBeltSpeedMPerS, kMaxPlausibleBeltSpeedMPerS, "m/s", "belt grinding (5 to 35 m/s)",
                        "a speed in km/s?", "a speed in mm/s or m/min typed in the m/s field?"});
  tool.RejectUnknownKeys();
  p.work_modulus = value(work["modulus_GPa"], {kMinPlausibleWorkModulusGPa, kMaxPlausibleWorkModulusGPa, "GPa",
                                               "engineering solids (1 GPa polymers to 400 GPa carbides)",
                                               "a modulus in TPa typed in the GPa field?",
                                               "a modulus in MPa or Pa typed in the GPa field?"}) *
                   1e9;
  p.work_poisson = work["poisson"].NumberInRange(0.0, 0.5, true, false);
  p.preston_coefficient = value(work["preston_coefficient_m2_per_N"],
                                {kMinPlausiblePrestonM2PerN, kMaxPlausiblePrestonM2PerN, "m²/N",
                                 "Preston coefficients (1e-14 to 1e-10 m²/N)", "a value in m²/kN or m²/MN?",
                                 "a value in mm²/N (x1e6) typed in the m²/N field?"});
  work.RejectUnknownKeys();
  p.force = value(proc["force_N"], {kMinPlausiblePolishForceN, kMaxPlausiblePolishForceN, "N",
                                    "robotic polishing contact forces (1 to 100 N)",
                                    "a force in kN typed in the N field?", "a force in mN typed in the N field?"});
  p.margin = MmToM(proc["margin_mm"].NumberInRange(0.0, 1e6));
  p.max_speed = MmToM(value(proc["max_speed_mm_per_s"],
                            {kMinPlausiblePolishSpeedMmPerS, kMaxPlausiblePolishSpeedMmPerS, "mm/s",
                             "robot polishing feeds (5 to 200 mm/s)", "a speed in m/s typed in the mm/s field?",
                             "a speed in mm/min or um/s typed in the mm/s field?"}));
  p.flip_normal = proc.Has("flip_normal") ? proc["flip_normal"].Bool() : false;
  proc.MarkUsed("flip_normal");
  proc.RejectUnknownKeys();
  if (doc.Has("robot")) {
    // Contact frame C in the flange F (our addition, README "polish-plan on
    // the robot"): position in mm, then fixed-axis x-y-z rotation in degrees.
    const YamlDoc r = doc["robot"];
    const std::vector<double> x = r["contact_frame_in_flange_mm_deg"].Numbers(6);
    r.RejectUnknownKeys();
    p.p_FC = Eigen::Vector3d(MmToM(x[0]), MmToM(x[1]), MmToM(x[2]));
    p.R_FC = (Eigen::AngleAxisd(DegToRad(x[5]), Eigen::Vector3d::UnitZ()) *
              Eigen::AngleAxisd(DegToRad(x[4]), Eigen::Vector3d::UnitY()) *
              Eigen::AngleAxisd(DegToRad(x[3]), Eigen::Vector3d::UnitX()))
                 .toRotationMatrix();
  } else {
    doc.MarkUsed("robot");
  }
  doc.RejectUnknownKeys();
  AtLocation({path, 0, 0}, "", [&] { polishing::CheckValid(p); });
  return p;
}

PolishPathFile ReadPolishPath(const std::string& path) {
  const CsvTable csv = CsvTable::ReadFile(path);
  PolishPathFile f;
  f.path = path;
  f.metadata = csv.metadata();
  const std::vector<std::string> required = {"t_s", "x_mm", "y_mm", "z_mm", "nx", "ny", "nz", "tx", "ty", "tz"};
  for (const auto& c : required) csv.RequireColumn(c);
  std::vector<std::string> known = required;
  known.insert(known.end(), {"u", "v", "force_N"});
  const auto unknown = csv.UnknownColumns(known);
  if (!unknown.empty()) {
    throw InputError({path, csv.header_line(), 0}, "unknown column '" + unknown[0] + "'; expected t_s,x_mm,y_mm,z_mm,nx,ny,nz,tx,ty,tz[,u,v][,force_N]");
  }
  f.has_uv = csv.HasColumn("u") && csv.HasColumn("v");
  if (csv.HasColumn("u") != csv.HasColumn("v")) {
    throw InputError({path, csv.header_line(), 0}, "columns u and v go together; found only one of them");
  }
  if (csv.num_rows() < 2) throw InputError({path, csv.header_line(), 0}, "a path needs at least 2 rows");
  for (int r = 0; r < csv.num_rows(); ++r) {
    polishing::PathRow row;
    row.t = csv.Number(r, "t_s");
    row.p = Eigen::Vector3d(csv.Number(r, "x_mm"), csv.Number(r, "y_mm"), csv.Number(r, "z_mm")) * 1e-3;
    row.n = Eigen::Vector3d(csv.Number(r, "nx"), csv.Number(r, "ny"), csv.Number(r, "nz"));
    row.tx = Eigen::Vector3d(csv.Number(r, "tx"), csv.Number(r, "ty"), csv.Number(r, "tz"));
    if (std::abs(row.n.norm() - 1.0) > 1e-3) {
      throw csv.ErrorAt(r, "nx", "expected a unit normal (nx,ny,nz), got length " + FormatDouble(row.n.norm()));
    }
    if (std::abs(row.tx.norm() - 1.0) > 1e-3) {
      throw csv.ErrorAt(r, "tx", "expected a unit tool x axis (tx,ty,tz), got length " + FormatDouble(row.tx.norm()));
    }
    if (std::abs(row.tx.dot(row.n)) > 1e-3) {
      throw csv.ErrorAt(r, "tx", "tool x (tx,ty,tz) must be normal to (nx,ny,nz); their dot product is " +
                                     FormatDouble(row.tx.dot(row.n)));
    }
    row.n.normalize();
    row.tx = (row.tx - row.tx.dot(row.n) * row.n).normalized();
    if (f.has_uv && !csv.IsEmpty(r, "u")) {
      row.u = csv.Number(r, "u");
      row.v = csv.Number(r, "v");
    } else {
      row.u = row.v = std::nan("");
    }
    if (csv.HasColumn("force_N")) {
      row.force = csv.Number(r, "force_N");
      if (!(row.force >= 0)) {
        throw csv.ErrorAt(r, "force_N", "expected a force >= 0 (0: the tool is lifted), got " + FormatDouble(row.force));
      }
    }
    if (r > 0 && !(row.t > f.rows.back().t)) {
      throw csv.ErrorAt(r, "t_s", "expected t_s strictly increasing, got " + FormatDouble(row.t) + " after " +
                                      FormatDouble(f.rows.back().t));
    }
    f.rows.push_back(row);
    f.lines.push_back(csv.line(r));
  }
  return f;
}

namespace {
std::string Fixed(double x, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << (std::abs(x) < 0.5 * std::pow(10.0, -digits) ? 0.0 : x);
  return s.str();
}
}  // namespace

void WritePolishPath(const std::string& path, const std::vector<polishing::PathRow>& rows,
                     const std::vector<std::pair<std::string, std::string>>& metadata) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    for (const auto& [k, v] : metadata) out << "# " << k << ": " << v << "\n";
    // force_N only when the path sets it (a planned path with lifts sets it on every row).
    const bool with_force = std::any_of(rows.begin(), rows.end(), [](const auto& r) { return r.force >= 0; });
    if (with_force && !std::all_of(rows.begin(), rows.end(), [](const auto& r) { return r.force >= 0; })) {
      throw std::logic_error("WritePolishPath: some rows have a force and others not");
    }
    out << "t_s,x_mm,y_mm,z_mm,nx,ny,nz,tx,ty,tz,u,v" << (with_force ? ",force_N" : "") << "\n";
    for (const auto& r : rows) {
      // 1e-4 mm and 1e-9 s: far below the 0.01 mm surface tolerance, and a
      // path timed at the speed limit stays at it when read back (with 1e-6 s
      // a 0.01 mm/s excess could appear); the direction cosines to 1e-9.
      out << Fixed(r.t, 9) << ',' << Fixed(1e3 * r.p.x(), 4) << ',' << Fixed(1e3 * r.p.y(), 4) << ','
          << Fixed(1e3 * r.p.z(), 4) << ',' << Fixed(r.n.x(), 9) << ',' << Fixed(r.n.y(), 9) << ','
          << Fixed(r.n.z(), 9) << ',' << Fixed(r.tx.x(), 9) << ',' << Fixed(r.tx.y(), 9) << ','
          << Fixed(r.tx.z(), 9) << ',' << FormatDouble(r.u) << ',' << FormatDouble(r.v);
      if (with_force) out << ',' << FormatDouble(r.force);
      out << '\n';
    }
  });
}

void WriteRemovalMap(const std::string& path, const polishing::SampleGrid& grid, const std::vector<double>& removal_m) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "x_mm,y_mm,z_mm,u,v,removal_um\n";
    for (int j = 0; j < grid.nt(); ++j) {
      for (int i = 0; i < grid.ns(); ++i) {
        const int k = grid.index(i, j);
        if (!grid.in_region()[k]) continue;
        const Eigen::Vector3d& p = grid.points()[k];
        out << Fixed(1e3 * p.x(), 4) << ',' << Fixed(1e3 * p.y(), 4) << ',' << Fixed(1e3 * p.z(), 4) << ','
            << FormatDouble(grid.u(i)) << ',' << FormatDouble(grid.v(j)) << ',' << Fixed(1e6 * removal_m[k], 6)
            << '\n';
      }
    }
  });
}

std::vector<std::pair<std::string, std::string>> PlannedPathMetadata(const polishing::PathParameters& params,
                                                                     double edge_overrun_m) {
  const bool cyc = params.pattern == polishing::Pattern::kCycloid;
  const std::string guides_used =
      ToString(cyc ? params.guides : polishing::GuideLines::kParallelLines);  // the zig-zag's rows: "parallel"
  std::vector<std::pair<std::string, std::string>> meta = {{"pattern", polishing::PathPatternOf(params.pattern).name()}};
  meta.push_back({"offset_mm", FormatDouble(1e3 * params.offset)});
  meta.push_back({"edge_overrun_mm", FormatDouble(1e3 * edge_overrun_m)});
  if (cyc) {
    meta.push_back({"guides", guides_used});
    meta.push_back({"radius_mm", FormatDouble(1e3 * params.radius)});
    meta.push_back({"pitch_mm", FormatDouble(1e3 * params.pitch)});
    meta.push_back({"stagger_loops", FormatDouble(params.stagger)});
  }
  if (!cyc || params.guides == polishing::GuideLines::kParallelLines) {
    meta.push_back({"line_angle_deg", FormatDouble(params.line_angle * 180.0 / kPi)});
  }
  return meta;
}

void WriteJointTrajectoryCsv(const std::string& path, const std::vector<polishing::PathRow>& rows,
                             const kinematics::PosePathCheck& check, int num_joints) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "t_s";
    for (int j = 0; j < num_joints; ++j) out << ",q" << j + 1 << "_deg";
    out << ",reachable,limit_margin_deg,jacobian_condition\n";
    for (size_t r = 0; r < rows.size(); ++r) {
      out << FormatDouble(rows[r].t);
      for (int j = 0; j < num_joints; ++j) out << ',' << (check.reachable[r] ? FormatDouble(RadToDeg(check.q[r](j))) : "");
      out << ',' << (check.reachable[r] ? 1 : 0) << ','
          << (check.reachable[r] ? FormatDouble(RadToDeg(check.limit_margin[r])) : "") << ','
          << (check.reachable[r] ? FormatDouble(check.condition[r]) : "") << '\n';
    }
  });
}

}  // namespace robomach::io
