#include "robomach/io/frf_files.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"

namespace robomach::io {
namespace {

using dynamics::Frf;
using dynamics::FrfKey;
using dynamics::FrfSet;

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string Trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

std::string Fmt(double v) {
  std::ostringstream o;
  o.precision(10);
  o << v;
  return o.str();
}

bool ParseAxis(const std::string& text, Axis* axis) {
  const std::string t = Lower(text);
  if (t == "x") *axis = Axis::kX;
  else if (t == "y") *axis = Axis::kY;
  else if (t == "z") *axis = Axis::kZ;
  else return false;
  return true;
}

// Log-log slope of |H| over the lowest lines. A receptance tends to the static compliance below the first
// resonance (slope ~0), a mobility grows like f (slope 1), an accelerance
// like f² (slope 2). Returns NaN if there are too few usable lines.
double LowFrequencySlope(const Frf& frf) {
  const auto& f = frf.freq_hz();
  int first = 0;
  while (first < frf.size() && f(first) <= 0.0) ++first;
  if (first >= frf.size()) return NAN;
  // Up to twice the first line, and at least four lines (a coarse grid).
  const double f_end = std::max(2.0 * f(first), f(std::min(first + 3, frf.size() - 1)));
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (int i = first; i < frf.size() && f(i) <= f_end; ++i) {
    const double a = std::abs(frf.receptance()(i));
    if (!(a > 0.0)) continue;
    const double x = std::log(f(i)), y = std::log(a);
    sx += x; sy += y; sxx += x * x; sxy += x * y;
    ++n;
  }
  if (n < 3) return NAN;
  const double den = n * sxx - sx * sx;
  if (!(den > 0.0)) return NAN;
  return (n * sxy - sx * sy) / den;
}

void CheckLowFrequencyTrend(const FrfKey& key, const Frf& frf, const std::string& where,
                            std::vector<std::string>* warnings) {
  const double slope = LowFrequencySlope(frf);
  if (!std::isfinite(slope)) return;
  std::string guess;
  if (slope > 1.5) guess = "accelerance";
  else if (slope > 0.6) guess = "mobility";
  if (guess.empty()) return;
  std::ostringstream m;
  m.precision(3);
  m << where << ": FRF " << key.ToString() << " is declared as receptance, but |H| grows like f^"
    << slope << " over its lowest lines; a receptance tends to the static compliance below the "
    << "first resonance, so this looks like " << guess << " (add '# quantity: " << guess
    << "' to the file, or ignore this if the lowest line is close to the first resonance)";
  warnings->push_back(m.str());
}

// Format a double with printf into a std::string.
std::string Printf(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

std::string Pad80(const std::string& s) {
  std::string t = s.substr(0, 80);
  t.resize(80, ' ');
  return t;
}

std::string PadTo(const std::string& s, size_t n) {
  std::string t = s.substr(0, n);
  t.resize(n, ' ');
  return t;
}

}  // namespace

std::string QuantityName(FrfQuantity q) {
  switch (q) {
    case FrfQuantity::kReceptance: return "receptance";
    case FrfQuantity::kMobility: return "mobility";
    case FrfQuantity::kAccelerance: return "accelerance";
  }
  return "?";
}

FrfQuantity ParseQuantity(const std::string& name) {
  const std::string n = Lower(Trim(name));
  if (n == "receptance") return FrfQuantity::kReceptance;
  if (n == "mobility") return FrfQuantity::kMobility;
  if (n == "accelerance") return FrfQuantity::kAccelerance;
  throw std::invalid_argument("quantity '" + name +
                              "': expected receptance, mobility or accelerance");
}

std::complex<double> ToReceptance(FrfQuantity quantity, double freq_hz, std::complex<double> value) {
  const double w = HzToRadPerSec(freq_hz);
  switch (quantity) {
    case FrfQuantity::kReceptance: return value;
    case FrfQuantity::kMobility: return value / std::complex<double>(0.0, w);  // Y = iω H
    case FrfQuantity::kAccelerance: return -value / (w * w);                  // A = −ω² H
  }
  return value;
}

std::complex<double> FromReceptance(FrfQuantity quantity, double freq_hz, std::complex<double> h) {
  const double w = HzToRadPerSec(freq_hz);
  switch (quantity) {
    case FrfQuantity::kReceptance: return h;
    case FrfQuantity::kMobility: return h * std::complex<double>(0.0, w);
    case FrfQuantity::kAccelerance: return -h * (w * w);
  }
  return h;
}

double RoundToUffPrecision(double v) {
  if (v == 0.0 || !std::isfinite(v)) return v;
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.12E", v);
  return std::strtod(buf, nullptr);
}

// ---------------------------------------------------------------- CSV --

FrfReadResult ReadFrfCsv(const std::string& path) {
  const CsvTable t = CsvTable::ReadFile(path);
  FrfReadResult out;
  if (auto it = t.metadata().find("quantity"); it != t.metadata().end()) {
    try {
      out.file_quantity = ParseQuantity(it->second);
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
    out.averages = static_cast<int>(n);
  }
  for (const char* c : {"pose_id", "response", "excitation", "freq_hz", "re", "im"}) t.RequireColumn(c);
  const bool has_coherence = t.HasColumn("coherence");
  if (t.num_rows() == 0) throw InputError({path, t.header_line(), 0}, "no FRF lines after the header");

  struct Block {
    FrfKey key;
    int first_row{0}, last_row{0};
    std::vector<double> f;
    std::vector<std::complex<double>> h;
    std::vector<double> coh;
    double step{NAN};      // the step of an even grid, once established
    int step_from_row{0};
  };
  std::map<FrfKey, std::pair<int, int>> seen;  // key -> first and last line of its block
  Block cur;
  bool open = false;
  auto finish = [&]() {
    if (!open) return;
    seen[cur.key] = {t.line(cur.first_row), t.line(cur.last_row)};
    if (cur.f.empty()) {
      open = false;
      return;
    }
    Eigen::VectorXd f = Eigen::Map<Eigen::VectorXd>(cur.f.data(), cur.f.size());
    Eigen::VectorXcd h = Eigen::Map<Eigen::VectorXcd>(cur.h.data(), cur.h.size());
    std::optional<Eigen::VectorXd> coh;
    if (has_coherence) coh = Eigen::Map<Eigen::VectorXd>(cur.coh.data(), cur.coh.size());
    try {
      Frf frf = Frf::FromSamples(f, h, coh);
      if (out.file_quantity == FrfQuantity::kReceptance) {
        CheckLowFrequencyTrend(cur.key, frf, path + ":" + std::to_string(t.line(cur.first_row)),
                               &out.warnings);
      }
      out.frfs.Insert(cur.key, std::move(frf));
    } catch (const std::invalid_argument& e) {
      throw InputError({path, t.line(cur.first_row), 0},
                       "FRF " + cur.key.ToString() + ": " + e.what());
    }
    open = false;
  };

  for (int r = 0; r < t.num_rows(); ++r) {
    FrfKey key;
    key.pose_id = t.Text(r, "pose_id");
    if (!ParseAxis(t.Text(r, "response"), &key.response)) {
      throw t.ErrorAt(r, "response", "expected x, y or z, got \"" + t.Text(r, "response") + "\"");
    }
    if (!ParseAxis(t.Text(r, "excitation"), &key.excitation)) {
      throw t.ErrorAt(r, "excitation", "expected x, y or z, got \"" + t.Text(r, "excitation") + "\"");
    }
    if (!open || !(key == cur.key)) {
      finish();
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
    const std::complex<double> v(t.Number(r, "re"), t.Number(r, "im"));
    double coh = NAN;
    if (has_coherence) {
      coh = t.Number(r, "coherence");
      if (coh < 0.0 || coh > 1.0) throw t.ErrorAt(r, "coherence", "expected a value in [0, 1], got " + t.Text(r, "coherence"));
    }
    if (f == 0.0 && out.file_quantity != FrfQuantity::kReceptance) {
      out.warnings.push_back(path + ":" + std::to_string(t.line(r)) + ": the 0 Hz line of a " +
                             QuantityName(out.file_quantity) +
                             " FRF has no receptance equivalent; it is skipped");
      continue;
    }
    cur.f.push_back(f);
    cur.h.push_back(ToReceptance(out.file_quantity, f, v));
    if (has_coherence) cur.coh.push_back(coh);
  }
  finish();
  return out;
}

void WriteFrfCsv(std::ostream& os, const FrfSet& frfs, FrfQuantity quantity, int averages) {
  bool coherence = !frfs.empty();
  for (const auto& [k, f] : frfs) coherence = coherence && f.coherence().has_value();
  os << "# quantity: " << QuantityName(quantity) << '\n';
  if (averages > 0) os << "# averages: " << averages << '\n';
  os << "# written by robomach; tool-tip FRFs in the robot base frame B, SI units\n";
  os << "pose_id,response,excitation,freq_hz,re,im" << (coherence ? ",coherence" : "") << '\n';
  for (const auto& [k, frf] : frfs) {
    for (int i = 0; i < frf.size(); ++i) {
      const double f = frf.freq_hz()(i);
      if (f == 0.0 && quantity != FrfQuantity::kReceptance) continue;  // undefined there
      const std::complex<double> v = FromReceptance(quantity, f, frf.receptance()(i));
      os << k.pose_id << ',' << AxisName(k.response) << ',' << AxisName(k.excitation) << ','
         << FormatDouble(f) << ',' << FormatDouble(v.real()) << ',' << FormatDouble(v.imag());
      if (coherence) os << ',' << FormatDouble((*frf.coherence())(i));
      os << '\n';
    }
  }
}

void WriteFrfCsv(const std::string& path, const FrfSet& frfs, FrfQuantity quantity, int averages) {
  WriteFileAtomically(path, [&](std::ostream& os) { WriteFrfCsv(os, frfs, quantity, averages); });
}

// ---------------------------------------------------------------- UFF58 --

namespace {

struct UffLine {
  std::string text;
  int line{0};  // 1-based
};

// Numbers of a free-format line; Fortran 'D' exponents are accepted.
std::vector<double> Numbers(const std::string& path, const UffLine& l, const std::string& what) {
  std::vector<double> v;
  std::istringstream in(l.text);
  std::string tok;
  while (in >> tok) {
    for (char& c : tok) {
      if (c == 'D' || c == 'd') c = 'E';
    }
    double x = 0.0;
    if (!ParseFiniteNumber(tok, &x)) {
      throw InputError({path, l.line, 0}, what + ": expected a number, got \"" + tok + "\"");
    }
    v.push_back(x);
  }
  return v;
}

std::string Field(const std::string& s, size_t b, size_t e) {
  if (b >= s.size()) return "";
  return Trim(s.substr(b, std::min(e, s.size()) - b));
}

int IntField(const std::string& path, const UffLine& l, size_t b, size_t e, const std::string& what) {
  const std::string f = Field(l.text, b, e);
  double x = 0.0;
  if (!ParseFiniteNumber(f, &x) || x != std::floor(x)) {
    throw InputError({path, l.line, static_cast<int>(b) + 1},
                     what + ": expected an integer in columns " + std::to_string(b + 1) + "-" +
                         std::to_string(e) + ", got \"" + f + "\"");
  }
  return static_cast<int>(x);
}

bool DirectionAxis(int code, Axis* axis, int* sign) {
  const int a = std::abs(code);
  if (a < 1 || a > 3) return false;
  *axis = static_cast<Axis>(a - 1);
  *sign = code < 0 ? -1 : 1;
  return true;
}

void RejectNonSiLabel(const std::string& path, const UffLine& l, const std::string& label,
                      const std::string& what) {
  static const std::vector<std::string> kNonSi = {"mm", "mm/s", "mm/s^2", "mm/s2", "g", "g's",
                                                  "in", "in/s", "in/s^2", "inch", "lbf", "lb",
                                                  "kn", "um", "µm", "rpm", "ft", "ft/s"};
  const std::string low = Lower(Trim(label));
  if (std::find(kNonSi.begin(), kNonSi.end(), low) != kNonSi.end()) {
    throw InputError({path, l.line, 0}, what + " unit label is \"" + Trim(label) +
                                            "\"; robomach reads UFF58 in SI units only "
                                            "(m, m/s, m/s^2 per N; Hz): convert the export");
  }
}

struct UffCoherence {
  FrfKey key;
  Eigen::VectorXd f, c;
  int line{0};
};

}  // namespace

FrfReadResult ReadUff58(const std::string& path, const std::string& default_pose_id) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, 0, 0}, "cannot open file for reading");
  std::vector<UffLine> lines;
  {
    std::string s;
    int n = 0;
    while (std::getline(in, s)) {
      ++n;
      if (!s.empty() && s.back() == '\r') s.pop_back();
      lines.push_back({s, n});
    }
  }
  FrfReadResult out;
  bool quantity_set = false;
  std::vector<UffCoherence> coherences;
  const std::regex pose_re(R"(pose=([^\s,]+))");
  size_t i = 0;
  auto is_delim = [&](size_t k) { return Trim(lines[k].text) == "-1"; };
  int records = 0;
  while (i < lines.size()) {
    if (Trim(lines[i].text).empty()) {
      ++i;
      continue;
    }
    if (!is_delim(i)) {
      throw InputError({path, lines[i].line, 0},
                       "expected the UFF record delimiter \"    -1\", got \"" + Trim(lines[i].text) + "\"");
    }
    const size_t start = i;
    if (i + 1 >= lines.size()) break;
    const UffLine& type_line = lines[i + 1];
    const std::string type = Trim(type_line.text);
    // The record ends at the next delimiter.
    size_t end = i + 2;
    while (end < lines.size() && !is_delim(end)) ++end;
    if (end >= lines.size()) {
      throw InputError({path, lines[start].line, 0},
                       "UFF record starting here has no closing \"    -1\" line");
    }
    i = end + 1;
    const std::string type_word = type.substr(0, type.find_first_of(" \t"));
    if (type_word == "151") continue;  // header: no data
    if (type_word != "58") {
      std::string hint;
      if (Lower(type_word) == "58b") hint = " (binary 58b: export ASCII dataset 58 instead)";
      throw InputError({path, type_line.line, 0},
                       "UFF dataset " + type_word + " is not supported" + hint +
                           "; robomach reads ASCII dataset 58 (function at nodal DOF) records and "
                           "skips 151 headers");
    }
    ++records;
    const size_t b = start + 2;  // ID line 1
    if (end - b < 11) {
      throw InputError({path, type_line.line, 0},
                       "UFF58 record has " + std::to_string(end - b) +
                           " lines before its closing -1; expected 11 header lines and data");
    }
    const std::string where_rec = "UFF58 record at line " + std::to_string(type_line.line);
    // Record 1: ID line 1 may name the posture.
    std::string pose = default_pose_id;
    std::smatch m;
    if (std::regex_search(lines[b].text, m, pose_re)) pose = m[1].str();
    if (pose.empty()) {
      throw InputError({path, lines[b].line, 0},
                       "no posture for this record: put 'pose=P1' in ID line 1, or give the file on "
                       "the command line as --pose P1=" + path);
    }
    // Record 6: DOF identification, format 2(I5,I10),2(1X,10A1,I10,I4).
    const UffLine& r6 = lines[b + 5];
    const int func_type = IntField(path, r6, 0, 5, "record 6 function type");
    const int resp_dir = IntField(path, r6, 51, 55, "record 6 response direction");
    const int ref_dir = IntField(path, r6, 76, 80, "record 6 reference direction");
    // Record 7: data form, format 3I10,3E13.5.
    const UffLine& r7 = lines[b + 6];
    const std::vector<double> f7 = Numbers(path, r7, "record 7");
    if (f7.size() < 5) {
      throw InputError({path, r7.line, 0}, "record 7: expected ordinate type, number of points, "
                                           "spacing, abscissa minimum and increment");
    }
    const int ord_type = static_cast<int>(f7[0]);
    const long npts = static_cast<long>(f7[1]);
    const int spacing = static_cast<int>(f7[2]);
    const double xmin = f7[3], dx = f7[4];
    // Records 8-10: abscissa, ordinate numerator and denominator, format I10,3I5,2(1X,20A1).
    const UffLine& r8 = lines[b + 7];
    const UffLine& r9 = lines[b + 8];
    const UffLine& r10 = lines[b + 9];
    RejectNonSiLabel(path, r8, Field(r8.text, 47, 67), "abscissa (record 8)");
    RejectNonSiLabel(path, r9, Field(r9.text, 47, 67), "ordinate (record 9)");
    RejectNonSiLabel(path, r10, Field(r10.text, 47, 67), "ordinate denominator (record 10)");
    const int ord_specific = IntField(path, r9, 0, 10, "record 9 specific data type");

    FrfKey key;
    key.pose_id = pose;
    int s_resp = 1, s_ref = 1;
    if (!DirectionAxis(resp_dir, &key.response, &s_resp) ||
        !DirectionAxis(ref_dir, &key.excitation, &s_ref)) {
      throw InputError({path, r6.line, 52},
                       "record 6: response direction " + std::to_string(resp_dir) +
                           " and reference direction " + std::to_string(ref_dir) +
                           ": expected translational codes 1/-1 (x), 2/-2 (y), 3/-3 (z)");
    }
    const bool complex_data = ord_type == 5 || ord_type == 6;
    const bool real_data = ord_type == 2 || ord_type == 4;
    if (!complex_data && !real_data) {
      throw InputError({path, r7.line, 0}, "record 7: ordinate data type " + std::to_string(ord_type) +
                                               " is not one of 2, 4 (real) or 5, 6 (complex)");
    }
    if (func_type == 4 && !complex_data) {
      throw InputError({path, r7.line, 0},
                       "record 7: an FRF (function type 4) needs complex ordinates (data type 5 or "
                       "6), got " + std::to_string(ord_type));
    }
    if (func_type == 6 && !real_data) {
      throw InputError({path, r7.line, 0}, "record 7: coherence (function type 6) must be real (data "
                                           "type 2 or 4), got " + std::to_string(ord_type));
    }
    if (func_type != 4 && func_type != 6) {
      throw InputError({path, r6.line, 1},
                       "record 6: function type " + std::to_string(func_type) +
                           " is not supported; robomach reads FRFs (4) and their coherence (6)");
    }
    if (spacing != 0 && spacing != 1) {
      throw InputError({path, r7.line, 0}, "record 7: abscissa spacing must be 0 (uneven) or 1 "
                                           "(even), got " + std::to_string(spacing));
    }
    if (npts <= 0) throw InputError({path, r7.line, 0}, "record 7: number of data points must be > 0");
    if (spacing == 1 && !(dx > 0.0)) {
      throw InputError({path, r7.line, 0}, "record 7: abscissa increment must be > 0 for even spacing");
    }
    // Record 12: the data.
    std::vector<double> data;
    for (size_t k = b + 11; k < end; ++k) {
      const std::vector<double> v = Numbers(path, lines[k], where_rec + " data");
      data.insert(data.end(), v.begin(), v.end());
    }
    const int per_point = (complex_data ? 2 : 1) + (spacing == 0 ? 1 : 0);
    if (static_cast<long>(data.size()) != npts * per_point) {
      throw InputError({path, r7.line, 0},
                       "record 7 announces " + std::to_string(npts) + " points (" +
                           std::to_string(npts * per_point) + " numbers), but the data lines " +
                           std::to_string(lines[b + 11].line) + "-" + std::to_string(lines[end - 1].line) +
                           " hold " + std::to_string(data.size()) + " numbers");
    }
    Eigen::VectorXd f(npts);
    Eigen::VectorXcd v(npts);
    Eigen::VectorXd real_v(npts);
    for (long p = 0; p < npts; ++p) {
      const double* d = data.data() + p * per_point;
      int o = 0;
      if (spacing == 0) {
        f(p) = d[0];
        o = 1;
      } else {
        f(p) = xmin + p * dx;
      }
      if (complex_data) v(p) = std::complex<double>(d[o], d[o + 1]);
      else real_v(p) = d[o];
    }
    if (func_type == 6) {
      coherences.push_back({key, f, real_v, type_line.line});
      continue;
    }
    FrfQuantity q = FrfQuantity::kReceptance;
    if (ord_specific == 8) q = FrfQuantity::kReceptance;
    else if (ord_specific == 11) q = FrfQuantity::kMobility;
    else if (ord_specific == 12) q = FrfQuantity::kAccelerance;
    else if (ord_specific == 0 || ord_specific == 1) {
      out.warnings.push_back(path + ":" + std::to_string(r9.line) +
                             ": record 9 gives no physical ordinate type (" +
                             std::to_string(ord_specific) + "); read as receptance [m/N]");
    } else {
      throw InputError({path, r9.line, 1},
                       "record 9: ordinate specific data type " + std::to_string(ord_specific) +
                           " is not 8 (displacement), 11 (velocity) or 12 (acceleration)");
    }
    if (!quantity_set) {
      out.file_quantity = q;
      quantity_set = true;
    }
    const double sign = s_resp * s_ref;
    std::vector<double> fk;
    std::vector<std::complex<double>> hk;
    for (long p = 0; p < npts; ++p) {
      if (f(p) == 0.0 && q != FrfQuantity::kReceptance) {
        out.warnings.push_back(path + ":" + std::to_string(type_line.line) + ": the 0 Hz line of a " +
                               QuantityName(q) + " FRF has no receptance equivalent; it is skipped");
        continue;
      }
      fk.push_back(f(p));
      hk.push_back(sign * ToReceptance(q, f(p), v(p)));
    }
    try {
      Frf frf = Frf::FromSamples(Eigen::Map<Eigen::VectorXd>(fk.data(), fk.size()),
                                 Eigen::Map<Eigen::VectorXcd>(hk.data(), hk.size()));
      if (q == FrfQuantity::kReceptance) {
        CheckLowFrequencyTrend(key, frf, path + ":" + std::to_string(type_line.line), &out.warnings);
      }
      out.frfs.Insert(key, std::move(frf));
    } catch (const std::invalid_argument& e) {
      throw InputError({path, type_line.line, 0}, where_rec + ": " + e.what());
    }
  }
  if (records == 0) throw InputError({path, 0, 0}, "no UFF dataset 58 record found");
  // Attach coherence records to their FRFs (same posture and directions, same grid).
  for (const UffCoherence& c : coherences) {
    if (!out.frfs.contains(c.key)) {
      throw InputError({path, c.line, 0}, "coherence record for " + c.key.ToString() +
                                              " has no FRF record with the same directions");
    }
    const Frf& frf = out.frfs.at(c.key);
    if (frf.coherence()) {
      throw InputError({path, c.line, 0}, "second coherence record for " + c.key.ToString());
    }
    // The FRF may have lost a 0 Hz line; align by frequency.
    Eigen::VectorXd coh(frf.size());
    int j = 0;
    for (int p = 0; p < frf.size(); ++p) {
      while (j < c.f.size() && c.f(j) < frf.freq_hz()(p) - 1e-9 * std::max(1.0, frf.freq_hz()(p))) ++j;
      if (j >= c.f.size() || std::abs(c.f(j) - frf.freq_hz()(p)) > 1e-6 * std::max(1.0, frf.freq_hz()(p))) {
        throw InputError({path, c.line, 0}, "coherence record for " + c.key.ToString() +
                                                " is not on the grid of its FRF");
      }
      coh(p) = c.c(j);
    }
    try {
      Frf with = Frf::FromSamples(frf.freq_hz(), frf.receptance(), coh);
      FrfSet rebuilt;
      for (const auto& [k, g] : out.frfs) rebuilt.Insert(k, k == c.key ? with : g);
      out.frfs = std::move(rebuilt);
    } catch (const std::invalid_argument& e) {
      throw InputError({path, c.line, 0}, "coherence record for " + c.key.ToString() + ": " + e.what());
    }
  }
  return out;
}

void WriteUff58(std::ostream& os, const FrfSet& frfs, FrfQuantity quantity) {
  int specific = 8;
  std::string unit = "m";
  if (quantity == FrfQuantity::kMobility) {
    specific = 11;
    unit = "m/s";
  } else if (quantity == FrfQuantity::kAccelerance) {
    specific = 12;
    unit = "m/s^2";
  }
  auto axis_line = [&](int spec, int len, int force, const std::string& label, const std::string& units) {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "%10d%5d%5d%5d", spec, len, force, 0);
    return std::string(buf) + " " + PadTo(label, 20) + " " + PadTo(units, 20);
  };
  // The abscissa uses E13.6: 7 significant digits still fit the 13-wide field
  // of the format's E13.5 for positive frequencies, and Fortran input honours
  // an explicit decimal point whatever the descriptor's d.
  auto write_record = [&](const FrfKey& k, const Frf& frf, bool coherence_record) {
    std::vector<int> idx;
    for (int i = 0; i < frf.size(); ++i) {
      if (!coherence_record && frf.freq_hz()(i) == 0.0 && quantity != FrfQuantity::kReceptance) continue;
      idx.push_back(i);
    }
    const long n = static_cast<long>(idx.size());
    bool even = n >= 2;
    double f0 = n > 0 ? frf.freq_hz()(idx[0]) : 0.0;
    double df = n >= 2 ? (frf.freq_hz()(idx[n - 1]) - f0) / (n - 1) : 0.0;
    if (even) {
      const double f0r = std::strtod(Printf("%.6E", f0).c_str(), nullptr);
      const double dfr = std::strtod(Printf("%.6E", df).c_str(), nullptr);
      const double tol = 1e-9 * frf.freq_hz()(idx[n - 1]);
      for (long p = 0; p < n && even; ++p) {
        even = std::abs(frf.freq_hz()(idx[p]) - (f0r + p * dfr)) <= tol;
      }
    }
    os << "    -1\n    58\n";
    os << Pad80("pose=" + k.pose_id + " tool-tip " +
                (coherence_record ? std::string("coherence") : QuantityName(quantity))) << '\n';
    os << Pad80(std::string(coherence_record ? "C" : "H") + AxisName(k.response) + AxisName(k.excitation)) << '\n';
    os << Pad80("robomach") << '\n' << Pad80("NONE") << '\n' << Pad80("NONE") << '\n';
    char buf[256];
    std::snprintf(buf, sizeof(buf), "%5d%10d%5d%10d %10s%10d%4d %10s%10d%4d", coherence_record ? 6 : 4, 0, 0, 0,
                  "tip", 1, static_cast<int>(k.response) + 1, "tip", 1, static_cast<int>(k.excitation) + 1);
    os << buf << '\n';
    std::snprintf(buf, sizeof(buf), "%10d%10ld%10d%13.6E%13.6E%13.6E", coherence_record ? 4 : 6, n,
                  even ? 1 : 0, even ? f0 : 0.0, even ? df : 0.0, 0.0);
    os << buf << '\n';
    os << axis_line(18, 0, 0, "NONE", "Hz") << '\n';
    if (coherence_record) {
      os << axis_line(0, 0, 0, "NONE", "none") << '\n';
      os << axis_line(0, 0, 0, "NONE", "none") << '\n';
    } else {
      os << axis_line(specific, 1, 0, "NONE", unit) << '\n';
      os << axis_line(13, 0, 1, "NONE", "N") << '\n';
    }
    os << axis_line(0, 0, 0, "NONE", "none") << '\n';
    if (coherence_record) {
      const Eigen::VectorXd& c = *frf.coherence();
      if (even) {
        for (long p = 0; p < n; ++p) {
          os << Printf("%20.12E", c(idx[p])) << ((p % 4 == 3 || p == n - 1) ? "\n" : "");
        }
      } else {
        for (long p = 0; p < n; ++p) {
          os << Printf("%13.6E", frf.freq_hz()(idx[p])) << Printf("%20.12E", c(idx[p]))
             << ((p % 2 == 1 || p == n - 1) ? "\n" : "");
        }
      }
    } else {
      for (long p = 0; p < n; ++p) {
        const double f = frf.freq_hz()(idx[p]);
        const std::complex<double> v = FromReceptance(quantity, f, frf.receptance()(idx[p]));
        if (even) {
          os << Printf("%20.12E", v.real()) << Printf("%20.12E", v.imag())
             << ((p % 2 == 1 || p == n - 1) ? "\n" : "");
        } else {
          os << Printf("%13.6E", f) << Printf("%20.12E", v.real()) << Printf("%20.12E", v.imag()) << '\n';
        }
      }
    }
    os << "    -1\n";
  };
  for (const auto& [k, frf] : frfs) {
    write_record(k, frf, false);
    if (frf.coherence()) write_record(k, frf, true);
  }
}

void WriteUff58(const std::string& path, const FrfSet& frfs, FrfQuantity quantity) {
  WriteFileAtomically(path, [&](std::ostream& os) { WriteUff58(os, frfs, quantity); });
}

FrfReadResult ReadFrfFile(const std::string& path, const std::string& default_pose_id) {
  std::string ext;
  if (auto dot = path.find_last_of('.'); dot != std::string::npos) ext = Lower(path.substr(dot + 1));
  if (ext == "uff" || ext == "unv" || ext == "uf") return ReadUff58(path, default_pose_id);
  return ReadFrfCsv(path);
}

}  // namespace robomach::io
