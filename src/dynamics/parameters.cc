#include "robomach/dynamics/parameters.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "robomach/common/number_format.h"

namespace robomach::dynamics {
void ParameterSet::Add(ParameterSpec spec) {
  if (Has(spec.name)) throw std::invalid_argument("parameter '" + spec.name + "' defined twice");
  if (!(spec.lower <= spec.default_value && spec.default_value <= spec.upper)) {
    throw std::invalid_argument("parameter '" + spec.name + "': default " +
                                FormatNumber(spec.default_value, 10) + " " + spec.unit + " is outside [" +
                                FormatNumber(spec.lower, 10) + ", " + FormatNumber(spec.upper, 10) + "]");
  }
  specs_.push_back(std::move(spec));
  values_.conservativeResize(specs_.size());
  values_(values_.size() - 1) = specs_.back().default_value;
}

int ParameterSet::IndexOf(std::string_view name) const {
  for (size_t i = 0; i < specs_.size(); ++i) {
    if (specs_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::string ParameterSet::NameList() const {
  std::string s;
  for (const auto& p : specs_) s += (s.empty() ? "" : ", ") + p.name;
  return s;
}

const ParameterSpec& ParameterSet::spec(std::string_view name) const {
  const int i = IndexOf(name);
  if (i < 0) {
    throw std::invalid_argument("unknown parameter '" + std::string(name) + "'; known: " +
                                NameList());
  }
  return specs_[i];
}

double ParameterSet::Get(std::string_view name) const {
  spec(name);
  return values_(IndexOf(name));
}

void ParameterSet::Set(std::string_view name, double value) {
  const ParameterSpec& s = spec(name);
  if (!std::isfinite(value) || value < s.lower || value > s.upper) {
    throw std::invalid_argument("parameter '" + s.name + "': " + FormatNumber(value, 10) + " " + s.unit +
                                " is outside its bounds [" + FormatNumber(s.lower, 10) + ", " + FormatNumber(s.upper, 10) +
                                "]");
  }
  values_(IndexOf(name)) = value;
}

void ParameterSet::SetClamped(std::string_view name, double value) {
  const ParameterSpec& s = spec(name);
  if (!std::isfinite(value)) {
    throw std::invalid_argument("parameter '" + s.name + "': " + FormatNumber(value, 10) + " is not a finite number");
  }
  values_(IndexOf(name)) = std::min(std::max(value, s.lower), s.upper);
}

}  // namespace robomach::dynamics
