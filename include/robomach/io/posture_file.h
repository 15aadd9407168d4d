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

/// An angle beyond this many degrees (~278 turns) is not a joint angle in
/// any unit (radians under a _rad header stay far below it): refused.
inline constexpr double kMaxJointAngleDeg = 1e5;
/// One turn in radians: every angle of a file within it under _deg headers
/// (with fractional non-zero values) looks like radians; an angle beyond it
/// under _rad headers looks like degrees (docs/plausibility.md).
inline constexpr double kOneTurnRad = 6.283185307179586;

/// Reads a posture file: `pose_id,q1_deg..qn_deg` (or `_rad`; each joint in
/// one unit, never both). `num_joints` must match the robot model: a missing
/// q column or one beyond n is an error naming both counts; 0 takes the
/// count from the file (its highest q column), with no column missing below. An angle beyond
/// kMaxJointAngleDeg is refused. When `unit_warnings` is given, it receives
/// "implausible (unit mistake?): ..." when the angles fit the other unit far
/// better (radians under _deg headers, degrees under _rad headers); a tool
/// prints them and flags its result (exit 3).
/// @throws InputError with file, line and column.
std::vector<Posture> ReadPostureFile(const std::string& path, int num_joints,
                                     std::vector<std::string>* unit_warnings = nullptr);

/// The unit check of ReadPostureFile on the angles as written (row-major,
/// `is_deg` per joint): the warnings, empty when the units look right.
std::vector<std::string> PostureUnitWarnings(const std::string& path, const std::vector<std::vector<double>>& written,
                                             const std::vector<bool>& is_deg);

/// Writes a posture file with degrees.
void WritePostureFile(const std::string& path, const std::vector<Posture>& postures);

}  // namespace robomach::io
