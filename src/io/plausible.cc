#include "plausible.h"

#include <cmath>

#include "robomach/common/number_format.h"
#include "robomach/common/units.h"

namespace robomach::io {
namespace {
// One turn: an angle in radians is within it (joint angles, DH twists and
// offsets, rpy); degrees mostly are not.
constexpr double kOneTurn = 2.0 * kPi;
}  // namespace

std::string ImplausibleMessage(const YamlDoc& node, const std::string& value, const PlausibleRange& r, bool low) {
  // The value as typed; the limits in plain digits (100000, not 1e+05).
  const std::string unit = r.unit.empty() ? "" : " " + r.unit;
  return "implausible (unit mistake?): " + node.location().ToString() + ": " + node.key_path() + " " + value + unit +
         " is outside the " + FormatNumber(r.lo, 7) + " to " + FormatNumber(r.hi, 7) + unit + " of " + r.practice + ": " + (low ? r.low_hint : r.high_hint);
}

void CheckPlausible(const YamlDoc& node, double v, const PlausibleRange& r, std::vector<std::string>* out) {
  if (!out || (v >= r.lo && v <= r.hi)) return;
  out->push_back(ImplausibleMessage(node, node.String(), r, v < r.lo));
}

void CheckDegreesNotRadians(const std::vector<TypedAngle>& angles, std::vector<std::string>* out) {
  if (!out) return;
  const TypedAngle* largest = nullptr;
  bool fractional = false;
  for (const TypedAngle& a : angles) {
    const double m = std::abs(a.value);
    if (m == 0.0) continue;
    if (m > kOneTurn) return;  // a value only degrees can be
    if (m != std::floor(m)) fractional = true;
    if (!largest || m > std::abs(largest->value)) largest = &a;
  }
  if (!largest || !fractional) return;
  out->push_back("implausible (unit mistake?): " + largest->node.location().ToString() + ": " +
                 largest->node.key_path() + " " + largest->node.String() + ": every non-zero angle under the _deg keys " +
                 "here is within 2 pi = 6.28 (" + std::to_string(angles.size()) + " angles, largest " +
                 FormatNumber(std::abs(largest->value), 6) + "), as radians are: radians typed in _deg fields? (" +
                 FormatNumber(largest->value, 6) + " rad is " + FormatNumber(RadToDeg(largest->value), 4) + " deg)");
}

void CheckRadiansNotDegrees(const std::vector<TypedAngle>& angles, std::vector<std::string>* out) {
  if (!out) return;
  const TypedAngle* largest = nullptr;
  for (const TypedAngle& a : angles) {
    if (std::abs(a.value) > kOneTurn && (!largest || std::abs(a.value) > std::abs(largest->value))) largest = &a;
  }
  if (!largest) return;
  out->push_back("implausible (unit mistake?): " + largest->node.location().ToString() + ": " +
                 largest->node.key_path() + " " + largest->node.String() + " rad is " +
                 FormatNumber(RadToDeg(largest->value), 4) + " deg, more than a turn: degrees typed in a _rad field?");
}

double DegreesInRange(const YamlDoc& node, double lo, double hi, bool include_lo, bool include_hi) {
  const double v = node.Number();
  const auto inside = [&](double x) {
    return (include_lo ? x >= lo : x > lo) && (include_hi ? x <= hi : x < hi);
  };
  if (inside(v)) return v;
  std::string message = "expected an angle in " + std::string(include_lo ? "[" : "(") + FormatNumber(lo, 7) + ", " +
                        FormatNumber(hi, 7) + (include_hi ? "]" : ")") + " deg, got " + node.String();
  if (inside(RadToDeg(v))) {
    message += ": " + node.String() + " rad is " + FormatNumber(RadToDeg(v), 4) + " deg; radians typed in a _deg field?";
  }
  throw node.Error(message);
}

}  // namespace robomach::io
