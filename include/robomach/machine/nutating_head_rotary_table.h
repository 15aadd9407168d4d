#pragma once
// 45° nutating B head + C rotary table (DMU 80P type), formats.md §8.3 and
// seed 002 eqs. (6)-(12). Chain: workpiece - C - Y - X - Z - B - tool.

#include <array>

#include "robomach/machine/kinematics.h"

namespace robomach::machine {

/// Geometry and rotary errors, SI. The errors all default to 0.
struct NutatingHeadGeometry {
  double nutation{0.7853981633974483};          // n: B axis (0, sin n, cos n) [rad]
  double pivot_length{0.3};                      // L: B pivot to spindle nose [m]
  double tool_length{0.12};                      // t1: spindle nose to tool tip [m]
  std::array<double, 2> c_centre{0.0, 0.0};     // (XC0, YC0) [m]
  std::array<double, 3> zero_offset{0.0, 0.0, 0.0};  // (X0, Y0, Z0) [m]
  std::array<double, 2> b_eccentricity{0.0, 0.0};    // (PBX, PBY) [m]
  double pivot_length_error{0.0};                    // dL [m]
  std::array<double, 2> c_eccentricity{0.0, 0.0};    // (PCX, PCY) [m]
};

/// @throws std::invalid_argument naming the field (lengths finite, nutation in (0, 90°]).
void CheckValid(const NutatingHeadGeometry& g);

/// Axes X, Y, Z [m], B, C [rad]. Exactly formats.md §8.3:
///   p_m = (X, Y, Z) + (PBX, PBY, 0) + (0, 0, L + t1) + R(u_B, B) (0, 0, -(L + dL + t1))
///   k_m = R(u_B, B) (0, 0, 1),  u_B = (0, sin n, cos n)
///   w   = Rz(-C) (p_m - c) + c - o,  c = (XC0 + PCX, YC0 + PCY, 0),  o = (X0, Y0, Z0)
class NutatingHeadRotaryTable final : public MachineKinematics {
 public:
  explicit NutatingHeadRotaryTable(const NutatingHeadGeometry& geometry);
  const NutatingHeadGeometry& geometry() const { return g_; }

  std::vector<std::string> axis_names() const override { return {"X", "Y", "Z", "B", "C"}; }
  std::vector<bool> rotary() const override { return {false, false, false, true, true}; }
  ToolPose Forward(const Eigen::VectorXd& q) const override;
  /// Both B solutions (B and -B: cos B is fixed by the tool axis's z
  /// component), each with its C; at B = 0 (tool axis along Z) C is free and
  /// q_previous's C is kept.
  std::vector<Eigen::VectorXd> InverseSolutions(const ToolPose& pose,
                                                const Eigen::VectorXd& q_previous) const override;
  std::unique_ptr<MachineKinematics> WithoutErrors() const override;

 private:
  NutatingHeadGeometry g_;
  Eigen::Vector3d u_B_;
};

}  // namespace robomach::machine
