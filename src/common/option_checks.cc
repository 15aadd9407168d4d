#include "robomach/common/option_checks.h"

#include <cmath>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"

namespace robomach {

std::string FieldNames::Name(const std::string& field) const {
  const auto it = names.find(field);
  return it == names.end() ? field : it->second;
}

void CheckOptionRange(const std::string& field, double value, double lo, double hi) {
  if (value >= lo && value <= hi) return;
  std::ostringstream s;
  s << field << ": expected a value in [" << lo << ", " << hi << "], got " << value;
  throw OptionError(field, s.str());
}

std::string ImplausibleOption(const std::string& name, double value, double lo, double hi, const std::string& unit,
                              const std::string& practice, const std::string& low_hint,
                              const std::string& high_hint) {
  if (value >= lo && value <= hi) return "";
  const std::string u = unit.empty() ? "" : " " + unit;
  return "implausible (unit mistake?): " + name + " " + FormatNumber(value, 7) + u + " is outside the " +
         FormatNumber(lo, 7) + " to " + FormatNumber(hi, 7) + u + " of " + practice + ": " +
         (value < lo ? low_hint : high_hint);
}

std::string RadiansInDegreeOption(const std::string& name, double value_deg) {
  constexpr double kTurnRad = 6.283185307179586;
  if (value_deg == 0.0 || !(std::abs(value_deg) <= kTurnRad) || value_deg == std::floor(value_deg)) return "";
  return "implausible (unit mistake?): " + name + " " + FormatNumber(value_deg, 7) +
         " deg is within 2 pi = 6.28 and not whole, as radians are: radians typed in the deg option? (" +
         FormatNumber(value_deg, 7) + " rad is " + FormatNumber(value_deg * 180.0 / 3.141592653589793, 4) + " deg)";
}

}  // namespace robomach
