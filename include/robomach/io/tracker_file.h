#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "robomach/identification/load_case.h"

namespace robomach::io {

/// A tracker file read into measurements (SI units, radians).
// Plausible ranges of a load test (docs/plausibility.md): laser trackers
// measure to 0.005 - 0.05 mm (1 sigma; Leica AT960 and API Radian data
// sheets); load tests hang 5 - 300 kg (up to the payload; the seed's
// KR 210: 10 - 30 kg); an industrial robot's target is 0.05 - 20 m from
// its base; a load that deflects a robot measurably is 5 N - 20 kN.
inline constexpr double kMinPlausibleTrackerNoiseMm = 1e-4, kMaxPlausibleTrackerNoiseMm = 1.0;
inline constexpr double kMinPlausibleLoadMassKg = 0.5, kMaxPlausibleLoadMassKg = 500.0;
inline constexpr double kMinPlausibleTargetDistanceMm = 50.0, kMaxPlausibleTargetDistanceMm = 20000.0;
inline constexpr double kMinPlausibleLoadN = 5.0, kMaxPlausibleLoadN = 20000.0;

struct TrackerFile {
  std::string path;
  std::vector<identification::TrackerMeasurement> measurements;
  bool rope_form{false};                           // mass_kg + rope points (else fx_N..fz_N)
  std::map<std::string, std::string> metadata;     // `# key: value` before the header
  std::vector<std::string> unknown_columns;        // ignored, for --verbose
  /// "implausible (unit mistake?): ..." when the file's numbers fit another
  /// unit far better than the one its headers name: radians under _deg
  /// (PostureUnitWarnings), positions in m or um under _mm (the median
  /// distance of the unloaded target from the base outside
  /// kMin/MaxPlausibleTargetDistanceMm), masses in g or t under mass_kg,
  /// forces in kN under _N. A tool prints them and flags its result.
  std::vector<std::string> unit_warnings;
};

/// "implausible (unit mistake?): --noise-mm ..." when a tracker noise
/// [mm] is outside kMin/MaxPlausibleTrackerNoiseMm (0 is allowed: no
/// noise); empty when plausible. `option` names where it came from.
std::string TrackerNoiseUnitFinding(const std::string& option, double noise_mm);

/// Reads a laser-tracker load-test file (formats.md §2): `case_id, pose_id,
/// q1_deg..qn_deg` (or `_rad`), `x0_mm..z1_mm`, and the load as either
/// `fx_N,fy_N,fz_N` or `mass_kg` with rope points `ax_mm..bz_mm` (exactly one
/// form per file); optional `lx_mm,ly_mm,lz_mm` (load point) and
/// `tx_mm,ty_mm,tz_mm` (target) in the tip frame, all three or none, a row
/// with all three empty meaning the TCP. Columns are matched by name.
/// @throws InputError naming file, line and column for: a missing column, a
///   file mixing the two load forms, joint columns not matching
///   `num_joints`, a non-numeric cell, a duplicate case_id, a mass <= 0, a
///   zero rope vector, a file without cases.
TrackerFile ReadTrackerFile(const std::string& path, int num_joints);

/// Writes measurements in the format of ReadTrackerFile, atomically. All
/// measurements must use the same load form; the tip-frame columns are
/// written if any measurement has them. `metadata` becomes `# key: value`
/// lines before the header.
/// @throws std::invalid_argument for mixed load forms; OutputError on failure.
void WriteTrackerFile(const std::string& path,
                      const std::vector<identification::TrackerMeasurement>& measurements,
                      const std::vector<std::pair<std::string, std::string>>& metadata = {});
void WriteTrackerFile(std::ostream& os,
                      const std::vector<identification::TrackerMeasurement>& measurements,
                      const std::vector<std::pair<std::string, std::string>>& metadata = {});

}  // namespace robomach::io
