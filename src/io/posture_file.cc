#include "robomach/io/posture_file.h"

#include <charconv>
#include <map>
#include <regex>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

std::vector<Posture> ReadPostureFile(const std::string& path, int num_joints) {
  const CsvTable t = CsvTable::ReadFile(path);
  t.RequireColumn("pose_id");
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
                       "missing column " + deg + " (or " + rad + "): the robot has " +
                           std::to_string(num_joints) + " joints");
    }
    is_deg[j] = t.HasColumn(deg);
    cols[j] = is_deg[j] ? deg : rad;
  }
  std::vector<Posture> out;
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
      throw t.ErrorAtRow(r, "pose_id \"" + p.id + "\" appears twice (first on line " +
                                std::to_string(it->second) + ")");
    }
    p.q.resize(num_joints);
    for (int j = 0; j < num_joints; ++j) {
      const double v = t.Number(r, cols[j]);
      p.q(j) = is_deg[j] ? DegToRad(v) : v;
    }
    out.push_back(std::move(p));
  }
  if (out.empty()) throw InputError({path, 0, 0}, "no postures (the file has a header only)");
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
