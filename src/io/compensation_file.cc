#include "robomach/io/compensation_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "machine_text.h"
#include "robomach/common/errors.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/number_format.h"

#include "text.h"

namespace robomach::io {

using machine::AxisScale;
using machine_text::ReadWholeFile;
using machine_text::ToSi;

namespace {

struct Assignment {
  int line{0};
  std::string name;               // without '$'
  std::vector<std::string> index; // bracket arguments, trimmed
  std::string value;
};

// One partially read table, keyed by (kind, number, axis).
struct PendingTable {
  int first_line{0};
  std::map<int, std::pair<double, int>> points;  // index -> (value, line)
  std::optional<std::pair<double, int>> step, min, max;
  std::optional<std::pair<std::string, int>> input, output;
};

std::optional<Assignment> ParseAssignment(const std::string& raw, int line) {
  std::string s = raw;
  const size_t semi = s.find(';');
  if (semi != std::string::npos) s.resize(semi);
  s = Trim(s);
  // An optional block number "N10 ".
  if (s.size() > 1 && (s[0] == 'N' || s[0] == 'n') && std::isdigit(static_cast<unsigned char>(s[1]))) {
    size_t i = 1;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i;
    s = Trim(s.substr(i));
  }
  if (s.empty() || s[0] != '$') return std::nullopt;
  Assignment a;
  a.line = line;
  const size_t lb = s.find('['), eq = s.find('=');
  if (eq == std::string::npos) return std::nullopt;  // not an assignment
  if (lb == std::string::npos || lb > eq) {
    a.name = Trim(s.substr(1, eq - 1));
  } else {
    const size_t rb = s.find(']', lb);
    if (rb == std::string::npos || rb > eq) {
      a.name = Trim(s.substr(1, lb - 1));
      a.index = {"<unclosed>"};
    } else {
      a.name = Trim(s.substr(1, lb - 1));
      std::stringstream args(s.substr(lb + 1, rb - lb - 1));
      std::string arg;
      while (std::getline(args, arg, ',')) a.index.push_back(Trim(arg));
    }
  }
  a.value = Trim(s.substr(eq + 1));
  if (a.value.size() >= 2 && (a.value.front() == '"' || a.value.front() == '\'') && a.value.back() == a.value.front()) {
    a.value = a.value.substr(1, a.value.size() - 2);
  }
  std::transform(a.name.begin(), a.name.end(), a.name.begin(), [](unsigned char c) { return std::toupper(c); });
  return a;
}

// Everything the assignment pass gathers: the tables in progress and what the
// message of a file without tables needs. One struct, so the stages share it
// without long parameter lists.
struct ReadAssignments {
  std::map<std::pair<int, int>, PendingTable> enc;  // (axis index, system) -> table
  std::map<int, PendingTable> cec;                  // table number -> table
  std::map<std::string, int> seen_line;             // duplicate detection: name + index -> line
  int table_assignments = 0;
  int first_line = 0;      // the first line that is neither blank nor a comment
  std::string first_text;  // and its text, for the message of a file without tables
};

// One table assignment being read: the value, index and axis checks every
// field shares, each error naming the variable and its line.
struct AssignmentReader {
  const std::string& path;
  const MachineFile& mf;
  const Assignment& a;

  InputError Err(const std::string& m) const { return InputError({path, a.line, 0}, m); }
  double Number(const std::string& what) const {
    double v = 0.0;
    if (!ParseFiniteNumber(a.value, &v)) throw Err("$" + a.name + ": expected a number " + what + ", got \"" + a.value + "\"");
    return v;
  }
  int Integer(const std::string& text, const std::string& what) const {
    int v = 0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
    if (r.ec != std::errc() || r.ptr != text.data() + text.size()) {
      throw Err("$" + a.name + ": expected " + what + ", got \"" + text + "\"");
    }
    return v;
  }
  int AxisOf(const std::string& name) const {
    auto it = mf.controller_axes.find(name);
    if (it == mf.controller_axes.end()) {
      std::string known;
      for (const auto& [n, i] : mf.controller_axes) known += (known.empty() ? "" : ", ") + n;
      throw Err("$" + a.name + ": unknown axis '" + name + "'; controller_axes of " + mf.path + " has: " +
                (known.empty() ? "(none)" : known));
    }
    return it->second;
  }
  void WantArgs(size_t n) const {
    if (a.index.size() != n) {
      throw Err("$" + a.name + ": expected " + std::to_string(n) + " index value(s) in [], got " +
                std::to_string(a.index.size()));
    }
  }
};

// $AA_ENC_COMP[system, point, axis] and its _STEP, _MIN, _MAX and
// _IS_MODULO fields, into the encoder table of that axis.
void ReadEncAssignment(const AssignmentReader& r, ReadAssignments& st) {
  const Assignment& a = r.a;
  const int line = a.line;
  const std::string field = a.name.substr(std::string("AA_ENC_COMP").size());
  if (field.empty()) {
    r.WantArgs(3);
    const int sys = r.Integer(a.index[0], "a measuring system number");
    if (sys != 0) throw r.Err("$AA_ENC_COMP: only measuring system 0 is supported, got " + a.index[0]);
    const int point = r.Integer(a.index[1], "a point index >= 0");
    if (point < 0) throw r.Err("$AA_ENC_COMP: expected a point index >= 0, got " + a.index[1]);
    const int axis = r.AxisOf(a.index[2]);
    auto& t = st.enc[{axis, sys}];
    if (t.first_line == 0) t.first_line = line;
    t.points[point] = {r.Number("(the compensation value)"), line};
    return;
  }
  r.WantArgs(2);
  const int sys = r.Integer(a.index[0], "a measuring system number");
  if (sys != 0) throw r.Err("$" + a.name + ": only measuring system 0 is supported, got " + a.index[0]);
  const int axis = r.AxisOf(a.index[1]);
  auto& t = st.enc[{axis, sys}];
  if (t.first_line == 0) t.first_line = line;
  if (field == "_STEP") {
    t.step = {r.Number("(the point spacing)"), line};
  } else if (field == "_MIN") {
    t.min = {r.Number("(the first point's position)"), line};
  } else if (field == "_MAX") {
    t.max = {r.Number("(the last point's position)"), line};
  } else if (field == "_IS_MODULO") {
    if (r.Number("(0 or 1)") != 0.0) throw r.Err("$" + a.name + ": modulo tables are not supported (expected 0)");
  } else {
    throw r.Err("$" + a.name + ": not supported (expected $AA_ENC_COMP, _STEP, _MIN, _MAX, _IS_MODULO)");
  }
}

// $AN_CEC[table, point] and its per-table fields, into the cross-axis table
// of that number.
void ReadCecAssignment(const AssignmentReader& r, ReadAssignments& st) {
  const Assignment& a = r.a;
  const int line = a.line;
  const std::string field = a.name.substr(std::string("AN_CEC").size());
  if (field.empty()) {
    r.WantArgs(2);
    const int table = r.Integer(a.index[0], "a table number >= 0");
    const int point = r.Integer(a.index[1], "a point index >= 0");
    if (table < 0 || point < 0) throw r.Err("$AN_CEC: expected a table number and point index >= 0");
    auto& t = st.cec[table];
    if (t.first_line == 0) t.first_line = line;
    t.points[point] = {r.Number("(the compensation value)"), line};
    return;
  }
  r.WantArgs(1);
  const int table = r.Integer(a.index[0], "a table number >= 0");
  auto& t = st.cec[table];
  if (t.first_line == 0) t.first_line = line;
  if (field == "_INPUT_AXIS") {
    r.AxisOf(a.value);
    t.input = {a.value, line};
  } else if (field == "_OUTPUT_AXIS") {
    r.AxisOf(a.value);
    t.output = {a.value, line};
  } else if (field == "_STEP") {
    t.step = {r.Number("(the point spacing)"), line};
  } else if (field == "_MIN") {
    t.min = {r.Number("(the first point's position)"), line};
  } else if (field == "_MAX") {
    t.max = {r.Number("(the last point's position)"), line};
  } else if (field == "_IS_MODULO") {
    if (r.Number("(0 or 1)") != 0.0) throw r.Err("$" + a.name + ": modulo tables are not supported (expected 0)");
  } else if (field == "_DIRECTION") {
    if (r.Number("(0, 1 or -1)") != 0.0) {
      throw r.Err("$AN_CEC_DIRECTION: only 0 (both directions) is supported, got " + a.value);
    }
  } else if (field == "_MULT_BY_TABLE") {
    if (r.Number("(a table number or 0)") != 0.0) {
      throw r.Err("$AN_CEC_MULT_BY_TABLE: multiplied tables are not supported (expected 0), got " + a.value);
    }
  } else {
    throw r.Err("$" + a.name + ": not supported (expected $AN_CEC, _INPUT_AXIS, _OUTPUT_AXIS, _STEP, _MIN, "
                "_MAX, _IS_MODULO, _DIRECTION, _MULT_BY_TABLE)");
  }
}

// The pass over the lines: each $AA_ENC_COMP / $AN_CEC assignment read into
// its pending table in file order, so the first bad line is the one reported;
// other lines are skipped.
ReadAssignments ReadTableAssignments(const std::string& path, const std::string& text, const MachineFile& mf) {
  ReadAssignments st;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  while (std::getline(in, raw)) {
    ++line;
    if (st.first_line == 0) {
      const std::string t = Trim(raw);
      if (!t.empty() && t[0] != ';' && t[0] != '#') {
        st.first_line = line;
        st.first_text = t.size() > 60 ? t.substr(0, 60) + "..." : t;
      }
    }
    const auto oa = ParseAssignment(raw, line);
    if (!oa) continue;
    const Assignment& a = *oa;
    const bool enc_var = a.name.rfind("AA_ENC_COMP", 0) == 0;
    const bool cec_var = a.name.rfind("AN_CEC", 0) == 0;
    if (!enc_var && !cec_var) continue;  // some other variable: not a table assignment
    ++st.table_assignments;
    const AssignmentReader r{path, mf, a};
    if (!a.index.empty() && a.index[0] == "<unclosed>") throw r.Err("$" + a.name + ": unclosed '['");
    std::string key = a.name + "[";
    for (const auto& i : a.index) key += i + ",";
    if (auto it = st.seen_line.find(key); it != st.seen_line.end()) {
      throw r.Err("$" + a.name + " is assigned twice for the same index (first on line " + std::to_string(it->second) +
                  ")");
    }
    st.seen_line[key] = line;
    if (enc_var) {
      ReadEncAssignment(r, st);
    } else {
      ReadCecAssignment(r, st);
    }
  }
  return st;
}

// A file without a single table assignment holds nothing to compensate
// with: applying none would give the uncompensated path without a word
// (docs/conventions.md: a file the tool cannot use is bad data, 65).
void RefuseFileWithoutTables(const std::string& path, const FileSniff& sniff, const std::string& option,
                             const ReadAssignments& st) {
  if (st.table_assignments != 0) return;
  FileSniff what = sniff;
  what.description += " without a single $AA_ENC_COMP or $AN_CEC table assignment";
  if (st.first_line > 0) {
    throw InputError({path, st.first_line, 0}, WrongFileKindMessage(what, kCompensationFileFormat, option) +
                                                   " (this line is \"" + st.first_text + "\")");
  }
  throw InputError({path, 0, 0}, WrongFileKindMessage(what, kCompensationFileFormat, option));
}

// Turns pending tables into machine tables, collecting the implausible-value
// findings of all tables in one list (they warn, they do not refuse).
struct TableAssembler {
  const std::string& path;
  std::vector<std::string> implausible;

  InputError Err(int line, const std::string& m) const { return InputError({path, line, 0}, m); }

  // Values in the output axis's unit: refused when impossible, one finding
  // per table (its largest value) when implausible.
  void CheckValues(const PendingTable& t, const std::string& what, const AxisScale& out_axis) {
    const bool mm = out_axis.kind == machine::AxisKind::kLinear;
    const std::string unit = mm ? "mm" : "deg";
    const std::pair<double, int>* largest = nullptr;
    for (const auto& [i, v] : t.points) {
      if (!largest || std::abs(v.first) > std::abs(largest->first)) largest = &v;
    }
    if (!largest) return;
    const double m = std::abs(largest->first);
    if (m > (mm ? kMaxCompensationMm : kMaxCompensationDeg)) {
      throw Err(largest->second, what + ": value " + FormatDouble(largest->first) + " " + unit + " is beyond the " +
                                     FormatDouble(mm ? kMaxCompensationMm : kMaxCompensationDeg) + " " + unit +
                                     " any compensation table corrects: " +
                                     (mm ? "values in um or nm typed in the mm table?" : "values in arc-seconds typed in the deg table?"));
    }
    if (m > (mm ? kMaxPlausibleCompensationMm : kMaxPlausibleCompensationDeg)) {
      implausible.push_back("implausible (unit mistake?): " + path + ":" + std::to_string(largest->second) + ": " + what +
                            ": value " + FormatDouble(largest->first) + " " + unit + " is outside the +-" +
                            FormatDouble(mm ? kMaxPlausibleCompensationMm : kMaxPlausibleCompensationDeg) + " " + unit +
                            " of compensation tables (they hold a few um to tens of um): " +
                            (mm ? "values in um typed in the mm table?"
                                : "values in arc-seconds or millidegrees typed in the deg table?"));
    }
  }

  // Assemble and check one table (formats.md §8.4: MAX = MIN + (n - 1) STEP);
  // the values are filled in by the caller, in the output axis's unit.
  machine::CompensationTable Build(const PendingTable& t, const std::string& what, const AxisScale& input_axis) {
    if (t.points.empty()) throw Err(t.first_line, what + ": the table has no points");
    if (!t.step) throw Err(t.first_line, what + ": _STEP is missing");
    if (!t.min) throw Err(t.first_line, what + ": _MIN is missing");
    if (!t.max) throw Err(t.first_line, what + ": _MAX is missing");
    int expect = 0;
    for (const auto& [i, v] : t.points) {
      if (i != expect) throw Err(v.second, what + ": point " + std::to_string(expect) + " is missing before point " + std::to_string(i));
      ++expect;
    }
    if (!(t.step->first > 0.0)) {
      throw Err(t.step->second, what + ": _STEP must be > 0, got " + FormatDouble(t.step->first));
    }
    const int n = static_cast<int>(t.points.size());
    const double expected_max = t.min->first + (n - 1) * t.step->first;
    if (std::abs(t.max->first - expected_max) > 1e-9 * std::max({1.0, std::abs(expected_max), std::abs(t.max->first)})) {
      throw Err(t.max->second, what + ": _MAX " + FormatDouble(t.max->first) + " must equal _MIN + (points - 1) * _STEP = " +
                                   FormatDouble(t.min->first) + " + " + std::to_string(n - 1) + " * " +
                                   FormatDouble(t.step->first) + " = " + FormatDouble(expected_max));
    }
    // Positions of a linear input axis within machine travels (um typed
    // for mm moves them x1000).
    if (input_axis.kind == machine::AxisKind::kLinear) {
      const auto& far = std::abs(t.min->first) > std::abs(t.max->first) ? *t.min : *t.max;
      if (std::abs(far.first) > kMaxPlausibleMachineLengthMm) {
        implausible.push_back("implausible (unit mistake?): " + path + ":" + std::to_string(far.second) + ": " + what +
                              ": position " + FormatDouble(far.first) + " mm is outside the +-" +
                              FormatDouble(kMaxPlausibleMachineLengthMm) +
                              " mm of machine tool travels: positions in um typed in the mm table?");
      }
    }
    machine::CompensationTable table;
    table.min = ToSi(input_axis, t.min->first);
    table.step = ToSi(input_axis, t.step->first);
    return table;
  }
};

}  // namespace

CompensationTables ReadCompensationFile(const std::string& path, const MachineFile& mf, const std::string& option) {
  // A PNG, a YAML, a CSV (the temperature log given as the tables) is named
  // as what it is before the lines are read as assignments.
  const FileSniff sniff = SniffFileKind(path);
  RequireFileKind(path, {FileKind::kMpf}, kCompensationFileFormat, option);
  const std::string text = ReadWholeFile(path);
  const ReadAssignments st = ReadTableAssignments(path, text, mf);
  RefuseFileWithoutTables(path, sniff, option, st);

  TableAssembler assembler{path, {}};
  CompensationTables out;
  for (const auto& [key, t] : st.enc) {
    const AxisScale& ax = mf.machine.axes[key.first];
    machine::CompensationTable table = assembler.Build(t, "$AA_ENC_COMP table of axis " + ax.name, ax);
    assembler.CheckValues(t, "$AA_ENC_COMP table of axis " + ax.name, ax);
    for (const auto& [i, v] : t.points) table.values.push_back(ToSi(ax, v.first));
    out.encoder.push_back({key.first, table});
  }
  for (const auto& [num, t] : st.cec) {
    const std::string what = "$AN_CEC table " + std::to_string(num);
    if (!t.input) throw assembler.Err(t.first_line, what + ": _INPUT_AXIS is missing");
    if (!t.output) throw assembler.Err(t.first_line, what + ": _OUTPUT_AXIS is missing");
    const int in_axis = mf.controller_axes.at(t.input->first);
    const int out_axis = mf.controller_axes.at(t.output->first);
    machine::CompensationTable table = assembler.Build(t, what, mf.machine.axes[in_axis]);
    assembler.CheckValues(t, what, mf.machine.axes[out_axis]);
    for (const auto& [i, v] : t.points) table.values.push_back(ToSi(mf.machine.axes[out_axis], v.first));
    out.cross_axis.push_back({in_axis, out_axis, table});
  }
  out.implausible = std::move(assembler.implausible);
  return out;
}

}  // namespace robomach::io
