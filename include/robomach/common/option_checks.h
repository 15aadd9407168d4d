#pragma once
// The checks of an options struct's fields (issue #36: a validator for every
// options struct that names field, value and bound, used by the tools and
// Python alike). The workflows' Validate() call these with the field's name;
// a tool words the same message with its option (apps::FromFields,
// apps::CheckOptionRange), so a range or a sense finding reads the same
// whichever layer makes it.

#include <map>
#include <string>

namespace robomach {

/// How an options struct's findings and messages name its fields: a tool
/// puts its options in `names` ("fmax_hz" -> "--fmax-hz"), Python the
/// keywords that differ from the fields; a field not in it goes by its own
/// name. The errors (OptionError) name the fields themselves, for the caller
/// to map (apps::FromFields). The options structs derive from it
/// (workflows::FrfSynthOptions, TrackerSynthOptions, AxisSynthOptions):
///
///   struct FooOptions : FieldNames { double fmax_hz{5000.0}; ... };
///   finding(ImplausibleOption(o.Name("fmax_hz"), o.fmax_hz, ...));
struct FieldNames {
  std::map<std::string, std::string> names;  // field -> how the messages name it

  /// names[field], or `field` itself when it has no entry.
  std::string Name(const std::string& field) const;
};

/// @throws OptionError(field, "FIELD: expected a value in [LO, HI], got
/// VALUE") unless lo <= value <= hi (a NaN is outside). The numbers as a
/// stream writes them.
void CheckOptionRange(const std::string& field, double value, double lo, double hi);

/// Sense check of a typed value (docs/plausibility.md): "" when lo <= value
/// <= hi, else "implausible (unit mistake?): NAME VALUE UNIT is outside the
/// LO to HI UNIT of PRACTICE: HINT" (low_hint below lo, high_hint above hi),
/// a finding for the caller to warn about and flag its result with.
std::string ImplausibleOption(const std::string& name, double value, double lo, double hi, const std::string& unit,
                              const std::string& practice, const std::string& low_hint,
                              const std::string& high_hint);

/// Sense check of an angle typed in degrees: "" unless the value looks like
/// radians, i.e. is within one turn in radians (|v| <= 2 pi = 6.28) and not
/// whole (-1.5708 for -90 deg; 5 deg is degrees), the rule of the files'
/// _deg fields (io::CheckDegreesNotRadians). The finding names the angle
/// the value is in degrees.
std::string RadiansInDegreeOption(const std::string& name, double value_deg);

}  // namespace robomach
