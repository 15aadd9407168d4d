#pragma once
// Sense checks of typed numbers (issue #35 item 1, docs/plausibility.md):
// a value outside a documented plausible range becomes a warning that
// names the likely unit mistake; the tools print the warnings and flag
// their result (exit 3). Private to io.

#include <string>
#include <vector>

#include "robomach/io/yaml_doc.h"

namespace robomach::io {

/// A plausible range of a quantity in the unit of its key, about 100 times
/// wider than practice where the units allow (sources in the headers that
/// define the constants).
struct PlausibleRange {
  double lo;
  double hi;
  std::string unit;       // as the key writes it: "kg", "m", "N·m/rad"
  std::string practice;   // "robot links and end-effector bodies"
  std::string low_hint;   // the likely mistake below lo, as a question
  std::string high_hint;  // the likely mistake above hi
};

/// The warning text: "implausible (unit mistake?): file:line:col: key value
/// unit is outside the lo to hi unit of practice: hint".
std::string ImplausibleMessage(const YamlDoc& node, const std::string& value, const PlausibleRange& r, bool low);

/// Appends ImplausibleMessage to *out when v (the node's value, or a value
/// derived from it such as |v|) is outside [r.lo, r.hi].
void CheckPlausible(const YamlDoc& node, double v, const PlausibleRange& r, std::vector<std::string>* out);

/// One typed angle, for the unit checks below.
struct TypedAngle {
  YamlDoc node;
  double value;  // as typed
};

/// Angles typed under `_deg` keys that all look like radians: every
/// non-zero |value| within one turn (2 pi = 6.28) and at least one of them
/// not whole (1.5708 is radians, 5 deg is degrees). One warning naming the
/// first such key and the largest value; nothing for all-zero lists.
void CheckDegreesNotRadians(const std::vector<TypedAngle>& angles, std::vector<std::string>* out);

/// Angles typed under `_rad` keys: any |value| over one turn looks like
/// degrees (90 rad is 5157 deg). One warning naming the largest.
void CheckRadiansNotDegrees(const std::vector<TypedAngle>& angles, std::vector<std::string>* out);

/// A `_deg` value refused by its range [lo, hi] (exit 65): the message names
/// radians when value x 180/pi falls inside the range ("2.06 is 118 deg in
/// radians: radians typed in a _deg field?").
double DegreesInRange(const YamlDoc& node, double lo, double hi, bool include_lo = true, bool include_hi = true);

}  // namespace robomach::io
