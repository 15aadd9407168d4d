#pragma once

#include <optional>
#include <string>
#include <vector>

#include "robomach/common/errors.h"
#include "robomach/drilling/drill_forces.h"
#include "robomach/drilling/drilling_process.h"
#include "robomach/drilling/flexible_joint_robot.h"
#include "robomach/drilling/force_fit.h"

namespace robomach::io {

/// A thrust/torque table (formats.md §9.1) in SI units.
struct ForceTableFile {
  std::string path;
  std::string source;                       // `# source:` metadata, if any
  std::vector<drilling::ForceTableRow> rows;
  std::vector<std::optional<double>> speed_rpm;  // per row, when the column is given
  std::vector<int> lines;                   // 1-based file line of each row
  std::vector<std::string> unknown_columns; // ignored (formats.md: listed with --verbose)
};

/// Reads a force table. With `require_forces` false (for --predict rows)
/// only diameter_mm and feed_mm_per_rev are required.
/// @throws InputError "file:line: column thrust_N: expected a positive
///   number, got 0" for a non-positive or non-numeric value, a missing
///   column or an empty table.
ForceTableFile ReadForceTable(const std::string& path, bool require_forces = true);

/// A drill file (formats.md §9.2): `drill:` always; `process:`, `offset:`
/// and `simulation:` when present (drill-sim requires `process:`).
struct DrillFile {
  std::string path;
  drilling::DrillGeometry drill;
  bool has_process{false};
  drilling::DrillingProcess process;       // defaults where absent
  SourceLocation hole_axis_at;             // for errors found later (feeding)
  SourceLocation initial_posture_at;
  /// "implausible (unit mistake?): file:line:col: ..." (docs/plausibility.md):
  /// drill and posture angles that all look like radians under _deg keys.
  std::vector<std::string> implausible;
};
/// @throws InputError with file:line:col for any problem (unknown keys too).
DrillFile ReadDrillFile(const std::string& path);

/// The material file drill-force-fit writes: the fitted coefficients with
/// units in their names, their standard deviations, the fit quality, the
/// drill geometry and the table (with the model at each row).
std::string MaterialYaml(const drilling::ForceFitResult& fit, const drilling::DrillGeometry& drill,
                         const ForceTableFile& table);

/// Reads the `material:` section of a material file (the rest is a record).
drilling::DrillingMaterial ReadMaterialFile(const std::string& path);

/// A flexible-joint robot (formats.md §9.3): a robot config's `robot:`
/// section (URDF or modified DH) and `flexible_joints:`, one entry per joint
/// in any order. `joint_stiffness_Nm_per_rad`, if given, must equal the
/// stiffnesses; `damping`, `end_effector`, `spindle_toolholder_interface`,
/// `hammer_test`, `effects` and `parameters` are accepted and not used (they
/// are listed in `unused_sections`).
struct FlexibleRobotFile {
  std::string path;
  kinematics::SerialChain chain;
  std::vector<drilling::JointDrive> drives;   // in chain order
  std::vector<std::string> unused_sections;
  /// "implausible (unit mistake?): file:line:col: ..." (docs/plausibility.md):
  /// the `dh:` table's masses, lengths and angles (robot_config.h's ranges),
  /// joint stiffnesses, gear ratios and rotor inertias outside their ranges.
  std::vector<std::string> implausible;
};
/// @throws InputError with file:line:col: a joint without an entry, an
///   unknown or repeated joint name, a stiffness, gear ratio or rotor inertia
///   not > 0, a negative damping, unknown keys.
FlexibleRobotFile ReadFlexibleRobotFile(const std::string& path);

// Plausible ranges of a flexible joint's drive (docs/plausibility.md).
// Sources: harmonic-drive and cycloidal robot gearboxes have ratios of 30 to
// 300 (Harmonic Drive AG, CSG catalogue; Nabtesco RV catalogue); servo
// motor rotor inertias are 1e-6 kg·m² (100 W) to 1e-2 kg·m² (15 kW)
// (Siemens 1FK7, Yaskawa Sigma-7 data sheets).
inline constexpr double kMinPlausibleGearRatio = 1.0;
inline constexpr double kMaxPlausibleGearRatio = 3000.0;
inline constexpr double kMinPlausibleRotorInertiaKgM2 = 1e-8;
inline constexpr double kMaxPlausibleRotorInertiaKgM2 = 1.0;

}  // namespace robomach::io
