#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace robomach::io {

/// One row of a posture file (formats.md §1).
struct Posture {
  std::string id;
  Eigen::VectorXd q;  // [rad]
  int line{0};        // line in the file, for messages
};

/// Reads a posture file: `pose_id,q1_deg..qn_deg` (or `_rad`; each joint in
/// one unit, never both). `num_joints` must match the robot model: a missing
/// q column or one beyond n is an error naming both counts.
/// @throws InputError with file, line and column.
std::vector<Posture> ReadPostureFile(const std::string& path, int num_joints);

/// Writes a posture file with degrees.
void WritePostureFile(const std::string& path, const std::vector<Posture>& postures);

}  // namespace robomach::io
