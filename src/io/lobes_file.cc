#include "robomach/io/lobes_file.h"

#include <cmath>

#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

double LobeSpeedRpm(double speed_rad_s) { return std::round(RadPerSecToRpm(speed_rad_s) * 1e9) / 1e9; }

void WriteLobesCsv(std::ostream& os, const std::vector<stability::LobeRow>& rows, bool with_bounds) {
  os << "pose_id,spindle_speed_rpm,critical_depth_mm,chatter_freq_hz,lobe_index,method,status,sd_steps"
     << (with_bounds ? ",critical_depth_mm_lower,critical_depth_mm_upper" : "") << '\n';
  for (const stability::LobeRow& r : rows) {
    const stability::LobePoint& p = r.point;
    os << r.id << ',' << FormatDouble(LobeSpeedRpm(p.spindle_speed_rad_s)) << ','
       << (std::isfinite(p.critical_depth) ? FormatDouble(MToMm(p.critical_depth)) : "") << ','
       << (std::isfinite(p.chatter_freq_hz) ? FormatDouble(p.chatter_freq_hz) : "") << ','
       << (p.lobe_index >= 0 ? std::to_string(p.lobe_index) : "") << ',' << r.method << ','
       << stability::ToString(p.status) << ',' << (p.sd_steps > 0 ? std::to_string(p.sd_steps) : "");
    if (with_bounds) os << ',' << FormatCell(MToMm(r.depth_lower)) << ',' << FormatCell(MToMm(r.depth_upper));
    os << '\n';
  }
}

void WriteLobesCsv(const std::string& path, const std::vector<stability::LobeRow>& rows, bool with_bounds) {
  WriteFileAtomically(path, [&](std::ostream& os) { WriteLobesCsv(os, rows, with_bounds); });
}

nlohmann::json LobesSummaryJson(const std::vector<stability::TipDynamics>& tips, const stability::LobesResult& lobes,
                                const std::vector<stability::LobeSummary>& summaries) {
  nlohmann::json results = nlohmann::json::array();
  for (const stability::LobeSummary& l : summaries) {
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
  // Every number stability-lobes tells on stderr is here too (issue #34
  // item 6): the fit reports, the band the ZOA uses, the SD's
  // discretisation and the comparison of the two methods.
  nlohmann::json tip_list = nlohmann::json::array();
  for (const stability::TipDynamics& t : tips) {
    nlohmann::json tj;
    tj["pose_id"] = t.id;
    if (t.freq_hz.size() > 0) tj["zoa_band_hz"] = {t.freq_hz(0), t.freq_hz(t.freq_hz.size() - 1)};
    if (!t.fits.empty()) {
      nlohmann::json fits = nlohmann::json::array();
      for (const stability::DirectionFit& d : t.fits) {
        nlohmann::json fj;
        fj["frf"] = d.label;
        if (!d.same_as.empty()) fj["same_as"] = d.same_as;
        fj["noise"] = d.fit.noise.description;
        if (!d.fit.noise.usable_bands.empty()) {
          fj["usable_band_hz"] = {d.fit.noise.usable_bands.front().first, d.fit.noise.usable_bands.back().second};
        }
        fj["usable_lines"] = d.fit.noise.usable_lines;
        nlohmann::json modes = nlohmann::json::array();
        for (const calibration::FittedMode& m : d.fit.fit.modes) {
          nlohmann::json mj;
          mj["freq_hz"] = m.freq_hz;
          mj["damping_ratio"] = m.damping_ratio;
          // 1 / Re A: the modal mass of a driving-point mode; none for Re A <= 0 (left out of the SD).
          if (m.modal_constant.real() > 0.0) mj["modal_mass_kg"] = 1.0 / m.modal_constant.real();
          modes.push_back(mj);
        }
        fj["modes"] = modes;
        if (std::isfinite(d.fit.noise_rms)) fj["rms_misfit_noise_units"] = d.fit.noise_rms;
        fj["poor"] = d.fit.poor;
        fits.push_back(fj);
      }
      tj["fits"] = fits;
    }
    for (const stability::SdDiscretisation& s : lobes.sd_discretisation) {
      if (s.id != t.id) continue;
      tj["sd_modes"] = s.modes;
      tj["sd_highest_mode_hz"] = s.highest_mode_hz;
      tj["sd_steps_per_tooth_period_min"] = s.min_steps_per_period;
      tj["sd_steps_per_tooth_period_max"] = s.max_steps_per_period;
      tj["sd_steps_capped"] = s.capped;
    }
    for (const stability::ZoaSdComparison& c : lobes.comparisons) {
      if (c.id != t.id) continue;
      nlohmann::json cj;
      cj["sd_min_critical_depth_mm"] = MToMm(c.sd_min_depth);
      cj["sd_min_critical_depth_speed_rpm"] = LobeSpeedRpm(c.sd_min_depth_speed_rad_s);
      cj["zoa_min_critical_depth_mm"] = MToMm(c.zoa_min_depth);
      cj["zoa_min_critical_depth_speed_rpm"] = LobeSpeedRpm(c.zoa_min_depth_speed_rad_s);
      cj["difference_percent"] = 100.0 * c.relative_difference;
      cj["agree"] = c.agree;
      tj["zoa_sd_comparison"] = cj;
    }
    for (const stability::ZoaFitCheck& c : lobes.zoa_fit_checks) {
      if (c.id != t.id) continue;
      nlohmann::json cj;
      cj["measured_min_critical_depth_mm"] = MToMm(c.measured_min_depth);
      cj["fit_min_critical_depth_mm"] = MToMm(c.fit_min_depth);
      cj["difference_percent"] = 100.0 * c.relative_difference;
      cj["agree"] = c.agree;
      tj["zoa_measured_vs_fit"] = cj;
    }
    tip_list.push_back(tj);
  }
  nlohmann::json j;
  j["lobes"] = results;
  j["tips"] = tip_list;
  j["no_boundary_at_some_speeds"] = lobes.no_boundary;
  j["flagged"] = lobes.verdict.flagged();
  return j;
}

}  // namespace robomach::io
