#include "robomach/io/uff58.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "robomach/common/errors.h"

#include "text.h"

namespace robomach::io {
namespace {

std::string RightTrim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  return s;
}

// ------------------------------------------------------------ unit labels --

struct UnitEntry {
  const char* name;
  double factor;
  int length, force, time;
};

// Case matters: "mN" is a millinewton, "MN" would be a meganewton (not
// listed), "g" standard gravity. A few upper-case spellings that exports use
// ("Sec", "HZ", "LBF", "IN") are matched case-insensitively after the exact
// match fails, except where that would change the unit ("M" is not "m"
// here only because no export writes it).
constexpr UnitEntry kUnits[] = {
    {"m", 1.0, 1, 0, 0},        {"cm", 1e-2, 1, 0, 0},        {"mm", 1e-3, 1, 0, 0},
    {"um", 1e-6, 1, 0, 0},      {"\xC2\xB5m", 1e-6, 1, 0, 0}, {"\xCE\xBCm", 1e-6, 1, 0, 0},
    {"\xB5m", 1e-6, 1, 0, 0},   {"micron", 1e-6, 1, 0, 0},    {"in", 0.0254, 1, 0, 0},
    {"inch", 0.0254, 1, 0, 0},  {"ft", 0.3048, 1, 0, 0},      {"N", 1.0, 0, 1, 0},
    {"kN", 1e3, 0, 1, 0},       {"mN", 1e-3, 0, 1, 0},        {"lbf", 4.4482216152605, 0, 1, 0},
    {"lb", 4.4482216152605, 0, 1, 0}, {"kgf", 9.80665, 0, 1, 0}, {"g", 9.80665, 1, 0, -2},
    {"gn", 9.80665, 1, 0, -2},  {"G", 9.80665, 1, 0, -2},     {"s", 1.0, 0, 0, 1},
    {"sec", 1.0, 0, 0, 1},      {"ms", 1e-3, 0, 0, 1},        {"min", 60.0, 0, 0, 1},
    {"Hz", 1.0, 0, 0, -1},      {"kHz", 1e3, 0, 0, -1},       {"rad", 1.0, 0, 0, 0},
};

class UnitParser {
 public:
  explicit UnitParser(const std::string& label) : s_(label) {}

  UnitDimension Parse() {
    UnitDimension d = Expr();
    SkipSpace();
    if (p_ != s_.size()) Fail("unexpected '" + s_.substr(p_, 1) + "'");
    d.given = true;
    return d;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::invalid_argument("unit label \"" + s_ + "\": " + what);
  }
  void SkipSpace() {
    while (p_ < s_.size() && (s_[p_] == ' ' || s_[p_] == '\t')) ++p_;
  }
  static UnitDimension Mul(UnitDimension a, const UnitDimension& b, int sign) {
    a.factor *= sign > 0 ? b.factor : 1.0 / b.factor;
    a.length += sign * b.length;
    a.force += sign * b.force;
    a.time += sign * b.time;
    return a;
  }
  // Exponents are bounded (issue #22, found by fuzz_uff58): a long one threw
  // std::out_of_range from std::stoi, and nested powers ("((m^9)^9)^9...")
  // overflowed the integer dimensions. No mechanical unit comes near these.
  static constexpr int kMaxExponent = 12;
  static constexpr int kMaxDimension = 64;
  UnitDimension Pow(UnitDimension a, int n) const {
    UnitDimension r;
    r.factor = std::pow(a.factor, n);
    const auto power = [&](int e) {
      const long long v = static_cast<long long>(e) * n;
      if (v > kMaxDimension || v < -kMaxDimension) {
        Fail("the unit's dimension exponent " + std::to_string(v) + " is out of range (|exponent| <= " +
             std::to_string(kMaxDimension) + ")");
      }
      return static_cast<int>(v);
    };
    r.length = power(a.length);
    r.force = power(a.force);
    r.time = power(a.time);
    return r;
  }
  bool AtTermStart() const {
    if (p_ >= s_.size()) return false;
    const unsigned char c = static_cast<unsigned char>(s_[p_]);
    return std::isalnum(c) || c == '(' || c >= 0x80;
  }
  UnitDimension Expr() {
    SkipSpace();
    UnitDimension d = Term();
    for (;;) {
      SkipSpace();
      if (p_ >= s_.size()) break;
      const char c = s_[p_];
      if (c == '*' || c == '.' || c == '/') {
        ++p_;
        SkipSpace();
        d = Mul(d, Term(), c == '/' ? -1 : 1);
      } else if (AtTermStart()) {  // juxtaposition: "N m"
        d = Mul(d, Term(), 1);
      } else {
        break;
      }
    }
    return d;
  }
  // An optional exponent after a factor.
  int Exponent() {
    if (s_.compare(p_, 2, "**") == 0) {
      p_ += 2;
      return SignedInt();
    }
    if (p_ < s_.size() && s_[p_] == '^') {
      ++p_;
      return SignedInt();
    }
    // Superscripts: UTF-8 C2 B2/B3/B9, or Latin-1 B2/B3/B9.
    auto super = [&](size_t at, size_t* len) -> int {
      const unsigned char a = static_cast<unsigned char>(s_[at]);
      if (a == 0xC2 && at + 1 < s_.size()) {
        const unsigned char b = static_cast<unsigned char>(s_[at + 1]);
        *len = 2;
        if (b == 0xB2) return 2;
        if (b == 0xB3) return 3;
        if (b == 0xB9) return 1;
        return 0;
      }
      *len = 1;
      if (a == 0xB2) return 2;
      if (a == 0xB3) return 3;
      if (a == 0xB9) return 1;
      return 0;
    };
    if (p_ < s_.size()) {
      size_t len = 0;
      if (const int n = super(p_, &len); n != 0) {
        p_ += len;
        return n;
      }
      if (std::isdigit(static_cast<unsigned char>(s_[p_])) || s_[p_] == '-') {
        // "s2", "s-2": digits glued to the unit.
        const size_t save = p_;
        if (s_[p_] == '-' && !(p_ + 1 < s_.size() && std::isdigit(static_cast<unsigned char>(s_[p_ + 1])))) {
          return 1;
        }
        try {
          return SignedInt();
        } catch (const std::invalid_argument&) {
          p_ = save;
        }
      }
    }
    return 1;
  }
  int SignedInt() {
    SkipSpace();
    bool paren = false;
    if (p_ < s_.size() && s_[p_] == '(') {
      paren = true;
      ++p_;
    }
    int sign = 1;
    if (p_ < s_.size() && (s_[p_] == '-' || s_[p_] == '+')) {
      sign = s_[p_] == '-' ? -1 : 1;
      ++p_;
    }
    size_t b = p_;
    while (p_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[p_]))) ++p_;
    if (b == p_) Fail("expected an integer exponent at position " + std::to_string(b + 1));
    int n = 0;
    if (p_ - b > 2 || (n = std::stoi(s_.substr(b, p_ - b))) > kMaxExponent) {
      Fail("exponent " + s_.substr(b, p_ - b) + " is out of range (at most " + std::to_string(kMaxExponent) + ")");
    }
    if (paren) {
      if (p_ >= s_.size() || s_[p_] != ')') Fail("expected ')' after the exponent");
      ++p_;
    }
    return sign * n;
  }
  UnitDimension Term() {
    SkipSpace();
    if (p_ >= s_.size()) Fail("expected a unit at the end");
    UnitDimension d;
    if (s_[p_] == '(') {
      ++p_;
      d = Expr();
      SkipSpace();
      if (p_ >= s_.size() || s_[p_] != ')') Fail("expected ')'");
      ++p_;
    } else if (std::isdigit(static_cast<unsigned char>(s_[p_]))) {
      size_t b = p_;
      while (p_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[p_]))) ++p_;
      if (s_.substr(b, p_ - b) != "1") Fail("a number other than 1 (\"" + s_.substr(b, p_ - b) + "\")");
    } else {
      // A unit name: letters, the micro sign, Greek mu.
      size_t b = p_;
      while (p_ < s_.size()) {
        const unsigned char c = static_cast<unsigned char>(s_[p_]);
        if (std::isalpha(c)) {
          ++p_;
        } else if (c == 0xC2 && p_ + 1 < s_.size() && static_cast<unsigned char>(s_[p_ + 1]) == 0xB5) {
          p_ += 2;
        } else if (c == 0xCE && p_ + 1 < s_.size() && static_cast<unsigned char>(s_[p_ + 1]) == 0xBC) {
          p_ += 2;
        } else if (c == 0xB5) {
          ++p_;
        } else {
          break;
        }
      }
      if (b == p_) Fail("unexpected '" + s_.substr(p_, 1) + "'");
      d = Lookup(s_.substr(b, p_ - b));
    }
    return Pow(d, Exponent());
  }
  UnitDimension Lookup(const std::string& name) const {
    for (const UnitEntry& u : kUnits) {
      if (name == u.name) return {true, u.factor, u.length, u.force, u.time};
    }
    const std::string low = Lower(name);
    for (const UnitEntry& u : kUnits) {
      // Case-insensitive only for names that cannot change meaning that way.
      const std::string n = u.name;
      if (n == "g" || n == "G" || n == "mN" || n == "m" || n == "ms") continue;
      if (low == Lower(n)) return {true, u.factor, u.length, u.force, u.time};
    }
    std::string hint;
    if (low == "v" || low == "mv") hint = ": a voltage; the export is not calibrated to physical units";
    else if (low == "deg" || low == "degree" || low == "rpm" || low == "order") hint = ": not a translational unit";
    throw std::invalid_argument("unit '" + name + "' (in \"" + s_ + "\") is not a unit robomach can convert" + hint);
  }

  std::string s_;
  size_t p_{0};
};

// ------------------------------------------------------------ file walking --

// The file as bytes with a cursor that hands out lines (LF or CR-LF) and
// binary blocks, and counts lines for messages.
class Cursor {
 public:
  Cursor(std::string bytes) : b_(std::move(bytes)) {}
  bool eof() const { return p_ >= b_.size(); }
  int line() const { return line_; }  // the line the next Line() returns
  size_t pos() const { return p_; }
  std::string Line() {
    const size_t e = b_.find('\n', p_);
    std::string s = b_.substr(p_, e == std::string::npos ? std::string::npos : e - p_);
    p_ = e == std::string::npos ? b_.size() : e + 1;
    if (!s.empty() && s.back() == '\r') s.pop_back();
    ++line_;
    return s;
  }
  std::string PeekLine() const {
    const size_t e = b_.find('\n', p_);
    std::string s = b_.substr(p_, e == std::string::npos ? std::string::npos : e - p_);
    if (!s.empty() && s.back() == '\r') s.pop_back();
    return s;
  }
  // Takes n bytes; returns false if fewer remain.
  bool Bytes(size_t n, std::string_view* out) {
    if (b_.size() - p_ < n) return false;
    *out = std::string_view(b_).substr(p_, n);
    line_ += static_cast<int>(std::count(out->begin(), out->end(), '\n'));
    p_ += n;
    return true;
  }

 private:
  std::string b_;
  size_t p_{0};
  int line_{1};
};

bool IsDelimiter(const std::string& line) { return Trim(line) == "-1"; }

// Free-format numbers of a data line: whitespace-separated or touching
// ("-3.1E-004-2.7E-004"), Fortran D exponents accepted.
void ScanNumbers(const std::string& path, int line, const std::string& text, std::vector<double>* out) {
  std::string t = text;
  for (char& c : t) {
    if (c == 'D' || c == 'd') c = 'E';
  }
  const char* p = t.data();
  const char* end = p + t.size();
  while (p < end) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == ',')) ++p;
    if (p >= end) break;
    const char* start = p;
    if (*p == '+') ++p;
    double v = 0.0;
    const auto r = std::from_chars(p, end, v);
    if (r.ec != std::errc() || !std::isfinite(v)) {
      const char* stop = start;
      while (stop < end && *stop != ' ') ++stop;
      throw InputError({path, line, static_cast<int>(start - t.data()) + 1},
                       "expected a number, got \"" + std::string(start, stop) + "\"");
    }
    out->push_back(v);
    p = r.ptr;
  }
}

std::string Field(const std::string& s, size_t b, size_t e) {
  if (b >= s.size()) return "";
  return Trim(s.substr(b, std::min(e, s.size()) - b));
}

// An integer in fixed columns [b, e) (0-based), as Fortran I-format reads it.
int IntField(const std::string& path, int line, const std::string& s, size_t b, size_t e, const std::string& what) {
  const std::string f = Field(s, b, e);
  if (f.empty()) return 0;  // Fortran reads a blank field as 0
  int v = 0;
  const auto r = std::from_chars(f.data() + (f[0] == '+' ? 1 : 0), f.data() + f.size(), v);
  if (r.ec != std::errc() || r.ptr != f.data() + f.size()) {
    throw InputError({path, line, static_cast<int>(b) + 1},
                     what + ": expected an integer in columns " + std::to_string(b + 1) + "-" + std::to_string(e) +
                         ", got \"" + f + "\"");
  }
  return v;
}

// Whitespace tokens of a header line, read as integers where asked.
std::vector<std::string> Tokens(const std::string& s) {
  std::istringstream in(s);
  return {std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
}

UffAxis ReadAxis(const std::string& path, int line, const std::string& s, const std::string& record) {
  UffAxis a;
  a.line = line;
  a.specific_type = IntField(path, line, s, 0, 10, record + " specific data type");
  a.length_exponent = IntField(path, line, s, 10, 15, record + " length units exponent");
  a.force_exponent = IntField(path, line, s, 15, 20, record + " force units exponent");
  a.temperature_exponent = IntField(path, line, s, 20, 25, record + " temperature units exponent");
  a.label = Field(s, 26, 46);
  a.units = Field(s, 47, 67);
  return a;
}

double Decode(std::string_view bytes, size_t at, int width, bool big_endian) {
  unsigned char b[8];
  std::memcpy(b, bytes.data() + at, width);
  const bool host_big = std::endian::native == std::endian::big;
  if (big_endian != host_big) std::reverse(b, b + width);
  if (width == 4) {
    float f;
    std::memcpy(&f, b, 4);
    return f;
  }
  double d;
  std::memcpy(&d, b, 8);
  return d;
}

// Records 1-11 of a dataset 58/58b (the 11 header lines).
void ReadHeader(const std::string& path, const std::vector<std::pair<int, std::string>>& h, Uff58Record* r) {
  for (int k = 0; k < 5; ++k) r->id_lines[k] = RightTrim(h[k].second);
  // Record 6: format 2(I5,I10),2(1X,10A1,I10,I4).
  const auto& [l6, s6] = h[5];
  r->record6_line = l6;
  r->function_type = IntField(path, l6, s6, 0, 5, "record 6 function type");
  r->function_id = IntField(path, l6, s6, 5, 15, "record 6 function identification number");
  r->version = IntField(path, l6, s6, 15, 20, "record 6 version number");
  r->load_case = IntField(path, l6, s6, 20, 30, "record 6 load case");
  r->response_entity = Field(s6, 31, 41);
  r->response_node = IntField(path, l6, s6, 41, 51, "record 6 response node");
  r->response_direction = IntField(path, l6, s6, 51, 55, "record 6 response direction");
  r->reference_entity = Field(s6, 56, 66);
  r->reference_node = IntField(path, l6, s6, 66, 76, "record 6 reference node");
  r->reference_direction = IntField(path, l6, s6, 76, 80, "record 6 reference direction");
  // Record 7: format 3I10,3E13.5 (read free-format: exports do not keep the columns).
  const auto& [l7, s7] = h[6];
  r->record7_line = l7;
  std::vector<double> v;
  ScanNumbers(path, l7, s7, &v);
  if (v.size() < 5) {
    throw InputError({path, l7, 0}, "record 7: expected the ordinate data type, the number of points, the abscissa "
                                    "spacing, the abscissa minimum and increment; got " +
                                        std::to_string(v.size()) + " numbers");
  }
  for (int k = 0; k < 3; ++k) {
    // Bounded before any cast to an integer (1e121 here was UB; issue #22,
    // found by fuzz_uff58).
    if (v[k] != std::floor(v[k]) || std::abs(v[k]) > 2e9) {
      throw InputError({path, l7, 0}, "record 7: field " + std::to_string(k + 1) + " must be an integer of at most 10 digits, got " +
                                          Trim(s7));
    }
  }
  r->ordinate_type = static_cast<int>(v[0]);
  if (v[1] < 1 || v[1] > 1e8) {
    throw InputError({path, l7, 0}, "record 7: the number of data points must be between 1 and 1e8, got " +
                                        std::to_string(static_cast<long long>(v[1])));
  }
  r->num_points = static_cast<long>(v[1]);
  const int spacing = static_cast<int>(v[2]);
  if (spacing != 0 && spacing != 1) {
    throw InputError({path, l7, 0}, "record 7: abscissa spacing must be 0 (uneven) or 1 (even), got " +
                                        std::to_string(spacing));
  }
  r->even = spacing == 1;
  r->x_min = v[3];
  r->dx = v[4];
  if (r->ordinate_type != 2 && r->ordinate_type != 4 && r->ordinate_type != 5 && r->ordinate_type != 6) {
    throw InputError({path, l7, 0}, "record 7: ordinate data type " + std::to_string(r->ordinate_type) +
                                        " is not 2 (real single), 4 (real double), 5 (complex single) or 6 (complex "
                                        "double)");
  }
  r->abscissa = ReadAxis(path, h[7].first, h[7].second, "record 8");
  r->ordinate = ReadAxis(path, h[8].first, h[8].second, "record 9");
  r->denominator = ReadAxis(path, h[9].first, h[9].second, "record 10");
  r->z_axis = ReadAxis(path, h[10].first, h[10].second, "record 11");
}

// Fills x and y from the numbers of an ASCII data block.
void FromNumbers(const std::string& path, const std::vector<double>& d, Uff58Record* r) {
  const int per = (r->complex() ? 2 : 1) + (r->even ? 0 : 1);
  const long need = r->num_points * per;
  if (static_cast<long>(d.size()) < need) {
    throw InputError({path, r->record7_line, 0},
                     "record 7 announces " + std::to_string(r->num_points) + " points (" + std::to_string(need) +
                         " numbers), but the data block holds only " + std::to_string(d.size()) +
                         " numbers: the file is truncated or the header is wrong");
  }
  r->trailing_values = static_cast<long>(d.size()) - need;
  for (size_t k = need; k < d.size(); ++k) r->trailing_all_zero = r->trailing_all_zero && d[k] == 0.0;
  r->x.resize(r->num_points);
  r->y.resize(r->num_points);
  for (long p = 0; p < r->num_points; ++p) {
    const double* v = d.data() + p * per;
    int o = 0;
    if (!r->even) {
      r->x(p) = v[0];
      o = 1;
    } else {
      r->x(p) = r->x_min + p * r->dx;
    }
    r->y(p) = r->complex() ? std::complex<double>(v[o], v[o + 1]) : std::complex<double>(v[o], 0.0);
  }
}

void FromBytes(const std::string& path, int line, std::string_view bytes, bool big_endian, Uff58Record* r) {
  const int value = (r->ordinate_type == 2 || r->ordinate_type == 5) ? 4 : 8;
  const int ord = value * (r->complex() ? 2 : 1);
  int absc = 0;
  const size_t n = static_cast<size_t>(r->num_points);
  if (!r->even) {
    // The abscissa of an uneven record is E13.5 in ASCII, so 4 bytes; some
    // writers store 8. The declared byte count tells which.
    absc = bytes.size() == n * (8 + ord) ? 8 : 4;
  }
  const size_t need = n * (absc + ord);
  if (bytes.size() < need) {
    throw InputError({path, line, 0},
                     "58b record: the header declares " + std::to_string(bytes.size()) + " data bytes, but record 7's " +
                         std::to_string(n) + " points of ordinate type " + std::to_string(r->ordinate_type) +
                         (r->even ? "" : " with an uneven abscissa") + " need " + std::to_string(need));
  }
  r->trailing_values = static_cast<long>((bytes.size() - need) / value);
  for (size_t k = need; k < bytes.size(); ++k) r->trailing_all_zero = r->trailing_all_zero && bytes[k] == 0;
  r->x.resize(r->num_points);
  r->y.resize(r->num_points);
  size_t at = 0;
  for (size_t p = 0; p < n; ++p) {
    if (!r->even) {
      r->x(p) = Decode(bytes, at, absc, big_endian);
      at += absc;
    } else {
      r->x(p) = r->x_min + static_cast<double>(p) * r->dx;
    }
    const double re = Decode(bytes, at, value, big_endian);
    const double im = r->complex() ? Decode(bytes, at + value, value, big_endian) : 0.0;
    at += ord;
    if (!std::isfinite(re) || !std::isfinite(im) || !std::isfinite(r->x(p))) {
      throw InputError({path, line, 0}, "58b record: point " + std::to_string(p + 1) +
                                            " is not a finite number (wrong byte order or floating-point format?)");
    }
    r->y(p) = {re, im};
  }
}

}  // namespace

UnitDimension ParseUnitLabel(const std::string& label) {
  const std::string t = Trim(label);
  const std::string low = Lower(t);
  if (t.empty() || low == "none" || low == "unknown") return {};
  UnitDimension d = UnitParser(t).Parse();
  return d;
}

std::string UffFunctionTypeName(int code) {
  static const char* const kNames[] = {
      "general or unknown function", "time response", "auto spectrum", "cross spectrum",
      "frequency response function", "transmissibility", "coherence", "auto correlation",
      "cross correlation", "power spectral density", "energy spectral density", "probability density function",
      "spectrum", "cumulative frequency distribution", "peaks valley", "stress/cycles", "strain/cycles", "orbit",
      "mode indicator function", "force pattern", "partial power", "partial coherence", "eigenvalue",
      "eigenvector", "shock response spectrum", "finite impulse response function", "multiple coherence",
      "order function", "phase compensation"};
  if (code >= 0 && code < static_cast<int>(std::size(kNames))) return kNames[code];
  return "function type " + std::to_string(code) + " (unknown)";
}

bool LooksLikeUff(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string s;
  for (int k = 0; k < 20 && std::getline(in, s); ++k) {
    if (!Trim(s).empty()) return IsDelimiter(s);
  }
  return false;
}

UffFile ReadUffFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, 0, 0}, "cannot open file for reading");
  Cursor c(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  UffFile out;
  int current_units = -1;
  while (!c.eof()) {
    const int dl = c.line();
    const std::string d = c.Line();
    if (Trim(d).empty()) continue;
    if (!IsDelimiter(d)) {
      throw InputError({path, dl, 0}, "expected the UFF dataset delimiter \"    -1\", got \"" + Trim(d).substr(0, 40) +
                                          "\"" + (out.records.empty() && out.skipped.empty() && out.units.empty()
                                                      ? " (is this a Universal File Format file?)"
                                                      : ""));
    }
    // Blank lines between the delimiter and the dataset number are tolerated.
    while (!c.eof() && Trim(c.PeekLine()).empty()) c.Line();
    if (c.eof()) break;  // a trailing delimiter
    const int tl = c.line();
    const std::string type_line = c.Line();
    const std::vector<std::string> tt = Tokens(type_line);
    const std::string number = tt.empty() ? "" : tt[0];
    if (number == "58b" || (number == "58" && tt.size() > 1 && Lower(tt[1]) == "b")) {
      // 58b header: format I6,1A1,I6,I6,I12,I12,I6,I6,I12,I12.
      const size_t o = number == "58b" ? 1 : 2;
      std::vector<long long> v;
      for (size_t k = o; k < tt.size() && v.size() < 4; ++k) {
        long long x = 0;
        const auto r = std::from_chars(tt[k].data(), tt[k].data() + tt[k].size(), x);
        if (r.ec != std::errc() || r.ptr != tt[k].data() + tt[k].size()) {
          throw InputError({path, tl, 0}, "58b header: expected integers (byte order, floating-point format, ASCII "
                                          "lines, bytes), got \"" + tt[k] + "\"");
        }
        v.push_back(x);
      }
      if (v.size() < 4) {
        throw InputError({path, tl, 0}, "58b header: expected byte order, floating-point format, number of ASCII "
                                        "lines and number of bytes after \"58b\"");
      }
      const long long order = v[0], fp = v[1], ascii_lines = v[2], nbytes = v[3];
      if (order != 1 && order != 2) {
        throw InputError({path, tl, 0}, "58b header: byte ordering " + std::to_string(order) +
                                            " is not 1 (little endian) or 2 (big endian)");
      }
      if (fp != 2) {
        throw InputError({path, tl, 0}, "58b header: floating-point format " + std::to_string(fp) +
                                            (fp == 1 ? " (DEC VMS)" : fp == 3 ? " (IBM 5/370)" : "") +
                                            " is not supported; robomach reads IEEE 754 (format 2)");
      }
      if (ascii_lines != 11) {
        throw InputError({path, tl, 0}, "58b header: " + std::to_string(ascii_lines) +
                                            " ASCII header lines announced; dataset 58b has 11 (records 1-11)");
      }
      if (nbytes < 1 || nbytes > (1LL << 31)) {
        throw InputError({path, tl, 0}, "58b header: the number of data bytes must be between 1 and 2^31, got " +
                                            std::to_string(nbytes));
      }
      std::vector<std::pair<int, std::string>> h;
      for (int k = 0; k < 11; ++k) {
        if (c.eof()) throw InputError({path, tl, 0}, "58b record ends inside its 11 header lines");
        const int l = c.line();
        h.emplace_back(l, c.Line());
      }
      Uff58Record r;
      r.line = tl;
      r.binary = true;
      ReadHeader(path, h, &r);
      std::string_view bytes;
      const int data_line = c.line();
      if (!c.Bytes(static_cast<size_t>(nbytes), &bytes)) {
        throw InputError({path, data_line, 0}, "58b record at line " + std::to_string(tl) + " declares " +
                                                   std::to_string(nbytes) +
                                                   " data bytes, but the file ends before them (truncated, or "
                                                   "copied in text mode)");
      }
      FromBytes(path, data_line, bytes, order == 2, &r);
      // The closing delimiter follows the block, possibly after a line end.
      while (!c.eof() && Trim(c.PeekLine()).empty()) c.Line();
      const int el = c.line();
      if (c.eof() || !IsDelimiter(c.Line())) {
        throw InputError({path, el, 0}, "58b record at line " + std::to_string(tl) + ": expected the closing \"    -1\" "
                                        "right after its " + std::to_string(nbytes) +
                                            " data bytes; the declared byte count is wrong, or the file was copied "
                                            "in text mode");
      }
      out.records.push_back(std::move(r));
      out.record_units.push_back(current_units);
      continue;
    }
    // ASCII dataset: its lines up to the next delimiter.
    std::vector<std::pair<int, std::string>> body;
    bool closed = false;
    while (!c.eof()) {
      const int l = c.line();
      std::string s = c.Line();
      if (IsDelimiter(s)) {
        closed = true;
        break;
      }
      body.emplace_back(l, std::move(s));
    }
    if (!closed) {
      throw InputError({path, tl, 0}, "UFF dataset " + number + " starting here has no closing \"    -1\" line "
                                      "(the file is truncated)");
    }
    if (number == "58") {
      if (body.size() < 11) {
        throw InputError({path, tl, 0}, "dataset 58 record has " + std::to_string(body.size()) +
                                            " lines before its closing -1; expected 11 header lines and data");
      }
      Uff58Record r;
      r.line = tl;
      ReadHeader(path, body, &r);
      std::vector<double> numbers;
      // Bounded by what the lines can hold (a corrupt count must not allocate
      // gigabytes before the data say it is wrong): at most 6 numbers a line.
      numbers.reserve(std::min(static_cast<size_t>(r.num_points) * 3, (body.size() - 11) * 6));
      for (size_t k = 11; k < body.size(); ++k) ScanNumbers(path, body[k].first, body[k].second, &numbers);
      FromNumbers(path, numbers, &r);
      out.records.push_back(std::move(r));
      out.record_units.push_back(current_units);
    } else if (number == "164") {
      // Record 1: I10,20A1,I10; record 2: 3D25.17; record 3: D25.17.
      if (body.size() < 2) throw InputError({path, tl, 0}, "dataset 164 (units) needs at least 2 records");
      UffUnits u;
      u.line = tl;
      u.code = IntField(path, body[0].first, body[0].second, 0, 10, "dataset 164 units code");
      u.description = Field(body[0].second, 10, 30);
      std::vector<double> f;
      for (size_t k = 1; k < body.size(); ++k) ScanNumbers(path, body[k].first, body[k].second, &f);
      if (f.size() < 2 || !(f[0] > 0.0) || !(f[1] > 0.0)) {
        throw InputError({path, body[1].first, 0},
                         "dataset 164 record 2: expected positive length and force conversion factors");
      }
      u.length = f[0];
      u.force = f[1];
      out.units.push_back(u);
      current_units = static_cast<int>(out.units.size()) - 1;
    } else {
      if (number.empty()) throw InputError({path, tl, 0}, "expected a dataset number after the delimiter \"-1\"");
      out.skipped[number].push_back(tl);
    }
  }
  return out;
}

}  // namespace robomach::io
