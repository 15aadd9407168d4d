#pragma once
// Axes of a machine as its measuring systems see them (seed 002, eq. 1).

#include <cstdint>
#include <string>
#include <vector>

namespace robomach::machine {

enum class AxisKind { kLinear, kRotary };

/// One measured axis: measured coordinate = origin + count * resolution
/// [seed 002, eq. (1)]. SI inside the library: metres for linear axes,
/// radians for rotary ones.
struct AxisScale {
  std::string name;                // "X", "B", ...
  AxisKind kind{AxisKind::kLinear};
  double resolution{0.0};          // [m] or [rad] per count, > 0
  double origin{0.0};              // [m] or [rad]

  double Measured(std::int64_t count) const { return origin + static_cast<double>(count) * resolution; }
};

/// Index of the axis named `name` in `axes`, or -1.
int FindAxis(const std::vector<AxisScale>& axes, const std::string& name);

}  // namespace robomach::machine
