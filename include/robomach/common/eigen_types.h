#pragma once

#include <Eigen/Core>

namespace robomach {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;  // Jacobians
using Matrix3Xd = Eigen::Matrix<double, 3, Eigen::Dynamic>;
// Eigen::Vector3d, Matrix3d, Matrix3cd, VectorXcd are used as they are.

/// The cross-product matrix: Skew(a) * b == a.cross(b).
inline Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

}  // namespace robomach
