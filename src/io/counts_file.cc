#include "robomach/io/counts_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

#include "machine_text.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

using machine::AxisScale;
using machine_text::ReadWholeFile;

machine::CountsRecord ReadCountsFile(const std::string& path, const MachineFile& mf, std::vector<std::string>* implausible) {
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
  std::vector<int> row_line;  // the file line of each row, for the step finding
  {
    const size_t lines = static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
    rec.t_s.reserve(lines);
    rec.counts.reserve(lines * n_axes);
    row_line.reserve(lines);
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
    if (t < 0.0) {
      throw InputError({path, line, 0}, "column t_s: expected a time >= 0 s on the clock the first row (the "
                                        "reference position, formats.md §8.1) starts, got " + std::string(cell_at(t_col)) +
                                        " s");
    }
    if (!rec.t_s.empty() && !(t > rec.t_s.back())) {
      throw InputError({path, line, 0}, "column t_s: time must increase, got " + FormatDouble(t) + " s after " +
                                            FormatDouble(rec.t_s.back()) + " s");
    }
    rec.t_s.push_back(t);
    row_line.push_back(line);
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
  // The median step (a pause or a dropped row does not count): rows slower
  // than kMaxPlausibleCountsStepS are a time in ms typed in the s column.
  if (implausible && rec.t_s.size() >= 2) {
    std::vector<double> steps(rec.t_s.size() - 1);
    for (size_t i = 1; i < rec.t_s.size(); ++i) steps[i - 1] = rec.t_s[i] - rec.t_s[i - 1];
    std::vector<double> sorted = steps;
    auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), mid, sorted.end());
    const double median = *mid;
    if (median > kMaxPlausibleCountsStepS) {
      const size_t i = static_cast<size_t>(std::find(steps.begin(), steps.end(), median) - steps.begin()) + 1;
      implausible->push_back("implausible (unit mistake?): " + path + ":" + std::to_string(row_line[i]) +
                             ": column t_s: the rows are " + FormatDouble(median) + " s apart (the median step; " +
                             FormatNumber(1.0 / median, 4) + " Hz), more than the " +
                             FormatNumber(kMaxPlausibleCountsStepS, 7) + " s (10 Hz) of position traces (100 Hz - "
                             "100 kHz): a time in ms typed in the s column?");
    }
  }
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

}  // namespace robomach::io
