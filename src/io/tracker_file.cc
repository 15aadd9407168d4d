#include "robomach/io/tracker_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"
#include "robomach/io/posture_file.h"

namespace robomach::io {
namespace {

const std::vector<std::string> kForceCols{"fx_N", "fy_N", "fz_N"};
const std::vector<std::string> kRopeCols{"mass_kg", "ax_mm", "ay_mm", "az_mm",
                                         "bx_mm",   "by_mm", "bz_mm"};
const std::vector<std::string> kLoadPointCols{"lx_mm", "ly_mm", "lz_mm"};
const std::vector<std::string> kTargetCols{"tx_mm", "ty_mm", "tz_mm"};
const std::vector<std::string> kPositionCols{"x0_mm", "y0_mm", "z0_mm", "x1_mm", "y1_mm", "z1_mm"};

InputError HeaderError(const CsvTable& t, const std::string& column, const std::string& message) {
  return InputError({t.path(), t.header_line(), t.ColumnIndex(column) + 1},
                    "column " + column + ": " + message);
}

std::string FirstPresent(const CsvTable& t, const std::vector<std::string>& cols) {
  for (const auto& c : cols) {
    if (t.HasColumn(c)) return c;
  }
  return "";
}

Eigen::Vector3d Point_mm(const CsvTable& t, int r, const std::vector<std::string>& cols, int first = 0) {
  return {MmToM(t.Number(r, cols[first])), MmToM(t.Number(r, cols[first + 1])),
          MmToM(t.Number(r, cols[first + 2]))};
}

// Optional tip-frame point: all three columns or none in the header; in a
// row all three cells or none.
std::optional<Eigen::Vector3d> OptionalPoint(const CsvTable& t, int r,
                                             const std::vector<std::string>& cols) {
  if (!t.HasColumn(cols[0])) return std::nullopt;
  int empty = 0;
  for (const auto& c : cols) empty += t.IsEmpty(r, c) ? 1 : 0;
  if (empty == 3) return std::nullopt;
  if (empty > 0) {
    for (const auto& c : cols) {
      if (t.IsEmpty(r, c)) {
        throw t.ErrorAt(r, c, "expected a number (give " + cols[0] + ".." + cols[2] +
                                  " all three, or leave all three empty for the tool centre point)");
      }
    }
  }
  return Point_mm(t, r, cols);
}

void CheckTriple(const CsvTable& t, const std::vector<std::string>& cols, const std::string& what) {
  const std::string present = FirstPresent(t, cols);
  if (present.empty()) return;
  for (const auto& c : cols) {
    if (!t.HasColumn(c)) {
      throw HeaderError(t, present, "the " + what + " needs all of " + cols[0] + ", " + cols[1] +
                                        ", " + cols[2] + "; " + c + " is missing");
    }
  }
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The unit checks of ReadTrackerFile (TrackerFile::unit_warnings): medians,
// so that one odd row is not taken for a unit.
std::vector<std::string> TrackerUnitWarnings(const TrackerFile& f, const CsvTable& t,
                                             const std::vector<std::string>& qcols, const std::vector<bool>& is_deg) {
  std::vector<std::vector<double>> written;
  for (int r = 0; r < t.num_rows(); ++r) {
    std::vector<double> row;
    for (const std::string& c : qcols) row.push_back(t.Number(r, c));
    written.push_back(row);
  }
  std::vector<std::string> out = PostureUnitWarnings(f.path, written, is_deg);
  const std::string head = "implausible (unit mistake?): " + f.path + ": ";
  std::vector<double> dist_mm, mass_kg, force_n;
  for (const auto& m : f.measurements) {
    dist_mm.push_back(MToMm(m.p0.norm()));
    if (m.force) force_n.push_back(m.force->norm());
    if (f.rope_form) mass_kg.push_back(m.mass_kg);
  }
  const double d = Median(dist_mm);
  if (d < kMinPlausibleTargetDistanceMm) {
    out.push_back(head + "the unloaded target (x0_mm, y0_mm, z0_mm) is a median " + FormatNumber(d) +
                  " mm from the robot base, closer than the " + FormatDouble(kMinPlausibleTargetDistanceMm) +
                  " mm a robot's tool can be: the positions look like metres under the _mm headers (the tracker "
                  "frame is the base frame, formats.md §2); convert them to mm");
  } else if (d > kMaxPlausibleTargetDistanceMm) {
    out.push_back(head + "the unloaded target (x0_mm, y0_mm, z0_mm) is a median " + FormatNumber(d) +
                  " mm from the robot base, farther than the " + FormatDouble(kMaxPlausibleTargetDistanceMm) +
                  " mm of any industrial robot: the positions look like micrometres under the _mm headers; "
                  "convert them to mm");
  }
  const double m = Median(mass_kg);
  if (m > kMaxPlausibleLoadMassKg) {
    out.push_back(head + "the median load mass_kg " + FormatNumber(m) + " is above the " +
                  FormatDouble(kMaxPlausibleLoadMassKg) + " kg a load test hangs (5 - 300 kg): grams under mass_kg?");
  } else if (m < kMinPlausibleLoadMassKg) {
    out.push_back(head + "the median load mass_kg " + FormatNumber(m) + " is below the " +
                  FormatDouble(kMinPlausibleLoadMassKg) + " kg that deflect a robot measurably: tonnes under "
                  "mass_kg?");
  }
  const double F = Median(force_n);
  if (F < kMinPlausibleLoadN) {
    out.push_back(head + "the median load |(fx_N, fy_N, fz_N)| " + FormatNumber(F) + " N is below the " +
                  FormatDouble(kMinPlausibleLoadN) + " N that deflect a robot measurably: kN under the _N headers?");
  } else if (F > kMaxPlausibleLoadN) {
    out.push_back(head + "the median load |(fx_N, fy_N, fz_N)| " + FormatNumber(F) + " N is above the " +
                  FormatDouble(kMaxPlausibleLoadN) + " N of a robot load test: a mass in g, or a force in "
                  "another unit, under the _N headers?");
  }
  return out;
}

}  // namespace

TrackerFile ReadTrackerFile(const std::string& path, int num_joints) {
  const CsvTable t = CsvTable::ReadFile(path, kTrackerCsvFormat);
  TrackerFile f;
  f.path = path;
  f.metadata = t.metadata();
  t.RequireColumn("case_id", "tracker");
  t.RequireColumn("pose_id", "tracker");
  for (const auto& c : kPositionCols) t.RequireColumn(c, "tracker");

  // Joint columns, as in the posture file (formats.md §1).
  const std::regex qcol(R"(q(\d+)_(deg|rad))");
  for (const std::string& h : t.header()) {
    std::smatch m;
    if (!std::regex_match(h, m, qcol)) continue;
    // Not std::stoi: a number past int's range threw std::out_of_range (found
    // by fuzz_posture_csv in the posture reader's twin, issue #22).
    int joint = 0;
    const std::errc ec = std::from_chars(h.data() + m.position(1), h.data() + m.position(1) + m.length(1), joint).ec;
    if (ec != std::errc() || joint > num_joints) {
      throw HeaderError(t, h, "the robot has " + std::to_string(num_joints) +
                                  " joints, so there is no joint " + std::string(m[1]));
    }
  }
  std::vector<std::string> qcols(num_joints);
  std::vector<bool> is_deg(num_joints);
  for (int j = 0; j < num_joints; ++j) {
    // std::string(1, 'q') + ...: "q" + std::to_string() trips GCC 12's
    // -Wrestrict false positive (GCC bug 105329).
    const std::string stem = std::string(1, 'q') + std::to_string(j + 1);
    const std::string deg = stem + "_deg";
    const std::string rad = stem + "_rad";
    if (t.HasColumn(deg) && t.HasColumn(rad)) {
      throw HeaderError(t, rad, "joint " + std::to_string(j + 1) + " is also given as " + deg +
                                    "; keep one");
    }
    if (!t.HasColumn(deg) && !t.HasColumn(rad)) {
      throw InputError({path, t.header_line(), 0},
                       "missing column " + deg + " (or " + rad + "): the robot has " +
                           std::to_string(num_joints) + " joints" +
                           JointColumnHint(t, j, num_joints) + t.LooksLike("tracker"));
    }
    is_deg[j] = t.HasColumn(deg);
    qcols[j] = is_deg[j] ? deg : rad;
  }

  // Exactly one load form per file.
  const std::string force_col = FirstPresent(t, kForceCols);
  const std::string rope_col = FirstPresent(t, kRopeCols);
  if (!force_col.empty() && !rope_col.empty()) {
    throw HeaderError(t, rope_col,
                      "the file mixes the two load forms (" + force_col + " is a force component, " +
                          rope_col + " belongs to the rope form); keep either fx_N,fy_N,fz_N or "
                          "mass_kg with ax_mm..bz_mm");
  }
  if (force_col.empty() && rope_col.empty()) {
    throw InputError({path, t.header_line(), 0},
                     "no load columns: expected fx_N,fy_N,fz_N or mass_kg with "
                     "ax_mm,ay_mm,az_mm,bx_mm,by_mm,bz_mm");
  }
  f.rope_form = !rope_col.empty();
  for (const auto& c : f.rope_form ? kRopeCols : kForceCols) {
    if (!t.HasColumn(c)) {
      throw InputError({path, t.header_line(), 0},
                       "missing column " + c + t.CloseColumn(c) + " (the " +
                           std::string(f.rope_form ? "rope" : "force") + " load form needs all of " +
                           (f.rope_form ? "mass_kg,ax_mm..bz_mm" : "fx_N,fy_N,fz_N") + ")");
    }
  }
  CheckTriple(t, kLoadPointCols, "load point");
  CheckTriple(t, kTargetCols, "target");

  std::vector<std::string> known{"case_id", "pose_id"};
  for (const auto& v : {kPositionCols, f.rope_form ? kRopeCols : kForceCols, kLoadPointCols, kTargetCols}) {
    known.insert(known.end(), v.begin(), v.end());
  }
  known.insert(known.end(), qcols.begin(), qcols.end());
  f.unknown_columns = t.UnknownColumns(known);

  std::map<std::string, int> seen;
  for (int r = 0; r < t.num_rows(); ++r) {
    identification::TrackerMeasurement m;
    m.line = t.line(r);
    m.case_id = t.Text(r, "case_id");
    auto [it, fresh] = seen.emplace(m.case_id, m.line);
    if (!fresh) {
      throw t.ErrorAt(r, "case_id", "case \"" + m.case_id + "\" appears twice (first on line " +
                                        std::to_string(it->second) + ")");
    }
    m.pose_id = t.Text(r, "pose_id");
    m.q.resize(num_joints);
    for (int j = 0; j < num_joints; ++j) {
      const double v = t.Number(r, qcols[j]);
      m.q(j) = is_deg[j] ? DegToRad(v) : v;
    }
    m.p0 = Point_mm(t, r, kPositionCols, 0);
    m.p1 = Point_mm(t, r, kPositionCols, 3);
    if (f.rope_form) {
      m.mass_kg = t.Number(r, "mass_kg");
      if (!(m.mass_kg > 0.0)) {
        throw t.ErrorAt(r, "mass_kg", "expected a mass > 0 kg, got " + t.Text(r, "mass_kg"));
      }
      m.rope_A = Point_mm(t, r, kRopeCols, 1);
      m.rope_B = Point_mm(t, r, kRopeCols, 4);
      // RopeForce's bound: below 1e-9 m the direction is undefined.
      if ((m.rope_B - m.rope_A).norm() < 1e-9) {
        throw t.ErrorAt(r, "bx_mm",
                        "rope points A (ax_mm..az_mm) and B (bx_mm..bz_mm) coincide, so the rope "
                        "direction is undefined; B must be a second point along the rope");
      }
    } else {
      m.force = Eigen::Vector3d(t.Number(r, "fx_N"), t.Number(r, "fy_N"), t.Number(r, "fz_N"));
      if (m.force->norm() == 0.0) {
        throw t.ErrorAt(r, "fx_N", "the force is zero (fx_N, fy_N, fz_N are all 0): a load case needs a load");
      }
    }
    m.p_load_tip = OptionalPoint(t, r, kLoadPointCols);
    m.p_target_tip = OptionalPoint(t, r, kTargetCols);
    f.measurements.push_back(std::move(m));
  }
  if (f.measurements.empty()) throw InputError({path, 0, 0}, "no load cases (the file has a header only)");
  f.unit_warnings = TrackerUnitWarnings(f, t, qcols, is_deg);
  return f;
}

std::string TrackerNoiseUnitFinding(const std::string& option, double noise_mm) {
  if (!(noise_mm > kMaxPlausibleTrackerNoiseMm || (noise_mm > 0.0 && noise_mm < kMinPlausibleTrackerNoiseMm))) {
    return "";
  }
  return "implausible (unit mistake?): " + option + " " + FormatDouble(noise_mm) +
         " is outside the 0.0001 to 1 mm of laser trackers (0.005 to 0.05 mm): " +
         (noise_mm > kMaxPlausibleTrackerNoiseMm ? "a noise in um typed in the mm option?"
                                                 : "a noise in m typed in the mm option?");
}

void WriteTrackerFile(std::ostream& os,
                      const std::vector<identification::TrackerMeasurement>& ms,
                      const std::vector<std::pair<std::string, std::string>>& metadata) {
  if (ms.empty()) throw std::invalid_argument("WriteTrackerFile: no measurements");
  const bool force = ms[0].force.has_value();
  bool load_point = false, target = false;
  for (const auto& m : ms) {
    if (m.force.has_value() != force) {
      throw std::invalid_argument("WriteTrackerFile: measurements mix the force and rope load forms");
    }
    load_point |= m.p_load_tip.has_value();
    target |= m.p_target_tip.has_value();
  }
  const int n = static_cast<int>(ms[0].q.size());
  for (const auto& [k, v] : metadata) os << "# " << k << ": " << v << "\n";
  os << "case_id,pose_id";
  for (int j = 0; j < n; ++j) os << ",q" << j + 1 << "_deg";
  for (const auto& c : kPositionCols) os << "," << c;
  for (const auto& c : force ? kForceCols : kRopeCols) os << "," << c;
  if (load_point) for (const auto& c : kLoadPointCols) os << "," << c;
  if (target) for (const auto& c : kTargetCols) os << "," << c;
  os << "\n";
  auto mm = [&](const Eigen::Vector3d& p) {
    for (int a = 0; a < 3; ++a) os << "," << FormatDouble(MToMm(p(a)));
  };
  for (const auto& m : ms) {
    if (m.q.size() != n) throw std::invalid_argument("WriteTrackerFile: joint counts differ");
    os << m.case_id << "," << m.pose_id;
    for (int j = 0; j < n; ++j) os << "," << FormatDouble(RadToDeg(m.q(j)));
    mm(m.p0);
    mm(m.p1);
    if (force) {
      for (int a = 0; a < 3; ++a) os << "," << FormatDouble((*m.force)(a));
    } else {
      os << "," << FormatDouble(m.mass_kg);
      mm(m.rope_A);
      mm(m.rope_B);
    }
    if (load_point) {
      if (m.p_load_tip) mm(*m.p_load_tip); else os << ",,,";
    }
    if (target) {
      if (m.p_target_tip) mm(*m.p_target_tip); else os << ",,,";
    }
    os << "\n";
  }
}

void WriteTrackerFile(const std::string& path,
                      const std::vector<identification::TrackerMeasurement>& ms,
                      const std::vector<std::pair<std::string, std::string>>& metadata) {
  std::ostringstream s;
  WriteTrackerFile(s, ms, metadata);  // validate before anything touches the disk
  WriteFileAtomically(path, s.str());
}

}  // namespace robomach::io
