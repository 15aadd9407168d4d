#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "robomach/identification/load_case.h"

namespace robomach::io {

/// A tracker file read into measurements (SI units, radians).
struct TrackerFile {
  std::string path;
  std::vector<identification::TrackerMeasurement> measurements;
  bool rope_form{false};                           // mass_kg + rope points (else fx_N..fz_N)
  std::map<std::string, std::string> metadata;     // `# key: value` before the header
  std::vector<std::string> unknown_columns;        // ignored, for --verbose
};

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
