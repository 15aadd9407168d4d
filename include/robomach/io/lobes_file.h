#pragma once
// The lobes CSV of stability-lobes (docs/stability.md) and its summary JSON's
// result part.

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/stability/lobes_workflow.h"

namespace robomach::io {

/// `pose_id,spindle_speed_rpm,critical_depth_mm,chatter_freq_hz,lobe_index,method,status,sd_steps`,
/// one row per point, empty cells where a point has no value; with
/// `with_bounds` (parameter uncertainty) also `critical_depth_mm_lower,
/// critical_depth_mm_upper` (LobeRow::depth_lower/upper; the lower one is
/// the safe depth). Speeds are
/// rounded to 1e-9 rpm: they went rpm -> rad/s -> rpm, and this hides the
/// last-bit residue (6000.000000000001). The path version is atomic; "-"
/// is stdout.
void WriteLobesCsv(std::ostream& os, const std::vector<stability::LobeRow>& rows, bool with_bounds = false);
void WriteLobesCsv(const std::string& path, const std::vector<stability::LobeRow>& rows, bool with_bounds = false);

/// A speed [rad/s] in rpm as the lobes CSV writes it (rounded to 1e-9 rpm).
double LobeSpeedRpm(double speed_rad_s);

/// The summary's result part (docs/formats.md §4.1): `lobes`, per tip and
/// method (`summaries`: stability::SummarizeLobes of the rows) the speeds, those with a boundary and, when
/// any, the smallest and largest critical depth [mm] with their speed
/// [rpm] (and the chatter frequency at the smallest); then
/// `no_boundary_at_some_speeds` and `flagged`.
nlohmann::json LobesSummaryJson(const std::vector<stability::TipDynamics>& tips, const stability::LobesResult& lobes,
                                const std::vector<stability::LobeSummary>& summaries);

}  // namespace robomach::io
