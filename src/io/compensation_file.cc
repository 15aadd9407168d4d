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

}  // namespace

CompensationTables ReadCompensationFile(const std::string& path, const MachineFile& mf, const std::string& option) {
  // A PNG, a YAML, a CSV (the temperature log given as the tables) is named
  // as what it is before the lines are read as assignments.
  const FileSniff sniff = SniffFileKind(path);
  RequireFileKind(path, {FileKind::kMpf}, kCompensationFileFormat, option);
  const std::string text = ReadWholeFile(path);
  std::map<std::pair<int, int>, PendingTable> enc;  // (axis index, system) -> table
  std::map<int, PendingTable> cec;                  // table number -> table
  std::set<std::string> seen;                       // duplicate detection: name + index
  std::map<std::string, int> seen_line;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  auto err = [&](int l, const std::string& m) { return InputError({path, l, 0}, m); };
  int table_assignments = 0;
  int first_line = 0;      // the first line that is neither blank nor a comment
  std::string first_text;  // and its text, for the message of a file without tables
  while (std::getline(in, raw)) {
    ++line;
    if (first_line == 0) {
      const std::string t = Trim(raw);
      if (!t.empty() && t[0] != ';' && t[0] != '#') {
        first_line = line;
        first_text = t.size() > 60 ? t.substr(0, 60) + "..." : t;
      }
    }
    const auto oa = ParseAssignment(raw, line);
    if (!oa) continue;
    const Assignment& a = *oa;
    const bool enc_var = a.name.rfind("AA_ENC_COMP", 0) == 0;
    const bool cec_var = a.name.rfind("AN_CEC", 0) == 0;
    if (!enc_var && !cec_var) continue;  // some other variable: not a table assignment
    ++table_assignments;
    if (!a.index.empty() && a.index[0] == "<unclosed>") throw err(line, "$" + a.name + ": unclosed '['");
    std::string key = a.name + "[";
    for (const auto& i : a.index) key += i + ",";
    if (auto it = seen_line.find(key); it != seen_line.end()) {
      throw err(line, "$" + a.name + " is assigned twice for the same index (first on line " +
                          std::to_string(it->second) + ")");
    }
    seen_line[key] = line;
    auto number = [&](const std::string& what) {
      double v = 0.0;
      if (!ParseFiniteNumber(a.value, &v)) throw err(line, "$" + a.name + ": expected a number " + what + ", got \"" + a.value + "\"");
      return v;
    };
    auto integer = [&](const std::string& text, const std::string& what) {
      int v = 0;
      const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
      if (r.ec != std::errc() || r.ptr != text.data() + text.size()) {
        throw err(line, "$" + a.name + ": expected " + what + ", got \"" + text + "\"");
      }
      return v;
    };
    auto axis_of = [&](const std::string& name) {
      auto it = mf.controller_axes.find(name);
      if (it == mf.controller_axes.end()) {
        std::string known;
        for (const auto& [n, i] : mf.controller_axes) known += (known.empty() ? "" : ", ") + n;
        throw err(line, "$" + a.name + ": unknown axis '" + name + "'; controller_axes of " + mf.path + " has: " +
                            (known.empty() ? "(none)" : known));
      }
      return it->second;
    };
    auto want_args = [&](size_t n) {
      if (a.index.size() != n) {
        throw err(line, "$" + a.name + ": expected " + std::to_string(n) + " index value(s) in [], got " +
                            std::to_string(a.index.size()));
      }
    };
    if (enc_var) {
      const std::string field = a.name.substr(std::string("AA_ENC_COMP").size());
      if (field.empty()) {
        want_args(3);
        const int sys = integer(a.index[0], "a measuring system number");
        if (sys != 0) throw err(line, "$AA_ENC_COMP: only measuring system 0 is supported, got " + a.index[0]);
        const int point = integer(a.index[1], "a point index >= 0");
        if (point < 0) throw err(line, "$AA_ENC_COMP: expected a point index >= 0, got " + a.index[1]);
        const int axis = axis_of(a.index[2]);
        auto& t = enc[{axis, sys}];
        if (t.first_line == 0) t.first_line = line;
        t.points[point] = {number("(the compensation value)"), line};
        continue;
      }
      want_args(2);
      const int sys = integer(a.index[0], "a measuring system number");
      if (sys != 0) throw err(line, "$" + a.name + ": only measuring system 0 is supported, got " + a.index[0]);
      const int axis = axis_of(a.index[1]);
      auto& t = enc[{axis, sys}];
      if (t.first_line == 0) t.first_line = line;
      if (field == "_STEP") {
        t.step = {number("(the point spacing)"), line};
      } else if (field == "_MIN") {
        t.min = {number("(the first point's position)"), line};
      } else if (field == "_MAX") {
        t.max = {number("(the last point's position)"), line};
      } else if (field == "_IS_MODULO") {
        if (number("(0 or 1)") != 0.0) throw err(line, "$" + a.name + ": modulo tables are not supported (expected 0)");
      } else {
        throw err(line, "$" + a.name + ": not supported (expected $AA_ENC_COMP, _STEP, _MIN, _MAX, _IS_MODULO)");
      }
      continue;
    }
    // $AN_CEC...
    const std::string field = a.name.substr(std::string("AN_CEC").size());
    if (field.empty()) {
      want_args(2);
      const int table = integer(a.index[0], "a table number >= 0");
      const int point = integer(a.index[1], "a point index >= 0");
      if (table < 0 || point < 0) throw err(line, "$AN_CEC: expected a table number and point index >= 0");
      auto& t = cec[table];
      if (t.first_line == 0) t.first_line = line;
      t.points[point] = {number("(the compensation value)"), line};
      continue;
    }
    want_args(1);
    const int table = integer(a.index[0], "a table number >= 0");
    auto& t = cec[table];
    if (t.first_line == 0) t.first_line = line;
    if (field == "_INPUT_AXIS") {
      axis_of(a.value);
      t.input = {a.value, line};
    } else if (field == "_OUTPUT_AXIS") {
      axis_of(a.value);
      t.output = {a.value, line};
    } else if (field == "_STEP") {
      t.step = {number("(the point spacing)"), line};
    } else if (field == "_MIN") {
      t.min = {number("(the first point's position)"), line};
    } else if (field == "_MAX") {
      t.max = {number("(the last point's position)"), line};
    } else if (field == "_IS_MODULO") {
      if (number("(0 or 1)") != 0.0) throw err(line, "$" + a.name + ": modulo tables are not supported (expected 0)");
    } else if (field == "_DIRECTION") {
      if (number("(0, 1 or -1)") != 0.0) {
        throw err(line, "$AN_CEC_DIRECTION: only 0 (both directions) is supported, got " + a.value);
      }
    } else if (field == "_MULT_BY_TABLE") {
      if (number("(a table number or 0)") != 0.0) {
        throw err(line, "$AN_CEC_MULT_BY_TABLE: multiplied tables are not supported (expected 0), got " + a.value);
      }
    } else {
      throw err(line, "$" + a.name + ": not supported (expected $AN_CEC, _INPUT_AXIS, _OUTPUT_AXIS, _STEP, _MIN, "
                      "_MAX, _IS_MODULO, _DIRECTION, _MULT_BY_TABLE)");
    }
  }

  // A file without a single table assignment holds nothing to compensate
  // with: applying none would give the uncompensated path without a word
  // (docs/conventions.md: a file the tool cannot use is bad data, 65).
  if (table_assignments == 0) {
    FileSniff what = sniff;
    what.description += " without a single $AA_ENC_COMP or $AN_CEC table assignment";
    if (first_line > 0) {
      throw err(first_line, WrongFileKindMessage(what, kCompensationFileFormat, option) + " (this line is \"" + first_text +
                                "\")");
    }
    throw err(0, WrongFileKindMessage(what, kCompensationFileFormat, option));
  }

  // Values in the output axis's unit: refused when impossible, one finding
  // per table (its largest value) when implausible.
  std::vector<std::string> out_implausible;
  auto check_values = [&](const PendingTable& t, const std::string& what, const AxisScale& out_axis) {
    const bool mm = out_axis.kind == machine::AxisKind::kLinear;
    const std::string unit = mm ? "mm" : "deg";
    const std::pair<double, int>* largest = nullptr;
    for (const auto& [i, v] : t.points) {
      if (!largest || std::abs(v.first) > std::abs(largest->first)) largest = &v;
    }
    if (!largest) return;
    const double m = std::abs(largest->first);
    if (m > (mm ? kMaxCompensationMm : kMaxCompensationDeg)) {
      throw err(largest->second, what + ": value " + FormatDouble(largest->first) + " " + unit + " is beyond the " +
                                     FormatDouble(mm ? kMaxCompensationMm : kMaxCompensationDeg) + " " + unit +
                                     " any compensation table corrects: " +
                                     (mm ? "values in um or nm typed in the mm table?" : "values in arc-seconds typed in the deg table?"));
    }
    if (m > (mm ? kMaxPlausibleCompensationMm : kMaxPlausibleCompensationDeg)) {
      out_implausible.push_back("implausible (unit mistake?): " + path + ":" + std::to_string(largest->second) + ": " +
                                what + ": value " + FormatDouble(largest->first) + " " + unit + " is outside the +-" +
                                FormatDouble(mm ? kMaxPlausibleCompensationMm : kMaxPlausibleCompensationDeg) + " " + unit +
                                " of compensation tables (they hold a few um to tens of um): " +
                                (mm ? "values in um typed in the mm table?"
                                    : "values in arc-seconds or millidegrees typed in the deg table?"));
    }
  };

  // Assemble and check each table (formats.md §8.4: MAX = MIN + (n - 1) STEP).
  auto build = [&](const PendingTable& t, const std::string& what, const AxisScale& input_axis) {
    if (t.points.empty()) throw err(t.first_line, what + ": the table has no points");
    if (!t.step) throw err(t.first_line, what + ": _STEP is missing");
    if (!t.min) throw err(t.first_line, what + ": _MIN is missing");
    if (!t.max) throw err(t.first_line, what + ": _MAX is missing");
    int expect = 0;
    for (const auto& [i, v] : t.points) {
      if (i != expect) throw err(v.second, what + ": point " + std::to_string(expect) + " is missing before point " + std::to_string(i));
      ++expect;
    }
    if (!(t.step->first > 0.0)) {
      throw err(t.step->second, what + ": _STEP must be > 0, got " + FormatDouble(t.step->first));
    }
    const int n = static_cast<int>(t.points.size());
    const double expected_max = t.min->first + (n - 1) * t.step->first;
    if (std::abs(t.max->first - expected_max) > 1e-9 * std::max({1.0, std::abs(expected_max), std::abs(t.max->first)})) {
      throw err(t.max->second, what + ": _MAX " + FormatDouble(t.max->first) + " must equal _MIN + (points - 1) * _STEP = " +
                                   FormatDouble(t.min->first) + " + " + std::to_string(n - 1) + " * " +
                                   FormatDouble(t.step->first) + " = " + FormatDouble(expected_max));
    }
    // Positions of a linear input axis within machine travels (um typed
    // for mm moves them x1000).
    if (input_axis.kind == machine::AxisKind::kLinear) {
      const auto& far = std::abs(t.min->first) > std::abs(t.max->first) ? *t.min : *t.max;
      if (std::abs(far.first) > kMaxPlausibleMachineLengthMm) {
        out_implausible.push_back("implausible (unit mistake?): " + path + ":" + std::to_string(far.second) + ": " + what +
                                  ": position " + FormatDouble(far.first) + " mm is outside the +-" +
                                  FormatDouble(kMaxPlausibleMachineLengthMm) +
                                  " mm of machine tool travels: positions in um typed in the mm table?");
      }
    }
    machine::CompensationTable table;
    table.min = ToSi(input_axis, t.min->first);
    table.step = ToSi(input_axis, t.step->first);
    return std::pair{table, n};
  };
  CompensationTables out;
  for (const auto& [key, t] : enc) {
    const AxisScale& ax = mf.machine.axes[key.first];
    auto [table, n] = build(t, "$AA_ENC_COMP table of axis " + ax.name, ax);
    check_values(t, "$AA_ENC_COMP table of axis " + ax.name, ax);
    for (const auto& [i, v] : t.points) table.values.push_back(ToSi(ax, v.first));
    out.encoder.push_back({key.first, table});
  }
  for (const auto& [num, t] : cec) {
    const std::string what = "$AN_CEC table " + std::to_string(num);
    if (!t.input) throw err(t.first_line, what + ": _INPUT_AXIS is missing");
    if (!t.output) throw err(t.first_line, what + ": _OUTPUT_AXIS is missing");
    const int in_axis = mf.controller_axes.at(t.input->first);
    const int out_axis = mf.controller_axes.at(t.output->first);
    auto [table, n] = build(t, what, mf.machine.axes[in_axis]);
    check_values(t, what, mf.machine.axes[out_axis]);
    for (const auto& [i, v] : t.points) table.values.push_back(ToSi(mf.machine.axes[out_axis], v.first));
    out.cross_axis.push_back({in_axis, out_axis, table});
  }
  out.implausible = std::move(out_implausible);
  return out;
}

}  // namespace robomach::io
