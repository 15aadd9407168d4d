#include "robomach/io/machine_files.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/format17.h"
#include "robomach/io/number_format.h"
#include "robomach/io/parallel_rows.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {
namespace {

using machine::AxisKind;
using machine::AxisScale;

std::string Trim(std::string_view s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

std::string ReadWholeFile(const std::string& path) {
  // One read into a string of the file's size (a counts file of a 60 s,
  // 8 kHz record is 21 MB; a stringstream would copy it twice).
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError({path, 0, 0}, "cannot open file for reading");
  const std::streamoff size = in.tellg();
  std::string text;
  if (size > 0) {
    text.resize(static_cast<size_t>(size));
    in.seekg(0);
    in.read(text.data(), size);
    text.resize(static_cast<size_t>(in.gcount()));
  }
  // Whatever a size-less file (a pipe) still has.
  in.clear();
  std::ostringstream rest;
  rest << in.rdbuf();
  text += rest.str();
  return text;
}

double ToSi(const AxisScale& a, double file_value) {
  return a.kind == AxisKind::kLinear ? MmToM(file_value) : DegToRad(file_value);
}
double FromSi(const AxisScale& a, double si) { return a.kind == AxisKind::kLinear ? MToMm(si) : RadToDeg(si); }
std::string UnitSuffix(const AxisScale& a) { return a.kind == AxisKind::kLinear ? "_mm" : "_deg"; }

}  // namespace

// ---------------------------------------------------------------- machine file

MachineFile ReadMachineFile(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path);
  MachineFile f;
  f.path = path;
  const YamlDoc axes = doc["axes"];
  if (!axes.IsMap() || axes.Keys().empty()) throw axes.Error("expected a map of axis names to {resolution_*, origin_*}");
  for (const std::string& name : axes.Keys()) {
    const YamlDoc a = axes[name];
    AxisScale s;
    s.name = name;
    const bool mm = a.Has("resolution_mm") || a.Has("origin_mm");
    const bool deg = a.Has("resolution_deg") || a.Has("origin_deg");
    if (mm == deg) {
      throw a.Error("expected either resolution_mm and origin_mm (linear axis) or resolution_deg and origin_deg "
                    "(rotary axis)");
    }
    s.kind = mm ? AxisKind::kLinear : AxisKind::kRotary;
    const std::string u = mm ? "_mm" : "_deg";
    const double res = a["resolution" + u].Number();
    if (!(res > 0.0)) throw a["resolution" + u].Error("expected a resolution > 0, got " + FormatDouble(res));
    s.resolution = ToSi(s, res);
    s.origin = ToSi(s, a["origin" + u].Number());
    a.RejectUnknownKeys();
    f.machine.axes.push_back(s);
  }
  if (f.machine.axes.size() > static_cast<size_t>(8)) {
    throw axes.Error("at most 8 axes fit the 16-bit capture words of formats.md §8.2");
  }
  const YamlDoc k = doc["kinematics"];
  const std::string type = k["type"].String();
  if (type != "nutating_head_rotary_table") {
    throw k["type"].Error("unknown kinematics type '" + type + "'; known: nutating_head_rotary_table");
  }
  machine::NutatingHeadGeometry& g = f.geometry;
  g.nutation = DegToRad(k["nutation_deg"].NumberInRange(0.0, 90.0, false, true));
  g.pivot_length = MmToM(k["pivot_length_mm"].Number());
  g.tool_length = MmToM(k["tool_length_mm"].Number());
  const auto cc = k["c_centre_mm"].Numbers(2);
  g.c_centre = {MmToM(cc[0]), MmToM(cc[1])};
  const auto zo = k["zero_offset_mm"].Numbers(3);
  g.zero_offset = {MmToM(zo[0]), MmToM(zo[1]), MmToM(zo[2])};
  if (k.Has("errors")) {
    const YamlDoc e = k["errors"];
    if (e.Has("b_eccentricity_mm")) {
      const auto v = e["b_eccentricity_mm"].Numbers(2);
      g.b_eccentricity = {MmToM(v[0]), MmToM(v[1])};
    }
    if (e.Has("pivot_length_error_mm")) g.pivot_length_error = MmToM(e["pivot_length_error_mm"].Number());
    if (e.Has("c_eccentricity_mm")) {
      const auto v = e["c_eccentricity_mm"].Numbers(2);
      g.c_eccentricity = {MmToM(v[0]), MmToM(v[1])};
    }
    e.RejectUnknownKeys();
  } else {
    k.MarkUsed("errors");
  }
  k.RejectUnknownKeys();
  f.machine.kinematics = std::make_shared<machine::NutatingHeadRotaryTable>(g);
  try {
    f.machine.kinematic_axis = machine::MapKinematicAxes(f.machine.axes, *f.machine.kinematics);
  } catch (const std::invalid_argument& e) {
    throw axes.Error(e.what());
  }
  if (doc.Has("controller_axes")) {
    const YamlDoc ca = doc["controller_axes"];
    for (const std::string& name : ca.Keys()) {
      const std::string axis = ca[name].String();
      const int i = machine::FindAxis(f.machine.axes, axis);
      if (i < 0) throw ca[name].Error("axis '" + axis + "' is not under axes:");
      f.controller_axes[name] = i;
    }
  } else {
    doc.MarkUsed("controller_axes");
  }
  doc.RejectUnknownKeys();
  return f;
}

void WriteMachineFile(const std::string& path, const MachineFile& f) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "# machine file (formats.md §8.3)\naxes:\n";
    for (const AxisScale& a : f.machine.axes) {
      const std::string u = UnitSuffix(a);
      out << "  " << a.name << ": {resolution" << u << ": " << FormatDouble(FromSi(a, a.resolution)) << ", origin" << u
          << ": " << FormatDouble(FromSi(a, a.origin)) << "}\n";
    }
    const auto& g = f.geometry;
    out << "kinematics:\n  type: nutating_head_rotary_table\n"
        << "  nutation_deg: " << FormatDouble(RadToDeg(g.nutation)) << "\n"
        << "  pivot_length_mm: " << FormatDouble(MToMm(g.pivot_length)) << "\n"
        << "  tool_length_mm: " << FormatDouble(MToMm(g.tool_length)) << "\n"
        << "  c_centre_mm: [" << FormatDouble(MToMm(g.c_centre[0])) << ", " << FormatDouble(MToMm(g.c_centre[1]))
        << "]\n"
        << "  zero_offset_mm: [" << FormatDouble(MToMm(g.zero_offset[0])) << ", "
        << FormatDouble(MToMm(g.zero_offset[1])) << ", " << FormatDouble(MToMm(g.zero_offset[2])) << "]\n"
        << "  errors:\n"
        << "    b_eccentricity_mm: [" << FormatDouble(MToMm(g.b_eccentricity[0])) << ", "
        << FormatDouble(MToMm(g.b_eccentricity[1])) << "]\n"
        << "    pivot_length_error_mm: " << FormatDouble(MToMm(g.pivot_length_error)) << "\n"
        << "    c_eccentricity_mm: [" << FormatDouble(MToMm(g.c_eccentricity[0])) << ", "
        << FormatDouble(MToMm(g.c_eccentricity[1])) << "]\n";
    if (!f.controller_axes.empty()) {
      out << "controller_axes: {";
      bool first = true;
      for (const auto& [name, i] : f.controller_axes) {
        out << (first ? "" : ", ") << name << ": " << f.machine.axes[i].name;
        first = false;
      }
      out << "}\n";
    }
  });
}

// ---------------------------------------------------------- compensation file

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

CompensationTables ReadCompensationFile(const std::string& path, const MachineFile& mf) {
  const std::string text = ReadWholeFile(path);
  std::map<std::pair<int, int>, PendingTable> enc;  // (axis index, system) -> table
  std::map<int, PendingTable> cec;                  // table number -> table
  std::set<std::string> seen;                       // duplicate detection: name + index
  std::map<std::string, int> seen_line;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  auto err = [&](int l, const std::string& m) { return InputError({path, l, 0}, m); };
  while (std::getline(in, raw)) {
    ++line;
    const auto oa = ParseAssignment(raw, line);
    if (!oa) continue;
    const Assignment& a = *oa;
    const bool enc_var = a.name.rfind("AA_ENC_COMP", 0) == 0;
    const bool cec_var = a.name.rfind("AN_CEC", 0) == 0;
    if (!enc_var && !cec_var) continue;  // some other variable: not a table assignment
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
    machine::CompensationTable table;
    table.min = ToSi(input_axis, t.min->first);
    table.step = ToSi(input_axis, t.step->first);
    return std::pair{table, n};
  };
  CompensationTables out;
  for (const auto& [key, t] : enc) {
    const AxisScale& ax = mf.machine.axes[key.first];
    auto [table, n] = build(t, "$AA_ENC_COMP table of axis " + ax.name, ax);
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
    for (const auto& [i, v] : t.points) table.values.push_back(ToSi(mf.machine.axes[out_axis], v.first));
    out.cross_axis.push_back({in_axis, out_axis, table});
  }
  return out;
}

// ------------------------------------------------------------ temperature log

std::vector<machine::TemperatureCompensation> ReadTemperatureLog(const std::string& path, const MachineFile& mf) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"t_s", "axis", "K0_mm", "tan_beta", "P0_mm"}) t.RequireColumn(c);
  std::map<int, machine::TemperatureCompensation> by_axis;
  std::map<int, int> last_line;
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string name = t.Text(r, "axis");
    const int axis = machine::FindAxis(mf.machine.axes, name);
    if (axis < 0) throw t.ErrorAt(r, "axis", "unknown axis '" + name + "'; the machine file " + mf.path + " has no such axis");
    if (mf.machine.axes[axis].kind != AxisKind::kLinear) {
      throw t.ErrorAt(r, "axis", "axis " + name + " is rotary; the log's K0_mm and P0_mm are for linear axes");
    }
    machine::TemperatureRow row;
    row.t_s = t.Number(r, "t_s");
    row.k0 = MmToM(t.Number(r, "K0_mm"));
    row.tan_beta = t.Number(r, "tan_beta");
    row.p0 = MmToM(t.Number(r, "P0_mm"));
    auto& tc = by_axis[axis];
    tc.axis = axis;
    if (!tc.rows.empty() && !(row.t_s > tc.rows.back().t_s)) {
      throw t.ErrorAt(r, "t_s", "time must increase for axis " + name + ": " + FormatDouble(row.t_s) +
                                    " s after " + FormatDouble(tc.rows.back().t_s) + " s (line " +
                                    std::to_string(last_line[axis]) + ")");
    }
    last_line[axis] = t.line(r);
    tc.rows.push_back(row);
  }
  std::vector<machine::TemperatureCompensation> out;
  for (auto& [a, tc] : by_axis) out.push_back(std::move(tc));
  return out;
}

// ----------------------------------------------------------------- counts file

machine::CountsRecord ReadCountsFile(const std::string& path, const MachineFile& mf) {
  // A dedicated reader: a 60 s record at 8 kHz has 480,000 rows, and
  // axis-acquire must finish in under a second (CsvTable keeps every cell as
  // a string). Same rules as CsvTable: '#' comments, header by name, unknown
  // columns ignored.
  const std::string text = ReadWholeFile(path);
  const size_t n_axes = mf.machine.axes.size();
  machine::CountsRecord rec;
  rec.num_axes = static_cast<int>(n_axes);
  std::vector<int> col_of_axis(n_axes, -1);
  int t_col = -1, num_cols = 0, header_line = 0;
  size_t pos = 0;
  int line = 0;
  std::vector<std::string_view> cells;
  std::vector<std::string> header;
  {
    const size_t lines = static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
    rec.t_s.reserve(lines);
    rec.counts.reserve(lines * n_axes);
  }
  const char* const text_end = text.data() + text.size();
  while (pos < text.size()) {
    const char* l_begin = text.data() + pos;
    const char* l_end = static_cast<const char*>(std::memchr(l_begin, '\n', static_cast<size_t>(text_end - l_begin)));
    if (l_end == nullptr) l_end = text_end;
    pos = static_cast<size_t>(l_end - text.data()) + 1;
    ++line;
    if (l_end > l_begin && l_end[-1] == '\r') --l_end;
    if (l_end == l_begin || *l_begin == '#') continue;
    cells.clear();
    for (const char* a = l_begin;;) {
      const char* c = static_cast<const char*>(std::memchr(a, ',', static_cast<size_t>(l_end - a)));
      const char* e = c == nullptr ? l_end : c;
      const char* b = a;
      while (b < e && (*b == ' ' || *b == '\t')) ++b;
      while (e > b && (e[-1] == ' ' || e[-1] == '\t')) --e;
      cells.emplace_back(b, static_cast<size_t>(e - b));
      if (c == nullptr) break;
      a = c + 1;
    }
    if (header_line == 0) {
      header_line = line;
      num_cols = static_cast<int>(cells.size());
      for (int c = 0; c < num_cols; ++c) header.emplace_back(cells[c]);
      for (int c = 0; c < num_cols; ++c) {
        if (header[c] == "t_s") t_col = c;
        for (size_t ax = 0; ax < n_axes; ++ax) {
          if (header[c] == mf.machine.axes[ax].name + "_count") col_of_axis[ax] = c;
        }
      }
      if (t_col < 0) throw InputError({path, line, 0}, "missing required column 't_s'");
      for (size_t ax = 0; ax < n_axes; ++ax) {
        if (col_of_axis[ax] < 0) {
          throw InputError({path, line, 0}, "missing required column '" + mf.machine.axes[ax].name +
                                                "_count' (axis " + mf.machine.axes[ax].name + " of " + mf.path + ")");
        }
      }
      continue;
    }
    if (static_cast<int>(cells.size()) > num_cols) {
      throw InputError({path, line, 0}, "expected " + std::to_string(num_cols) + " cells as in the header, got " +
                                            std::to_string(cells.size()));
    }
    auto cell_at = [&](int c) { return c < static_cast<int>(cells.size()) ? cells[c] : std::string_view(); };
    double t = 0.0;
    {
      const std::string_view s = cell_at(t_col);
      const auto r = std::from_chars(s.data(), s.data() + s.size(), t);
      if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(t)) {
        throw InputError({path, line, 0}, "column t_s: expected a number, got \"" + std::string(s) + "\"");
      }
    }
    if (!rec.t_s.empty() && !(t > rec.t_s.back())) {
      throw InputError({path, line, 0}, "column t_s: time must increase, got " + FormatDouble(t) + " s after " +
                                            FormatDouble(rec.t_s.back()) + " s");
    }
    rec.t_s.push_back(t);
    for (size_t ax = 0; ax < n_axes; ++ax) {
      const std::string_view s = cell_at(col_of_axis[ax]);
      std::int64_t v = 0;
      const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
      if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size()) {
        throw InputError({path, line, 0}, "column " + header[col_of_axis[ax]] + ": expected a whole number of counts, got \"" +
                                              std::string(s) + "\"");
      }
      if (rec.t_s.size() == 1 && v != 0) {
        throw InputError({path, line, 0}, "column " + header[col_of_axis[ax]] +
                                              ": the first row is the reference position and must hold 0 for every "
                                              "axis (formats.md §8.1), got " + std::string(s));
      }
      rec.counts.push_back(v);
    }
  }
  if (header_line == 0) throw InputError({path, 0, 0}, "no header row");
  if (rec.t_s.empty()) throw InputError({path, header_line, 0}, "no data rows after the header");
  return rec;
}

CountsWriter::CountsWriter(std::ostream& out, const std::vector<AxisScale>& axes,
                           const std::vector<std::pair<std::string, std::string>>& metadata)
    : out_(out), num_axes_(static_cast<int>(axes.size())) {
  for (const auto& [k, v] : metadata) out_ << "# " << k << ": " << v << "\n";
  out_ << "t_s";
  for (const auto& a : axes) out_ << "," << a.name << "_count";
  out_ << "\n";
}

void CountsWriter::Row(double t_s, const std::int64_t* counts) {
  char buf[32];
  buffer_.clear();
  auto r = std::to_chars(buf, buf + sizeof buf, t_s);
  buffer_.append(buf, r.ptr);
  for (int a = 0; a < num_axes_; ++a) {
    buffer_.push_back(',');
    r = std::to_chars(buf, buf + sizeof buf, counts[a]);
    buffer_.append(buf, r.ptr);
  }
  buffer_.push_back('\n');
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
}

// ------------------------------------------------------------ programmed path

machine::ProgrammedPath ReadProgramFile(const std::string& path) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"x_mm", "y_mm", "z_mm", "i", "j", "k"}) t.RequireColumn(c);
  std::vector<Eigen::Vector3d> tips, axes;
  for (int r = 0; r < t.num_rows(); ++r) {
    tips.emplace_back(MmToM(t.Number(r, "x_mm")), MmToM(t.Number(r, "y_mm")), MmToM(t.Number(r, "z_mm")));
    const Eigen::Vector3d k(t.Number(r, "i"), t.Number(r, "j"), t.Number(r, "k"));
    if (!(k.norm() > 1e-9)) throw t.ErrorAt(r, "i", "the tool axis (i, j, k) is zero");
    axes.push_back(k);
  }
  if (tips.size() < 2) throw InputError({path, t.header_line(), 0}, "expected at least 2 points of the path");
  try {
    return machine::ProgrammedPath(tips, axes);
  } catch (const std::invalid_argument& e) {
    throw InputError({path, 0, 0}, e.what());
  }
}

// --------------------------------------------------------------- acquired path

namespace {
constexpr size_t kMaxAxes = 8;                       // 16-bit capture words (formats.md §8.2)
constexpr size_t kMaxRowNumbers = 1 + kMaxAxes + 9;  // t_s, axes, tip, axis, 3 contour columns
}  // namespace

AcquiredPathWriter::AcquiredPathWriter(std::ostream& out, const std::vector<AxisScale>& axes, bool contour)
    : out_(out), axes_(axes) {
  if (axes_.size() > kMaxAxes) throw std::invalid_argument("AcquiredPathWriter: more than 8 axes");
  out_ << "t_s";
  for (const auto& a : axes_) out_ << "," << a.name << UnitSuffix(a);
  out_ << ",x_mm,y_mm,z_mm,i,j,k";
  if (contour) out_ << ",contour_error_mm,axis_error_deg,path_s_mm";
  out_ << "\n";
}

void AcquiredPathWriter::Row(double t_s, const machine::AcquiredSample& s, const machine::ContourError* c) {
  buffer_.clear();
  AppendRow(&buffer_, t_s, s, c);
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
}

void AcquiredPathWriter::AppendRow(std::string* buffer, double t_s, const machine::AcquiredSample& s,
                                   const machine::ContourError* c) const {
  // The row is built in a stack buffer and appended once (this runs 480,000
  // times for a 60 s, 8 kHz record).
  char row[kMaxRowNumbers * (kMaxChars17 + 1) + 1];
  char* p = row;
  p = std::to_chars(p, p + kMaxChars17, t_s).ptr;  // t_s copied from the counts: shortest exact text
  auto put = [&](double v) {
    *p++ = ',';
    p = WriteDouble17(v, p);  // "%.17g", fast
  };
  for (size_t a = 0; a < axes_.size(); ++a) put(FromSi(axes_[a], s.real[a]));
  for (int i = 0; i < 3; ++i) put(MToMm(s.pose.p_W(i)));
  for (int i = 0; i < 3; ++i) put(s.pose.k_W(i));
  if (c != nullptr) {
    put(MToMm(c->distance));
    put(RadToDeg(c->axis_angle));
    put(MToMm(c->s));
  }
  *p++ = '\n';
  buffer->append(row, p);
}

std::vector<machine::ContourError> WriteAcquiredPath(std::ostream& out, const machine::CountsRecord& record,
                                                     const std::vector<AxisScale>& axes,
                                                     machine::Acquisition* acquisition,
                                                     machine::ContourTracker* tracker, int threads) {
  const AcquiredPathWriter w(out, axes, tracker != nullptr);
  const long rows = record.rows();
  const size_t n = axes.size();
  std::vector<machine::ContourError> contour(tracker != nullptr ? static_cast<size_t>(rows) : 0);
  // 4096 rows are ~1.1 MB of text: small enough for the pipeline to start
  // formatting early, large enough that the hand-offs cost nothing.
  constexpr long kChunk = 4096;
  const int slots = 2 * std::max(1, threads) + 2;
  std::vector<std::vector<machine::AcquiredSample>> samples(static_cast<size_t>(slots),
                                                             std::vector<machine::AcquiredSample>(kChunk));
  WritePipelined(
      out, rows, kChunk, slots,
      [&](long first, long last, int slot) {
        auto& s = samples[static_cast<size_t>(slot)];
        for (long r = first; r < last; ++r) {
          s[static_cast<size_t>(r - first)] = acquisition->Process(record.t_s[r], record.counts.data() + r * n);
          if (tracker != nullptr) contour[static_cast<size_t>(r)] = tracker->Next(s[static_cast<size_t>(r - first)].pose);
        }
      },
      [&](long first, long last, int slot, std::string* text) {
        const auto& s = samples[static_cast<size_t>(slot)];
        text->reserve(static_cast<size_t>(last - first) * 320);
        for (long r = first; r < last; ++r) {
          w.AppendRow(text, record.t_s[r], s[static_cast<size_t>(r - first)],
                      tracker != nullptr ? &contour[static_cast<size_t>(r)] : nullptr);
        }
      },
      threads);
  return contour;
}

// -------------------------------------------------------------------- ISO runs

IsoRuns ReadIsoRuns(const std::string& path) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"axis", "run", "direction"}) t.RequireColumn(c);
  const bool mm = t.HasColumn("target_mm") || t.HasColumn("measured_mm");
  const bool deg = t.HasColumn("target_deg") || t.HasColumn("measured_deg");
  if (mm && deg) {
    throw InputError({path, t.header_line(), 0},
                     "a runs file holds one kind of axis: either target_mm,measured_mm or target_deg,measured_deg, not both");
  }
  if (!mm && !deg) throw InputError({path, t.header_line(), 0}, "missing required columns target_mm,measured_mm (or target_deg,measured_deg)");
  IsoRuns runs;
  runs.rotary = deg;
  const std::string u = deg ? "_deg" : "_mm";
  t.RequireColumn("target" + u);
  t.RequireColumn("measured" + u);
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string axis = t.Text(r, "axis");
    machine::Iso230Approach a;
    a.target = t.Number(r, "target" + u);
    const double run = t.Number(r, "run");
    if (run != std::floor(run) || run < 1 || run > 1e6) throw t.ErrorAt(r, "run", "expected a run number 1, 2, ...");
    a.run = static_cast<int>(run);
    const std::string dir = t.Text(r, "direction");
    if (dir != "+" && dir != "-") throw t.ErrorAt(r, "direction", "expected + or -, got \"" + dir + "\"");
    a.up = dir == "+";
    const double dev = t.Number(r, "measured" + u) - a.target;
    a.deviation = deg ? machine::WrapDeviationDeg(dev) : dev;
    if (!runs.approaches.count(axis)) runs.axis_order.push_back(axis);
    for (const auto& b : runs.approaches[axis]) {
      if (b.target == a.target && b.run == a.run && b.up == a.up) {
        throw t.ErrorAtRow(r, "axis " + axis + ", target " + FormatDouble(a.target) + ", run " + std::to_string(a.run) +
                                  ", direction " + dir + " appears twice");
      }
    }
    runs.approaches[axis].push_back(a);
  }
  if (runs.axis_order.empty()) throw InputError({path, t.header_line(), 0}, "no data rows");
  return runs;
}

}  // namespace robomach::io
