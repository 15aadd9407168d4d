#include "robomach/io/csv_table.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "robomach/common/closest_name.h"
#include "text.h"

namespace robomach::io {
namespace {

// Splits one CSV line (RFC 4180 quoting, no embedded newlines).
std::vector<std::string> SplitLine(std::string_view line, const std::string& path, int line_no) {
  std::vector<std::string> cells;
  std::string cur;
  bool quoted = false, was_quoted = false;
  // Whether `cur` is blank so far: a quote opens a quoted cell only there.
  // (Trimming `cur` at every quote made a line of quotes quadratic in its
  // length; issue #22.)
  bool blank = true;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < line.size() && line[i + 1] == '"') {
          cur += '"';
          ++i;
        } else {
          quoted = false;
        }
      } else {
        cur += c;
      }
    } else if (c == '"' && blank) {
      quoted = true;
      was_quoted = true;
      blank = false;
      cur.clear();
    } else if (c == ',') {
      cells.push_back(was_quoted ? cur : Trim(cur));
      cur.clear();
      was_quoted = false;
      blank = true;
    } else {
      cur += c;
      if (!std::isspace(static_cast<unsigned char>(c))) blank = false;
    }
  }
  if (quoted) {
    throw InputError({path, line_no, 0}, "unterminated quoted cell");
  }
  cells.push_back(was_quoted ? cur : Trim(cur));
  return cells;
}

}  // namespace

std::string JointColumnHint(const CsvTable& table, int joint, int num_joints) {
  std::vector<std::string> others{"pose_id", "case_id"};
  for (int k = 0; k < num_joints; ++k) {
    if (k == joint) continue;
    others.push_back("q" + std::to_string(k + 1) + "_deg");
    others.push_back("q" + std::to_string(k + 1) + "_rad");
  }
  const std::string stem = "q" + std::to_string(joint + 1);
  const std::string deg = table.CloseColumn(stem + "_deg", others);
  return deg.empty() ? table.CloseColumn(stem + "_rad", others) : deg;
}

bool ParseFiniteNumber(std::string_view text, double* value) {
  std::string t = Trim(text);
  if (t.empty()) return false;
  const char* begin = t.data();
  if (*begin == '+') ++begin;  // from_chars does not take a leading '+'
  double v = 0.0;
  auto [ptr, ec] = std::from_chars(begin, t.data() + t.size(), v);
  if (ec != std::errc() || ptr != t.data() + t.size()) return false;
  if (!std::isfinite(v)) return false;
  *value = v;
  return true;
}

CsvTable CsvTable::ReadFile(const std::string& path, const std::string& expected) {
  RequireFileKind(path, {FileKind::kCsv}, expected);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MissingFileError({path, 0, 0}, "cannot open file for reading");
  std::stringstream ss;
  ss << in.rdbuf();
  return Parse(ss.str(), path);
}

CsvTable CsvTable::Parse(std::string_view text, const std::string& path) {
  CsvTable t;
  t.path_ = path;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 BOM
  int line_no = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view raw = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
    const std::string line = Trim(raw);
    if (line.empty()) {
      if (nl == text.size()) break;
      continue;
    }
    if (line[0] == '#') {
      if (t.header_.empty()) {
        const std::string body = Trim(std::string_view(line).substr(1));
        const size_t colon = body.find(':');
        if (colon != std::string::npos && colon > 0) {
          const std::string key = Lower(Trim(std::string_view(body).substr(0, colon)));
          if (key.find(' ') == std::string::npos) {
            t.metadata_[key] = Trim(std::string_view(body).substr(colon + 1));
          }
        }
      }
      continue;
    }
    std::vector<std::string> cells = SplitLine(line, path, line_no);
    if (t.header_.empty()) {
      // A spreadsheet in a German or French locale saves ';' (or a tab)
      // between the cells: one header cell holding every name.
      if (cells.size() == 1) {
        for (const char sep : {';', '\t'}) {
          if (cells[0].find(sep) == std::string::npos) continue;
          throw InputError({path, line_no, 0},
                           std::string("the header '") + cells[0] + "' is separated by " +
                               (sep == ';' ? "semicolons" : "tabs") +
                               "; robomach's CSV files separate cells with commas and use a decimal point "
                               "(docs/formats.md): save the table as CSV with ',' as the separator (a "
                               "spreadsheet set to a German or French locale writes ';' and decimal commas)");
        }
      }
      std::map<std::string_view, size_t> first;  // (not a pairwise check: quadratic in the columns)
      for (size_t c = 0; c < cells.size(); ++c) {
        if (cells[c].empty()) {
          throw InputError({path, line_no, 0},
                           "header: column " + std::to_string(c + 1) + " has no name");
        }
        const auto [it, fresh] = first.emplace(cells[c], c);
        if (!fresh) {
          throw InputError({path, line_no, 0}, "header: column '" + cells[c] + "' appears twice (columns " +
                                                   std::to_string(it->second + 1) + " and " +
                                                   std::to_string(c + 1) + ")");
        }
      }
      t.header_ = std::move(cells);
      t.header_line_ = line_no;
      continue;
    }
    if (cells.size() > t.header_.size()) {
      throw InputError({path, line_no, 0},
                       "expected at most " + std::to_string(t.header_.size()) +
                           " cells as in the header, got " + std::to_string(cells.size()) +
                           " (a decimal comma, or an unquoted comma in a text cell?)");
    }
    cells.resize(t.header_.size());
    t.rows_.push_back(std::move(cells));
    t.lines_.push_back(line_no);
    if (nl == text.size()) break;
  }
  if (t.header_.empty()) {
    throw InputError({path, 0, 0}, "no header row found (file empty or only comments)");
  }
  return t;
}

int CsvTable::ColumnIndex(std::string_view name) const {
  for (size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] == name) return static_cast<int>(i);
  }
  return -1;
}

void CsvTable::RequireColumn(std::string_view name, std::string_view own) const {
  if (HasColumn(name)) return;
  std::string have;
  for (const auto& h : header_) have += (have.empty() ? "" : ",") + h;
  throw InputError({path_, header_line_, 0},
                   "missing required column '" + std::string(name) + "'" + CloseColumn(name) +
                       "; the header has: " + have + LooksLike(own));
}

std::string CsvTable::LooksLike(std::string_view own) const {
  // Each of robomach's CSV formats by the columns only it has (formats.md).
  const auto has = [&](std::initializer_list<const char*> cols) {
    for (const char* c : cols) {
      if (!HasColumn(c)) return false;
    }
    return true;
  };
  std::string kind, tag;
  if (has({"freq_hz", "re", "im"}) || has({"freq_hz", "response", "excitation"})) {
    kind = "a measured or predicted FRF (docs/formats.md §3; freq_hz, re, im)", tag = "frf";
  } else if (has({"freq_hz", "damping_ratio"})) {
    kind = "a modal table (docs/formats.md §4; freq_hz, damping_ratio)", tag = "modal";
  } else if (has({"case_id"})) {
    kind = "a laser-tracker load test (docs/formats.md §2; case_id, x0_mm..)", tag = "tracker";
  } else if (has({"pose_id", "rope_ux", "pulley_x_mm"})) {
    kind = "a load-test plan (kq-identify --plan; pose_id, q1_deg.., rope_ux.., pulley_x_mm..), for tracker-synth "
           "--plan-file";
    tag = "plan";
  } else if (has({"pose_id", "q1_deg"}) || has({"pose_id", "q1_rad"})) {
    kind = "a posture file (docs/formats.md §1; pose_id, q1_deg..)", tag = "posture";
  } else if (has({"x_mm", "y_mm", "z_mm", "tool_i"})) {
    kind = "a tool path (x_mm, y_mm, z_mm, tool_i..)", tag = "path";
  } else if (has({"target_mm", "measured_mm"}) || has({"target_deg", "measured_deg"})) {
    kind = "ISO 230-2 runs (docs/formats.md §8; target_mm, measured_mm)", tag = "iso";
  } else if (has({"time_s", "force_N"})) {
    kind = "hammer records (time_s, force_N)", tag = "hammer";
  }
  if (tag == own) return "";
  return kind.empty() ? "" : "; the columns are those of " + kind + ": the file for another option?";
}

std::string CsvTable::CellPosition(std::string_view column) const {
  // An empty cell shows nothing to find it by: count the commas.
  return " (cell " + std::to_string(ColumnIndex(column) + 1) + " of " + std::to_string(header_.size()) +
         " in the row, after " + std::to_string(ColumnIndex(column)) + " commas)";
}

std::string CsvTable::CloseColumn(std::string_view name, const std::vector<std::string>& exclude) const {
  std::vector<std::string> candidates;
  for (const std::string& h : header_) {
    if (std::find(exclude.begin(), exclude.end(), h) == exclude.end()) candidates.push_back(h);
  }
  const std::string close = ClosestName(std::string(name), candidates);
  if (close.empty() || close == name) return "";
  // Column names are short and alike (case_id, pose_id): one edit per four
  // characters at most, or the same name with its unit suffix changed.
  const auto lower = [](std::string_view v) {
    std::string out(v);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  };
  const std::string a = lower(name), b = lower(close);
  // Siblings of a family are not typos of each other: x0_mm and y0_mm,
  // fx_N and fy_N, tool_i and tool_j, q1_deg and q2_deg (one character
  // apart, both a coordinate or an index).
  if (a.size() == b.size()) {
    size_t diff = 0, at = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      if (a[i] != b[i]) {
        ++diff;
        at = i;
      }
    }
    const std::string family = "xyzijk0123456789";
    if (diff == 1 && family.find(a[at]) != std::string::npos && family.find(b[at]) != std::string::npos) return "";
  }
  const auto stem = [](const std::string& v) { return v.substr(0, v.rfind('_')); };
  const bool same_stem = stem(a) == b || stem(b) == a || (stem(a) == stem(b) && stem(a) != a);
  if (!same_stem && EditDistance(a, b) > std::max<size_t>(1, a.size() / 4)) return "";
  return " (the header has '" + close + "' (column " + std::to_string(ColumnIndex(close) + 1) + "): mistyped?)";
}

std::vector<std::string> CsvTable::UnknownColumns(const std::vector<std::string>& known) const {
  std::vector<std::string> out;
  for (const auto& h : header_) {
    if (std::find(known.begin(), known.end(), h) == known.end()) out.push_back(h);
  }
  return out;
}

const std::string& CsvTable::Cell(int row, int column) const { return rows_[row][column]; }

InputError CsvTable::ErrorAt(int row, std::string_view column, const std::string& message) const {
  return InputError({path_, lines_[row], 0}, "column " + std::string(column) + ": " + message);
}

InputError CsvTable::ErrorAtRow(int row, const std::string& message) const {
  return InputError({path_, lines_[row], 0}, message);
}

std::string CsvTable::Text(int row, std::string_view column) const {
  RequireColumn(column);
  const std::string& s = Cell(row, ColumnIndex(column));
  if (s.empty()) throw ErrorAt(row, column, "expected a value, got an empty cell" + CellPosition(column));
  return s;
}

bool CsvTable::IsEmpty(int row, std::string_view column) const {
  const int c = ColumnIndex(column);
  return c < 0 || Cell(row, c).empty();
}

double CsvTable::Number(int row, std::string_view column) const {
  RequireColumn(column);
  const std::string& s = Cell(row, ColumnIndex(column));
  double v = 0.0;
  if (ParseFiniteNumber(s, &v)) return v;
  if (s.empty()) throw ErrorAt(row, column, "expected a number, got an empty cell" + CellPosition(column));
  std::string hint;
  if (s.find(',') != std::string::npos) hint = " (decimal comma?)";
  const std::string low = Lower(s);
  if (low.find("nan") != std::string::npos || low.find("inf") != std::string::npos) {
    hint = " (nan and inf are not allowed)";
  }
  throw ErrorAt(row, column, "expected a number, got \"" + s + "\"" + hint);
}

}  // namespace robomach::io
