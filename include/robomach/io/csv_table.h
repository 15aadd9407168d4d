#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "robomach/common/errors.h"
#include "robomach/io/file_kind.h"

namespace robomach::io {

/// A CSV file as formats.md defines it: UTF-8, comma separated, one header
/// row naming the columns, `#` comment lines, `# key: value` metadata before
/// the header. Columns are found by name. Every accessor that fails throws
/// InputError naming the file, the line and the column, e.g.
/// `tracker.csv:17: column fy_N: expected a number, got "12,5" (decimal comma?)`;
/// an empty cell also gets its place in the row ("cell 3 of 7"). A header
/// separated by ';' or tabs is refused as such.
class CsvTable {
 public:
  /// @throws MissingFileError if the file is missing or cannot be read;
  ///   InputError if it is recognised as another kind of file (YAML, UFF58,
  ///   a picture; the message names `expected`, see io/file_kind.h), has no
  ///   header, or a data row has more cells than the header.
  static CsvTable ReadFile(const std::string& path, const std::string& expected = kCsvTableFormat);
  /// Parses text; `path` is used in messages only.
  static CsvTable Parse(std::string_view text, const std::string& path);

  const std::string& path() const { return path_; }
  /// `# key: value` comments before the header, keys lower-cased.
  const std::map<std::string, std::string>& metadata() const { return metadata_; }
  const std::vector<std::string>& header() const { return header_; }
  int header_line() const { return header_line_; }
  int num_rows() const { return static_cast<int>(rows_.size()); }
  /// 1-based line number of data row `row` in the file.
  int line(int row) const { return lines_[row]; }

  bool HasColumn(std::string_view name) const { return ColumnIndex(name) >= 0; }
  int ColumnIndex(std::string_view name) const;
  /// @throws InputError "path:header_line: missing required column 'name'",
  /// with a close column (CloseColumn) and the format the header is of
  /// (LooksLike(own): `own` the reader's own format, not named).
  void RequireColumn(std::string_view name, std::string_view own = "") const;
  /// " (the header has 'q1deg' (column 2): mistyped?)" when a header
  /// column is close to `name` (ClosestName), else "": for messages about
  /// a missing column.
  /// Columns in `exclude` (the ones the reader uses) are not suggested.
  std::string CloseColumn(std::string_view name, const std::vector<std::string>& exclude = {}) const;
  /// "; the columns are those of a posture file (...): the file for another
  /// option?" when the header is that of one of robomach's other CSV
  /// formats (an FRF given as --tracker), else "". `own`: the reader's
  /// format ("frf", "modal", "tracker", "posture", "path", "iso",
  /// "hammer"), never named.
  std::string LooksLike(std::string_view own = "") const;
  /// " (cell 3 of 7 in the row, after 2 commas)" for an empty cell's message.
  std::string CellPosition(std::string_view column) const;
  /// Header columns not in `known`, in file order.
  std::vector<std::string> UnknownColumns(const std::vector<std::string>& known) const;

  /// Raw cell text (trimmed); "" for a missing trailing cell.
  const std::string& Cell(int row, int column) const;
  /// Non-empty text of a required column.
  std::string Text(int row, std::string_view column) const;
  /// A finite number; empty, nan, inf or text is an error.
  double Number(int row, std::string_view column) const;
  /// True if the cell is empty (for optional columns).
  bool IsEmpty(int row, std::string_view column) const;
  /// An InputError located at the row and column.
  InputError ErrorAt(int row, std::string_view column, const std::string& message) const;
  InputError ErrorAtRow(int row, const std::string& message) const;

 private:
  std::string path_;
  std::map<std::string, std::string> metadata_;
  std::vector<std::string> header_;
  int header_line_{0};
  std::vector<std::vector<std::string>> rows_;
  std::vector<int> lines_;
};

/// CloseColumn for joint `joint` (0-based) of a posture or tracker file:
/// q<j>_deg, else q<j>_rad, among the columns that are not another joint's.
std::string JointColumnHint(const CsvTable& table, int joint, int num_joints);

/// Parses a decimal or exponent-form number. Returns false for anything
/// else, including nan and inf.
bool ParseFiniteNumber(std::string_view text, double* value);

}  // namespace robomach::io
