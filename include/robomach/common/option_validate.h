#pragma once
// The one-sided bounds and the nested structs of the options structs'
// Validate() (issue #36), beside CheckOptionRange (common/option_checks.h):
// every message has CheckOptionRange's shape, "FIELD: expected ..., got
// VALUE", so that it names the field, its bound and its value, and a tool's
// ValidateOptions puts its option in the field's place.

#include <cmath>
#include <sstream>
#include <string>

#include "robomach/common/errors.h"

namespace robomach {

/// @throws OptionError(field, "FIELD: expected a value > LO, got VALUE")
/// unless value > lo (a NaN is not; +inf is: an open band's fmax_hz). The
/// numbers as a stream writes them.
inline void CheckOptionAbove(const std::string& field, double value, double lo) {
  if (value > lo) return;
  std::ostringstream s;
  s << field << ": expected a value > " << lo << ", got " << value;
  throw OptionError(field, s.str());
}

/// @throws OptionError(field, "FIELD: expected a value >= LO, got VALUE")
/// unless value >= lo (a NaN is not): the counts (>= 1) and the non-negative
/// sizes.
inline void CheckOptionAtLeast(const std::string& field, double value, double lo) {
  if (value >= lo) return;
  std::ostringstream s;
  s << field << ": expected a value >= " << lo << ", got " << value;
  throw OptionError(field, s.str());
}

/// @throws OptionError(field, "FIELD: expected a finite value, got VALUE")
/// for a NaN or an infinity.
inline void CheckOptionFinite(const std::string& field, double value) {
  if (std::isfinite(value)) return;
  std::ostringstream s;
  s << field << ": expected a finite value, got " << value;
  throw OptionError(field, s.str());
}

/// @throws OptionError(hi_field, "HI_FIELD: expected a value > LO_FIELD LO,
/// got HI") unless 0 <= lo < hi (a band [Hz]: lo_field "fmin_hz", hi_field
/// "fmax_hz"; hi may be +inf); lo first: "LO_FIELD: expected a value >= 0,
/// got LO".
inline void CheckOptionBand(const std::string& lo_field, double lo, const std::string& hi_field, double hi) {
  CheckOptionAtLeast(lo_field, lo, 0.0);
  if (hi > lo) return;
  std::ostringstream s;
  s << hi_field << ": expected a value > " << lo_field << " " << lo << ", got " << hi;
  throw OptionError(hi_field, s.str());
}

/// Runs `nested.Validate()`, the options struct held in the field `prefix`
/// of another ("modal_fit" of CalibrationOptions): its OptionError is thrown
/// again with the field as the outer struct names it ("modal_fit.fmin_hz"),
/// in field() and at the head of the message.
template <class T>
void ValidateNested(const std::string& prefix, const T& nested) {
  try {
    nested.Validate();
  } catch (const OptionError& e) {
    const std::string what = e.what();
    const std::string field = prefix + "." + e.field();
    throw OptionError(field, what.rfind(e.field(), 0) == 0 ? prefix + "." + what : field + ": " + what);
  }
}

}  // namespace robomach
