#pragma once

// The "where it fails" part of the model-audit report (issue #5 §2.2, §2.4):
// the trends of the error against posture descriptors, the error map of
// postures against modes and the modes without a counterpart, as JSON for
// summary.json, CSV tables, PNGs and HTML sections for index.html. Everything
// is built in memory; the app writes the files.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/audit/error_patterns.h"

namespace robomach::report {

/// File names the HTML refers to (relative, next to index.html).
struct AuditPatternFiles {
  std::string trends_png{"trends.png"};
  std::string mode_error_map_png{"mode_error_map.png"};
  std::string trends_csv{"trends.csv"};
  std::string mode_errors_csv{"mode_errors.csv"};
  std::string posture_descriptors_csv{"posture_descriptors.csv"};
  std::string unmatched_modes_csv{"unmatched_modes.csv"};
};

struct AuditPatternsReport {
  /// summary.json keys (README, model-audit outputs): `trends`,
  /// `mode_error_map`, `unmatched_model_modes`, `unmatched_measured_modes`.
  nlohmann::json trends;
  nlohmann::json mode_error_map;
  nlohmann::json unmatched_model_modes;
  nlohmann::json unmatched_measured_modes;
  /// Per-posture descriptors for summary.json's `postures[id].descriptors`
  /// (keys with units: q1_deg, reach_m, gravity_torque_j2_Nm, …).
  nlohmann::json posture_descriptors;
  std::string trends_csv;
  std::string mode_errors_csv;
  std::string posture_descriptors_csv;
  std::string unmatched_modes_csv;
  /// The error per posture against the descriptors with the strongest
  /// correlation (at most 4; significant ones first; those that do not vary
  /// over the postures never), before and, with an accepted candidate,
  /// after it, each panel on its own error scale with its least-squares line.
  std::vector<unsigned char> trends_png;
  std::vector<std::string> trends_png_descriptors;  // the descriptors drawn, top to bottom
  /// Empty if no mode was matched anywhere (nothing to map).
  std::vector<unsigned char> mode_error_map_png;
  /// index.html sections (<h2> …), self-contained but for the PNGs above.
  std::string html;
};

/// Joint angles are shown in degrees (the posture file's unit); the other
/// descriptors in their SI unit. `noise_floor` is drawn in the trend plots
/// as the level a correct model reaches.
AuditPatternsReport MakeAuditPatternsReport(const audit::ErrorPatterns& patterns, double noise_floor,
                                            const std::string& title, const AuditPatternFiles& files = {});

}  // namespace robomach::report
