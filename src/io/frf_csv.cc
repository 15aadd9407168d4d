#include "robomach/io/frf_csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "robomach/common/errors.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"
#include "frf_text.h"

namespace robomach::io {

using dynamics::Frf;
using dynamics::FrfKey;
using dynamics::FrfSet;
using frf_text::CheckLowFrequencyTrend;
using frf_text::Fmt;

namespace {

// The metadata lines: `# quantity:` (the file's FRF quantity) and
// `# averages:` (behind the coherence), each checked.
void ReadFrfMetadata(const CsvTable& t, const std::string& path, FrfReadResult* out) {
  if (auto it = t.metadata().find("quantity"); it != t.metadata().end()) {
    try {
      out->file_quantity = ParseFrfQuantity(it->second);
    } catch (const std::invalid_argument&) {
      throw InputError({path, 0, 0}, "metadata '# quantity: " + it->second +
                                         "': expected receptance, mobility or accelerance");
    }
  }
  if (auto it = t.metadata().find("averages"); it != t.metadata().end()) {
    char* end = nullptr;
    const long n = std::strtol(it->second.c_str(), &end, 10);
    if (end == it->second.c_str() || *end != '\0' || n < 1 || n > 1000000) {
      throw InputError({path, 0, 0}, "metadata '# averages: " + it->second + "': expected a whole number >= 1");
    }
    out->averages = static_cast<int>(n);
  }
}

// Which of the optional columns the file has.
struct FrfColumns {
  bool has_coherence{false};
  const char* response_point_col{nullptr};  // "response_point", "point" or none
  bool has_excitation_point{false};
};

// The header: the required columns, and the optional ones.
FrfColumns ReadFrfColumns(const CsvTable& t, const std::string& path) {
  for (const char* c : {"pose_id", "response", "excitation", "freq_hz", "re", "im"}) t.RequireColumn(c, "frf");
  FrfColumns cols;
  cols.has_coherence = t.HasColumn("coherence");
  // Point numbers of a roving test (formats.md §3): `point` is the roving
  // transducer's point, read as the response point (by reciprocity a
  // roving hammer's point may go there too).
  if (t.HasColumn("point") && t.HasColumn("response_point")) {
    throw InputError({path, t.header_line(), 0},
                     "columns 'point' and 'response_point' are the same thing: give one of them");
  }
  cols.response_point_col = t.HasColumn("response_point") ? "response_point"
                            : t.HasColumn("point")         ? "point"
                                                           : nullptr;
  cols.has_excitation_point = t.HasColumn("excitation_point");
  return cols;
}

// A point number cell: a whole number >= 0.
int PointAt(const CsvTable& t, int r, const char* col) {
  const std::string text = t.Text(r, col);
  int v = -1;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || v < 0) {
    throw t.ErrorAt(r, col, "expected a point number (a whole number >= 0), got \"" + text + "\"");
  }
  return v;
}

// The contiguous lines of one FRF.
struct Block {
  FrfKey key;
  int first_row{0}, last_row{0};
  std::vector<double> f;
  std::vector<std::complex<double>> h;
  std::vector<double> coh;
  double step{NAN};      // the step of an even grid, once established
  int step_from_row{0};
};

// Reads the rows into FRFs, block by block: a block ends where the key
// changes, and a key met again after its block is refused.
struct FrfBlockReader {
  const CsvTable& t;
  const std::string& path;
  const FrfColumns& cols;
  FrfReadResult& out;
  std::map<FrfKey, std::pair<int, int>> seen{};  // key -> first and last line of its block
  Block cur{};
  bool open = false;

  // Closes the open block: its FRF into `out.frfs` (none for a block of
  // skipped 0 Hz lines only).
  void Finish() {
    if (!open) return;
    seen[cur.key] = {t.line(cur.first_row), t.line(cur.last_row)};
    if (cur.f.empty()) {
      open = false;
      return;
    }
    Eigen::VectorXd f = Eigen::Map<Eigen::VectorXd>(cur.f.data(), cur.f.size());
    Eigen::VectorXcd h = Eigen::Map<Eigen::VectorXcd>(cur.h.data(), cur.h.size());
    std::optional<Eigen::VectorXd> coh;
    if (cols.has_coherence) coh = Eigen::Map<Eigen::VectorXd>(cur.coh.data(), cur.coh.size());
    AtLocation({path, t.line(cur.first_row), 0}, "FRF " + cur.key.ToString() + ": ", [&] {
      Frf frf = Frf::FromSamples(f, h, coh);
      if (out.file_quantity == FrfQuantity::kReceptance) {
        CheckLowFrequencyTrend(cur.key, frf, path + ":" + std::to_string(t.line(cur.first_row)),
                               &out.warnings);
      }
      out.frfs.Insert(cur.key, std::move(frf));
    });
    open = false;
  }

  // A direction column's value (ParseAxis), its error at the cell.
  Axis AxisAt(int r, const std::string& column) const {
    try {
      return ParseAxis(t.Text(r, column));
    } catch (const std::invalid_argument& e) {
      throw t.ErrorAt(r, column, e.what());
    }
  }

  // The FRF a row belongs to: pose, directions and point numbers.
  FrfKey KeyOfRow(int r) const {
    FrfKey key;
    key.pose_id = t.Text(r, "pose_id");
    key.response = AxisAt(r, "response");
    key.excitation = AxisAt(r, "excitation");
    if (cols.response_point_col) key.response_point = PointAt(t, r, cols.response_point_col);
    if (cols.has_excitation_point) key.excitation_point = PointAt(t, r, "excitation_point");
    return key;
  }

  // A row's frequency: >= 0, above the previous line's, and on the block's
  // grid once its first two steps agree.
  double FrequencyOfRow(int r) {
    const double f = t.Number(r, "freq_hz");
    if (f < 0.0) throw t.ErrorAt(r, "freq_hz", "expected a frequency >= 0, got " + t.Text(r, "freq_hz"));
    if (!cur.f.empty()) {
      const double prev = cur.f.back();
      if (!(f > prev)) {
        throw t.ErrorAt(r, "freq_hz",
                        "expected a frequency above the previous line's " + Fmt(prev) +
                            " Hz (the lines of one FRF must be strictly increasing), got " +
                            t.Text(r, "freq_hz"));
      }
      const double step = f - prev;
      const double tol = 1e-6 * std::max(f, 1.0);
      if (cur.f.size() == 2) {
        const double s0 = cur.f[1] - cur.f[0];
        if (std::abs(step - s0) <= tol) {
          cur.step = s0;
          cur.step_from_row = cur.first_row;
        }
      } else if (std::isfinite(cur.step) && std::abs(step - cur.step) > tol) {
        throw t.ErrorAt(r, "freq_hz",
                        "mixed frequency grids in FRF " + cur.key.ToString() + ": step " +
                            Fmt(cur.step) + " Hz from line " + std::to_string(t.line(cur.step_from_row)) +
                            ", then " + Fmt(step) + " Hz here; one FRF must be on one grid");
      }
    }
    return f;
  }

  // One row: starts a new block when the key changes, then adds the row's
  // sample as receptance (a 0 Hz line of a mobility or accelerance is skipped).
  void ReadRow(int r) {
    const FrfKey key = KeyOfRow(r);
    if (!open || !(key == cur.key)) {
      Finish();
      if (auto it = seen.find(key); it != seen.end()) {
        throw t.ErrorAtRow(
            r, "mixed frequency grids: the lines of FRF " + key.ToString() + " resume here after "
                   "another FRF (its first block is lines " + std::to_string(it->second.first) +
                   "-" + std::to_string(it->second.second) +
                   "); a duplicate FRF, or one FRF split into blocks: the lines of one FRF must be contiguous, "
                   "on one strictly increasing grid");
      }
      cur = Block{};
      cur.key = key;
      cur.first_row = r;
      open = true;
    }
    cur.last_row = r;
    const double f = FrequencyOfRow(r);
    const std::complex<double> v(t.Number(r, "re"), t.Number(r, "im"));
    double coh = NAN;
    if (cols.has_coherence) {
      coh = t.Number(r, "coherence");
      if (coh < 0.0 || coh > 1.0) throw t.ErrorAt(r, "coherence", "expected a value in [0, 1], got " + t.Text(r, "coherence"));
    }
    if (f == 0.0 && out.file_quantity != FrfQuantity::kReceptance) {
      out.warnings.push_back(path + ":" + std::to_string(t.line(r)) + ": the 0 Hz line of " +
                             QuantityWithArticle(out.file_quantity) +
                             " FRF has no receptance equivalent; it is skipped");
      return;
    }
    cur.f.push_back(f);
    cur.h.push_back(ToReceptance(out.file_quantity, f, v));
    if (cols.has_coherence) cur.coh.push_back(coh);
  }
};

}  // namespace

FrfReadResult ReadFrfCsv(const std::string& path, bool keep_points) {
  const CsvTable t = CsvTable::ReadFile(path, kFrfFileFormat);
  FrfReadResult out;
  ReadFrfMetadata(t, path, &out);
  const FrfColumns cols = ReadFrfColumns(t, path);
  if (t.num_rows() == 0) throw InputError({path, t.header_line(), 0}, "no FRF lines after the header");

  FrfBlockReader blocks{t, path, cols, out};
  for (int r = 0; r < t.num_rows(); ++r) blocks.ReadRow(r);
  blocks.Finish();
  if (!keep_points) DropPointNumbers(path, &out);
  return out;
}

void WriteFrfCsv(std::ostream& os, const FrfSet& frfs, FrfQuantity quantity, int averages) {
  bool coherence = !frfs.empty();
  for (const auto& [k, f] : frfs) coherence = coherence && f.coherence().has_value();
  os << "# quantity: " << ToString(quantity) << '\n';
  if (averages > 0) os << "# averages: " << averages << '\n';
  os << "# written by robomach; tool-tip FRFs in the robot base frame B, SI units\n";
  bool points = false;
  for (const auto& [k, f] : frfs) points = points || k.response_point != 0 || k.excitation_point != 0;
  os << "pose_id,response,excitation,freq_hz,re,im" << (coherence ? ",coherence" : "")
     << (points ? ",response_point,excitation_point" : "") << '\n';
  for (const auto& [k, frf] : frfs) {
    for (int i = 0; i < frf.size(); ++i) {
      const double f = frf.freq_hz()(i);
      if (f == 0.0 && quantity != FrfQuantity::kReceptance) continue;  // undefined there
      const std::complex<double> v = FromReceptance(quantity, f, frf.receptance()(i));
      os << k.pose_id << ',' << AxisName(k.response) << ',' << AxisName(k.excitation) << ','
         << FormatDouble(f) << ',' << FormatDouble(v.real()) << ',' << FormatDouble(v.imag());
      if (coherence) os << ',' << FormatDouble((*frf.coherence())(i));
      if (points) os << ',' << k.response_point << ',' << k.excitation_point;
      os << '\n';
    }
  }
}

void WriteFrfCsv(const std::string& path, const FrfSet& frfs, FrfQuantity quantity, int averages) {
  WriteFileAtomically(path, [&](std::ostream& os) { WriteFrfCsv(os, frfs, quantity, averages); });
}

}  // namespace robomach::io
