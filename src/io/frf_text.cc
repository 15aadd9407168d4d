#include "frf_text.h"

#include "text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace robomach::io::frf_text {

using dynamics::Frf;
using dynamics::FrfKey;

std::string Fmt(double v) {
  std::ostringstream o;
  o.precision(10);
  o << v;
  return o.str();
}

// Log-log slope of |H| over the lowest lines. A receptance tends to the static compliance below the first
// resonance (slope ~0), a mobility grows like f (slope 1), an accelerance
// like f² (slope 2). Returns NaN if there are too few usable lines.
namespace {

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

}  // namespace

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

}  // namespace robomach::io::frf_text
