#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace robomach::dynamics {

/// One named model quantity that a later step may fit or switch. The name
/// carries the unit (it crosses file and command-line boundaries) and the
/// value is in that unit, which is always SI: `m6_kg`, `d6_m`, `alpha_s`,
/// `beta_per_s`, `kq3_Nm_per_rad`, `tip_mass.mass_kg`.
struct ParameterSpec {
  std::string name;
  std::string unit;         // "kg", "m", "s", "1/s", "N·m/rad", ...
  double default_value{0.0};
  double lower{-1e300};     // inclusive bounds
  double upper{1e300};
  bool fittable{true};
  std::string description;
};

/// An ordered set of named parameters with values. Names are unique.
class ParameterSet {
 public:
  /// @throws std::invalid_argument on a duplicate name or a default outside
  ///   the bounds.
  void Add(ParameterSpec spec);

  int size() const { return static_cast<int>(specs_.size()); }
  bool Has(std::string_view name) const { return IndexOf(name) >= 0; }
  int IndexOf(std::string_view name) const;
  const std::vector<ParameterSpec>& specs() const { return specs_; }
  const ParameterSpec& spec(std::string_view name) const;
  const Eigen::VectorXd& values() const { return values_; }

  /// @throws std::invalid_argument "unknown parameter 'm7_kg'; known: ...".
  double Get(std::string_view name) const;
  /// @throws std::invalid_argument for an unknown name, a non-finite value or
  ///   one outside [lower, upper] (the message names both).
  void Set(std::string_view name, double value);
  /// Set for values an algorithm computed (a scan's grid point, a fitted
  /// value, a step from a bound) that may pass a bound by round-off or by
  /// design: the value is clamped to [lower, upper]. A value on a bound is
  /// legal. @throws std::invalid_argument for an unknown name or a
  ///   non-finite value.
  void SetClamped(std::string_view name, double value);
  /// All names, comma separated, for messages.
  std::string NameList() const;

 private:
  std::vector<ParameterSpec> specs_;
  Eigen::VectorXd values_;
};

}  // namespace robomach::dynamics
