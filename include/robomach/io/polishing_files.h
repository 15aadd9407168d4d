#pragma once

// Readers and writers of the polishing files (formats.md §5-7): the NURBS
// patch YAML, the process YAML, tool-path CSV and removal-map CSV. Lengths
// are converted from mm to m here, once.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "robomach/kinematics/pose_path.h"
#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::io {

/// formats.md §5 NURBS patch. @throws InputError "file:line:col: ..." for a
/// knot vector that does not match the control points, a weight <= 0, ...
polishing::NurbsSurface ReadNurbsYaml(const std::string& path);

// Plausible ranges of a process file's values (docs/plausibility.md), about
// 10 to 100 times wider than practice. Sources: 3M and VSM belt-grinding
// guides (contact wheels of 25 to 250 mm radius, belts 10 to 300 mm wide,
// belt speeds 5 to 35 m/s); robotic belt polishing forces 5 to 100 N (Zhang
// et al., Robot. CIM 2020; the shipped example 2 N); pad rubber moduli 1 to
// 100 MPa; Young's moduli of metals 45 to 400 GPa, of polymers 1 to 3 GPa;
// Preston coefficients 1e-14 to 1e-10 m²/N (Preston 1927; Tam and Cheng,
// J. Mater. Process. Technol. 2007); robot polishing feeds 5 to 200 mm/s.
inline constexpr double kMinPlausibleWheelRadiusMm = 1.0, kMaxPlausibleWheelRadiusMm = 2000.0;
inline constexpr double kMinPlausibleCrownRadiusMm = 1.0, kMaxPlausibleCrownRadiusMm = 1e5;
inline constexpr double kMinPlausibleBeltWidthMm = 1.0, kMaxPlausibleBeltWidthMm = 2000.0;
inline constexpr double kMinPlausiblePadModulusMPa = 0.1, kMaxPlausiblePadModulusMPa = 5000.0;
inline constexpr double kMinPlausibleBeltSpeedMPerS = 0.1, kMaxPlausibleBeltSpeedMPerS = 100.0;
inline constexpr double kMinPlausibleWorkModulusGPa = 0.1, kMaxPlausibleWorkModulusGPa = 1000.0;
inline constexpr double kMinPlausiblePrestonM2PerN = 1e-16, kMaxPlausiblePrestonM2PerN = 1e-8;
inline constexpr double kMinPlausiblePolishForceN = 0.01, kMaxPlausiblePolishForceN = 5000.0;
inline constexpr double kMinPlausiblePolishSpeedMmPerS = 0.1, kMaxPlausiblePolishSpeedMmPerS = 2000.0;

/// formats.md §7 process file. Unknown keys are rejected. When `implausible`
/// is given, it receives "implausible (unit mistake?): file:line:col: ..."
/// for each value outside its plausible range above (the tools flag their
/// result, exit 3).
polishing::PolishingProcess ReadPolishingProcess(const std::string& path,
                                                 std::vector<std::string>* implausible = nullptr);

/// A tool path CSV as read (formats.md §6), SI.
struct PolishPathFile {
  std::string path;
  std::map<std::string, std::string> metadata;
  std::vector<polishing::PathRow> rows;
  std::vector<int> lines;  // file line of each row
  bool has_uv{false};
};
/// @throws InputError naming file, line and column: missing columns,
///   non-numbers, t_s not strictly increasing, non-unit or non-orthogonal
///   tool axes, a non-positive force.
PolishPathFile ReadPolishPath(const std::string& path);

/// Writes a path: `# key: value` metadata lines, then
/// t_s,x_mm,y_mm,z_mm,nx,ny,nz,tx,ty,tz,u,v. Atomic.
void WritePolishPath(const std::string& path, const std::vector<polishing::PathRow>& rows,
                     const std::vector<std::pair<std::string, std::string>>& metadata);

/// The `# key: value` lines polish-plan writes at the top of a planned path
/// (formats.md §6): pattern, offset_mm, edge_overrun_mm (`edge_overrun_m`,
/// the one the plan used: workflows::PlannedPathMetadata computes it); for
/// the cycloid guides, radius_mm, pitch_mm, stagger_loops; line_angle_deg
/// where guide lines are parallel.
std::vector<std::pair<std::string, std::string>> PlannedPathMetadata(const polishing::PathParameters& params,
                                                                     double edge_overrun_m);

/// Removal map CSV x_mm,y_mm,z_mm,u,v,removal_um of the region's points. Atomic.
void WriteRemovalMap(const std::string& path, const polishing::SampleGrid& grid, const std::vector<double>& removal_m);

/// Joint trajectory CSV: t_s,q1_deg..qn_deg,reachable,limit_margin_deg,jacobian_condition
/// (empty cells where a row is unreachable). Atomic.
void WriteJointTrajectoryCsv(const std::string& path, const std::vector<polishing::PathRow>& rows,
                             const kinematics::PosePathCheck& check, int num_joints);

}  // namespace robomach::io
