#include "robomach/io/lobes_file.h"

#include <cmath>

#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

double LobeSpeedRpm(double speed_rad_s) { return std::round(RadPerSecToRpm(speed_rad_s) * 1e9) / 1e9; }

void WriteLobesCsv(std::ostream& os, const std::vector<stability::LobeRow>& rows) {
  os << "pose_id,spindle_speed_rpm,critical_depth_mm,chatter_freq_hz,lobe_index,method,status,sd_steps\n";
  for (const stability::LobeRow& r : rows) {
    const stability::LobePoint& p = r.point;
    os << r.id << ',' << FormatDouble(LobeSpeedRpm(p.spindle_speed_rad_s)) << ','
       << (std::isfinite(p.critical_depth) ? FormatDouble(MToMm(p.critical_depth)) : "") << ','
       << (std::isfinite(p.chatter_freq_hz) ? FormatDouble(p.chatter_freq_hz) : "") << ','
       << (p.lobe_index >= 0 ? std::to_string(p.lobe_index) : "") << ',' << r.method << ','
       << stability::ToString(p.status) << ',' << (p.sd_steps > 0 ? std::to_string(p.sd_steps) : "") << '\n';
  }
}

void WriteLobesCsv(const std::string& path, const std::vector<stability::LobeRow>& rows) {
  WriteFileAtomically(path, [&](std::ostream& os) { WriteLobesCsv(os, rows); });
}

nlohmann::json LobesSummaryJson(const std::vector<stability::TipDynamics>& tips, const stability::LobesResult& lobes) {
  nlohmann::json results = nlohmann::json::array();
  for (const stability::LobeSummary& l : stability::SummarizeLobes(tips, lobes.rows)) {
    nlohmann::json r;
    r["pose_id"] = l.id;
    r["method"] = l.method;
    r["speeds"] = l.speeds;
    r["speeds_with_boundary"] = l.speeds_with_boundary;
    if (l.speeds_with_boundary > 0) {
      r["min_critical_depth_mm"] = MToMm(l.min_depth);
      r["min_critical_depth_speed_rpm"] = LobeSpeedRpm(l.min_depth_speed_rad_s);
      if (std::isfinite(l.min_depth_chatter_freq_hz)) r["min_critical_depth_chatter_freq_hz"] = l.min_depth_chatter_freq_hz;
      r["max_critical_depth_mm"] = MToMm(l.max_depth);
      r["max_critical_depth_speed_rpm"] = LobeSpeedRpm(l.max_depth_speed_rad_s);
    }
    results.push_back(r);
  }
  nlohmann::json j;
  j["lobes"] = results;
  j["no_boundary_at_some_speeds"] = lobes.no_boundary;
  j["flagged"] = lobes.flagged();
  return j;
}

}  // namespace robomach::io
