#pragma once

// The belt-grinding process of formats.md §7 (seed 004 set-up by default:
// belt 20 mm, 2 N, 3 m/s, rubber pad on a contact wheel, steel work).

#include <stdexcept>
#include <string>

#include <Eigen/Core>

namespace robomach::polishing {

struct PolishingProcess {
  // tool
  double wheel_radius{0.050};       // contact wheel radius, curvature along tool x [m]
  double crown_radius{0.200};       // radius across the belt, along tool y [m]
  double belt_width{0.020};         // [m]
  double pad_modulus{10e6};         // elastic layer of the wheel [Pa]
  double pad_poisson{0.47};
  double belt_speed{3.0};           // [m/s], along +tool x at the contact
  // workpiece
  double work_modulus{200e9};       // [Pa]
  double work_poisson{0.3};
  double preston_coefficient{1e-13};  // Kp in dh = Kp p v dt [1/Pa = m^2/N]
  // process
  double force{2.0};                // normal force [N]
  double margin{0.005};             // polished region: this far from the boundary [m]
  double max_speed{0.050};          // traverse speed limit of the contact [m/s]
  bool flip_normal{false};
  /// Contact frame C (tool frame at the contact point: z = surface normal
  /// towards the tool, x = belt direction) in the robot flange F: p_FC [m],
  /// R_FC. Only used with --robot. Default: the contact 250 mm along the
  /// flange z axis, C's z pointing back at the flange (180 deg about x).
  Eigen::Vector3d p_FC{0.0, 0.0, 0.25};
  Eigen::Matrix3d R_FC{Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal()};
};

/// @throws std::invalid_argument naming the field, its value and the bound.
void CheckValid(const PolishingProcess& process);

/// 1/E* = (1 - nu_pad^2)/E_pad + (1 - nu_work^2)/E_work [Pa].
double EffectiveModulus(const PolishingProcess& process);

/// Bad data at one row of a tool path (0-based `row`); apps turn it into
/// "file:line: ..." with the row's line number.
class PathRowError : public std::runtime_error {
 public:
  PathRowError(int row, const std::string& message) : std::runtime_error(message), row_(row) {}
  int row() const { return row_; }

 private:
  int row_;
};

}  // namespace robomach::polishing
