#include "robomach/io/posture_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <regex>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

std::vector<std::string> PostureUnitWarnings(const std::string& path, const std::vector<std::vector<double>>& written,
                                             const std::vector<bool>& is_deg) {
  double max_deg = 0.0, max_rad = 0.0;
  bool deg_fraction = false;  // a non-zero degree value that is not whole
  int deg_nonzero = 0;
  for (const auto& row : written) {
    for (size_t j = 0; j < row.size() && j < is_deg.size(); ++j) {
      const double a = std::abs(row[j]);
      if (is_deg[j]) {
        max_deg = std::max(max_deg, a);
        if (a > 0.0) ++deg_nonzero;
        if (a > 0.0 && a != std::floor(a)) deg_fraction = true;
      } else {
        max_rad = std::max(max_rad, a);
      }
    }
  }
  std::vector<std::string> out;
  if (deg_nonzero > 0 && deg_fraction && max_deg <= kOneTurnRad) {
    out.push_back("implausible (unit mistake?): " + path + ": every angle under the _deg headers is within "
                  "2 pi = 6.28 (largest " + FormatDouble(max_deg) +
                  "), as radians are: these look like radians; name the columns q1_rad, q2_rad, ... or convert to "
                  "degrees");
  }
  if (max_rad > kOneTurnRad) {
    out.push_back("implausible (unit mistake?): " + path + ": an angle of " + FormatDouble(max_rad) +
                  " under a _rad header is " + FormatNumber(RadToDeg(max_rad)) +
                  " deg, more than a turn: these look like degrees; name the columns q1_deg, q2_deg, ... or "
                  "convert to radians");
  }
  return out;
}

std::vector<Posture> ReadPostureFile(const std::string& path, int num_joints,
                                     std::vector<std::string>* unit_warnings) {
  const CsvTable t = CsvTable::ReadFile(path, kPostureCsvFormat);
  t.RequireColumn("pose_id", "posture");
  // Which joint columns exist, and in which unit.
  const std::regex qcol(R"(q(\d+)_(deg|rad))");
  int max_joint = 0;
  for (size_t c = 0; c < t.header().size(); ++c) {
    const std::string& h = t.header()[c];
    std::smatch m;
    if (!std::regex_match(h, m, qcol)) continue;
    // Not std::stoi: a number past int's range threw std::out_of_range (found
    // by fuzz_posture_csv, issue #22).
    int joint = 0;
    const std::errc ec = std::from_chars(h.data() + m.position(1), h.data() + m.position(1) + m.length(1), joint).ec;
    if (ec != std::errc()) {
      throw InputError({path, t.header_line(), static_cast<int>(c) + 1},
                       "column " + h + ": the robot has " + std::to_string(num_joints) + " joints, so there is no joint " +
                           m[1].str());
    }
    max_joint = std::max(max_joint, joint);
  }
  // num_joints <= 0: as many joints as the file's highest q column.
  const bool from_file = num_joints <= 0;
  if (from_file) {
    if (max_joint == 0) {
      throw InputError({path, t.header_line(), 0},
                       "no joint columns: expected q1_deg..qn_deg (or _rad)" + t.LooksLike("posture"));
    }
    num_joints = max_joint;
  }
  if (max_joint > num_joints) {
    throw InputError({path, t.header_line(), 0},
                     "the file has joint columns up to q" + std::to_string(max_joint) +
                         " but the robot has " + std::to_string(num_joints) + " joints");
  }
  std::vector<std::string> cols(num_joints);
  std::vector<bool> is_deg(num_joints);
  for (int j = 0; j < num_joints; ++j) {
    const std::string deg = "q" + std::to_string(j + 1) + "_deg";
    const std::string rad = "q" + std::to_string(j + 1) + "_rad";
    if (t.HasColumn(deg) && t.HasColumn(rad)) {
      throw InputError({path, t.header_line(), 0},
                       "joint " + std::to_string(j + 1) + " is given twice, as " + deg + " and " +
                           rad + "; keep one");
    }
    if (!t.HasColumn(deg) && !t.HasColumn(rad)) {
      throw InputError({path, t.header_line(), 0},
                       "missing column " + deg + " (or " + rad + "): " +
                           (from_file ? "the file has columns up to q" + std::to_string(num_joints)
                                      : "the robot has " + std::to_string(num_joints) + " joints") +
                           JointColumnHint(t, j, num_joints) + t.LooksLike("posture"));
    }
    is_deg[j] = t.HasColumn(deg);
    cols[j] = is_deg[j] ? deg : rad;
  }
  std::vector<Posture> out;
  std::vector<std::vector<double>> written;
  std::map<std::string, int> seen;
  for (int r = 0; r < t.num_rows(); ++r) {
    Posture p;
    p.id = t.Text(r, "pose_id");
    // formats.md §1: any non-empty text without commas (it is written back
    // unquoted in FRF and modal tables); 256 characters is plenty for a name.
    if (p.id.find(',') != std::string::npos || p.id.size() > 256) {
      throw t.ErrorAt(r, "pose_id", "expected a name without commas of at most 256 characters");
    }
    p.line = t.line(r);
    auto [it, fresh] = seen.emplace(p.id, p.line);
    if (!fresh) {
      // A plan or a tracker file repeats its postures: say which it is.
      throw t.ErrorAtRow(r, "pose_id \"" + p.id + "\" appears twice (first on line " +
                                std::to_string(it->second) + ")" + t.LooksLike("posture"));
    }
    p.q.resize(num_joints);
    std::vector<double>& as_written = written.emplace_back(num_joints);
    for (int j = 0; j < num_joints; ++j) {
      const double v = t.Number(r, cols[j]);
      as_written[j] = v;
      p.q(j) = is_deg[j] ? DegToRad(v) : v;
      // Finite but absurd (1e308): no robot joint turns that far in any
      // unit; refused before anything is computed (issue #35).
      if (std::abs(RadToDeg(p.q(j))) > kMaxJointAngleDeg) {
        throw t.ErrorAt(r, cols[j],
                        t.Cell(r, t.ColumnIndex(cols[j])) + (is_deg[j] ? " deg" : " rad") + " is not a joint angle (more than 100000 deg, 278 turns, in "
                            "magnitude): a typo or a value in another unit");
      }
    }
    out.push_back(std::move(p));
  }
  if (out.empty()) throw InputError({path, 0, 0}, "no postures (the file has a header only)");
  if (unit_warnings) *unit_warnings = PostureUnitWarnings(path, written, is_deg);
  return out;
}

void WritePostureFile(const std::string& path, const std::vector<Posture>& postures) {
  WriteFileAtomically(path, [&](std::ostream& os) {
    const int n = postures.empty() ? 0 : static_cast<int>(postures[0].q.size());
    os << "pose_id";
    for (int j = 0; j < n; ++j) os << ",q" << j + 1 << "_deg";
    os << "\n";
    for (const auto& p : postures) {
      os << p.id;
      for (int j = 0; j < n; ++j) os << "," << FormatDouble(RadToDeg(p.q(j)));
      os << "\n";
    }
  });
}

}  // namespace robomach::io
