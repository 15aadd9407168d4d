#include "robomach/machine/iso230.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "robomach/common/number_format.h"

namespace robomach::machine {
namespace {

void MeanAndS(const std::vector<double>& x, double* mean, double* s) {
  double sum = 0.0;
  for (double v : x) sum += v;
  *mean = sum / static_cast<double>(x.size());
  double ss = 0.0;
  for (double v : x) ss += (v - *mean) * (v - *mean);
  *s = std::sqrt(ss / static_cast<double>(x.size() - 1));
}

}  // namespace

double WrapDeviationDeg(double d) {
  double w = std::remainder(d, 360.0);  // [-180, 180]
  if (w <= -180.0) w += 360.0;
  return w;
}

Iso230Result EvaluateIso230(const std::vector<Iso230Approach>& approaches) {
  if (approaches.empty()) throw std::invalid_argument("ISO 230-2: no approaches");
  std::map<double, std::pair<std::vector<double>, std::vector<double>>> by_target;
  std::set<std::tuple<double, int, bool>> seen;
  for (const auto& a : approaches) {
    if (!std::isfinite(a.target) || !std::isfinite(a.deviation)) {
      throw std::invalid_argument("ISO 230-2: non-finite target or deviation");
    }
    if (!seen.insert({a.target, a.run, a.up}).second) {
      throw std::invalid_argument("ISO 230-2: target " + FormatNumber(a.target, 10) + ", run " + std::to_string(a.run) +
                                  ", direction " + (a.up ? "+" : "-") + " is given twice");
    }
    auto& d = by_target[a.target];
    (a.up ? d.first : d.second).push_back(a.deviation);
  }
  Iso230Result r;
  for (const auto& [target, d] : by_target) {
    if (d.first.size() < 2 || d.second.size() < 2) {
      throw std::invalid_argument("ISO 230-2: target " + FormatNumber(target, 10) + " has " + std::to_string(d.first.size()) +
                                  " runs in + and " + std::to_string(d.second.size()) +
                                  " in - direction; at least 2 each are needed (ISO asks for 5)");
    }
    Iso230Target t;
    t.target = target;
    t.runs_up = static_cast<int>(d.first.size());
    t.runs_down = static_cast<int>(d.second.size());
    MeanAndS(d.first, &t.mean_up, &t.s_up);
    MeanAndS(d.second, &t.mean_down, &t.s_down);
    t.mean = 0.5 * (t.mean_up + t.mean_down);
    t.reversal = t.mean_up - t.mean_down;
    t.R_up = 4.0 * t.s_up;
    t.R_down = 4.0 * t.s_down;
    t.R = std::max({2.0 * t.s_up + 2.0 * t.s_down + std::abs(t.reversal), t.R_up, t.R_down});
    r.targets.push_back(t);
  }
  auto max_of = [&](auto f) {
    double m = -INFINITY;
    for (const auto& t : r.targets) m = std::max(m, f(t));
    return m;
  };
  auto min_of = [&](auto f) {
    double m = INFINITY;
    for (const auto& t : r.targets) m = std::min(m, f(t));
    return m;
  };
  r.E_up = max_of([](const Iso230Target& t) { return t.mean_up; }) - min_of([](const Iso230Target& t) { return t.mean_up; });
  r.E_down = max_of([](const Iso230Target& t) { return t.mean_down; }) -
             min_of([](const Iso230Target& t) { return t.mean_down; });
  r.E = max_of([](const Iso230Target& t) { return std::max(t.mean_up, t.mean_down); }) -
        min_of([](const Iso230Target& t) { return std::min(t.mean_up, t.mean_down); });
  r.M = max_of([](const Iso230Target& t) { return t.mean; }) - min_of([](const Iso230Target& t) { return t.mean; });
  r.R_up = max_of([](const Iso230Target& t) { return t.R_up; });
  r.R_down = max_of([](const Iso230Target& t) { return t.R_down; });
  r.R = max_of([](const Iso230Target& t) { return t.R; });
  r.B = max_of([](const Iso230Target& t) { return std::abs(t.reversal); });
  double sum_b = 0.0;
  for (const auto& t : r.targets) sum_b += t.reversal;
  r.B_mean = sum_b / static_cast<double>(r.targets.size());
  r.A_up = max_of([](const Iso230Target& t) { return t.mean_up + 2.0 * t.s_up; }) -
           min_of([](const Iso230Target& t) { return t.mean_up - 2.0 * t.s_up; });
  r.A_down = max_of([](const Iso230Target& t) { return t.mean_down + 2.0 * t.s_down; }) -
             min_of([](const Iso230Target& t) { return t.mean_down - 2.0 * t.s_down; });
  r.A = max_of([](const Iso230Target& t) { return std::max(t.mean_up + 2.0 * t.s_up, t.mean_down + 2.0 * t.s_down); }) -
        min_of([](const Iso230Target& t) { return std::min(t.mean_up - 2.0 * t.s_up, t.mean_down - 2.0 * t.s_down); });
  return r;
}

}  // namespace robomach::machine

namespace robomach::machine {

std::vector<std::string> Iso230UnitFindings(const std::string& axis, const Iso230Result& r, bool rotary) {
  std::vector<std::string> out;
  if (r.targets.empty()) return out;
  double dev = 0.0, target = 0.0;
  for (const Iso230Target& t : r.targets) {
    dev = std::max({dev, std::abs(t.mean_up) + 2 * t.s_up, std::abs(t.mean_down) + 2 * t.s_down});
    target = std::max(target, std::abs(t.target));
  }
  const double travel = r.targets.back().target - r.targets.front().target;
  const double magnitude = std::max(target, travel);
  char b[512];
  if (rotary) {
    if (dev > kMaxPlausibleRotaryDeviationDeg) {
      std::snprintf(b, sizeof b,
                    "axis %s: deviations up to %.4g deg, more than the %.4g deg a rotary axis can be off: arcsec or "
                    "another unit under the _deg headers?",
                    axis.c_str(), dev, kMaxPlausibleRotaryDeviationDeg);
      out.push_back(b);
    }
    return out;
  }
  // Relative limit with a floor for short strokes (iso230.h).
  if (magnitude > 0 && dev > std::max(kMaxPlausibleDeviationFraction * magnitude, kMinPlausibleDeviationLimitMm)) {
    std::snprintf(b, sizeof b,
                  "axis %s: deviations up to %.4g mm are %.3g %% of the targets' magnitude (%.4g mm; more than "
                  "%.3g %% of it or %.3g mm, whichever is larger, is not a positioning error): measured values in "
                  "um (or targets in m) under the _mm headers?",
                  axis.c_str(), dev, 100 * dev / magnitude, magnitude, 100 * kMaxPlausibleDeviationFraction,
                  kMinPlausibleDeviationLimitMm);
    out.push_back(b);
  } else if (dev > kMaxPlausibleLinearDeviationMm) {
    std::snprintf(b, sizeof b,
                  "axis %s: deviations up to %.4g mm, more than the %.4g mm a machine axis can be off: targets and "
                  "measured values in um under the _mm headers?",
                  axis.c_str(), dev, kMaxPlausibleLinearDeviationMm);
    out.push_back(b);
  }
  return out;
}

}  // namespace robomach::machine
