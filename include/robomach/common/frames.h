#pragma once

// Frames and naming (style.md §2.4), declared once for the whole library.
//
//   B  robot base frame (= laser-tracker frame in the load tests)
//   F  flange frame
//   T  tool tip (tool centre point, TCP)
//
//   p_BT   position of T from B's origin, expressed in B                 [m]
//   X_BF   pose of F in B;  R_BF its rotation
//   J_BT   6×n geometric Jacobian of T in B. Rows are [v; ω]: linear
//          velocity of T first, then angular velocity (KDL's order).
//   M_X, K_X, C_X  6×6 Cartesian inertia/stiffness/damping at T, in B, [v; ω]
//   H_T    3×3 translational receptance at T, expressed in B, per line [m/N]
//   Jacobians of results w.r.t. parameters: J_<out>_<in>.
//
// Every 6-vector of the library (twists, wrenches, Jacobian rows) is ordered
// [linear; angular].

#include <cctype>
#include <string>
#include <vector>

#include "robomach/common/named_registry.h"

namespace robomach {

enum class Axis { kX = 0, kY = 1, kZ = 2 };

inline char AxisName(Axis a) { return "xyz"[static_cast<int>(a)]; }

/// The one printer and parser of a direction's name (issue #36 "one
/// vocabulary"): "x", "y", "z", as every file, option and Python names it.
inline std::string ToString(Axis a) { return std::string(1, AxisName(a)); }

/// "x", "y" or "z"; a capital too ("X", as UFF58 and users write it).
/// @throws std::invalid_argument "direction 'w': expected x, y or z".
inline Axis ParseAxis(const std::string& name) {
  static constexpr Axis kAll[] = {Axis::kX, Axis::kY, Axis::kZ};
  std::string key = name;
  if (key.size() == 1) key[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(key[0])));
  std::vector<std::string> names;
  for (Axis a : kAll) {
    if (key == ToString(a)) return a;
    names.push_back(ToString(a));
  }
  ThrowUnknownName("direction", name, NameListOf(names));
}

}  // namespace robomach
