#include "robomach/io/csv_table.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

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

void CsvTable::RequireColumn(std::string_view name) const {
  if (HasColumn(name)) return;
  std::string have;
  for (const auto& h : header_) have += (have.empty() ? "" : ",") + h;
  throw InputError({path_, header_line_, 0},
                   "missing required column '" + std::string(name) + "'; the header has: " + have);
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
  const int c = ColumnIndex(column);
  return InputError({path_, lines_[row], 0},
                    "column " + std::string(column) + (c < 0 ? "" : "") + ": " + message);
}

InputError CsvTable::ErrorAtRow(int row, const std::string& message) const {
  return InputError({path_, lines_[row], 0}, message);
}

std::string CsvTable::Text(int row, std::string_view column) const {
  RequireColumn(column);
  const std::string& s = Cell(row, ColumnIndex(column));
  if (s.empty()) throw ErrorAt(row, column, "expected a value, got an empty cell");
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
  if (s.empty()) throw ErrorAt(row, column, "expected a number, got an empty cell");
  std::string hint;
  if (s.find(',') != std::string::npos) hint = " (decimal comma?)";
  const std::string low = Lower(s);
  if (low.find("nan") != std::string::npos || low.find("inf") != std::string::npos) {
    hint = " (nan and inf are not allowed)";
  }
  throw ErrorAt(row, column, "expected a number, got \"" + s + "\"" + hint);
}

}  // namespace robomach::io
