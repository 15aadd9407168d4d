#include "robomach/workflows/stability_lobes.h"

#include <cmath>
#include <optional>
#include <sstream>
#include <string>

#include "robomach/calibration/frf_noise.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/lobes_file.h"
#include "robomach/io/number_format.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/workflows/frf_predict.h"
#include "robomach/workflows/tip_sources.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::workflows {
namespace {

template <typename T>
void CheckRange(const char* field, T value, T lo, T hi) {
  if (!(value >= lo && value <= hi)) {
    throw OptionError(field, std::string(field) + " " + FormatNumber(static_cast<double>(value), 6) +
                                 " is outside [" + FormatNumber(static_cast<double>(lo), 6) + ", " +
                                 FormatNumber(static_cast<double>(hi), 6) + "]");
  }
}

std::string AxisSource(const StabilityLobesOptions& o) {
  if (!o.tool_axis_source.empty()) return o.tool_axis_source;
  return "tool_axis " + FormatNumber(o.tool_axis(0), 6) + "," + FormatNumber(o.tool_axis(1), 6) + "," +
         FormatNumber(o.tool_axis(2), 6);
}

}  // namespace

void StabilityLobesOptions::Validate() const {
  const int sources = !robot_path.empty() + !frf_path.empty() + !modal_table_path.empty();
  if (sources != 1) {
    throw OptionError("robot_path",
                      "give exactly one tool-tip source: robot_path (with postures_path), frf_path or modal_table_path");
  }
  if (!robot_path.empty() && postures_path.empty()) throw OptionError("postures_path", "robot_path needs postures_path");
  if (!frf_y_path.empty() && frf_path.empty()) throw OptionError("frf_y_path", "frf_y_path needs frf_path");
  if (!uncertainty_paths.empty()) {
    if (robot_path.empty()) {
      throw OptionError("uncertainty_paths",
                        "uncertainty_paths needs robot_path: the parameter uncertainty is of a robot model's "
                        "parameters (a measured FRF's uncertainty is its noise)");
    }
    if (method == stability::LobeMethod::kSd) {
      throw OptionError("uncertainty_paths", "uncertainty_paths bands the ZOA lobes: use method zoa or both "
                                             "(the SD's band would take hundreds of SD runs)");
    }
    uncertainty.Validate();  // OptionError naming its field (confidence ...), as the tool's own options
  }
  if (!(tool_axis.allFinite() && tool_axis.norm() > 0.0)) {
    throw OptionError("tool_axis", AxisSource(*this) + ": expected a non-zero vector x,y,z");
  }
  ValidateSettings();
}

void StabilityLobesOptions::ValidateSettings() const {
  CheckRange("speeds", speeds, 0, 100000);
  CheckRange("max_lobe", max_lobe, 0, 1000);
  CheckRange("sd_speeds", sd_speeds, 1, 10000);
  if (sd_steps != 0) CheckRange("sd_steps", sd_steps, 2, 1000);
  CheckRange("sd_steps_per_mode_period", sd_steps_per_mode_period, 4.0, 1000.0);
  CheckRange("sd_modes", sd_modes, 1, 200);
  CheckRange("sd_max_depth_mm", sd_max_depth_mm, 1e-6, 1e4);
  CheckRange("threads", threads, 0, 256);
}

std::string StabilityLobesOptions::Source() const {
  return !robot_path.empty() ? "robot" : !frf_path.empty() ? "frf" : "modal_table";
}

stability::LobesOptions MakeLobesOptions(const io::CutSpec& cut, const StabilityLobesOptions& o) {
  stability::LobesOptions lo;
  lo.method = o.method;
  lo.process = cut.process;
  lo.min_speed_rad_s = cut.spindle_speed_min_rad_s;
  lo.max_speed_rad_s = cut.spindle_speed_max_rad_s;
  lo.zoa_speeds_rad_s = cut.SpeedRange(o.speeds);
  lo.sd_speeds_rad_s = cut.SpeedRange(o.sd_speeds);
  lo.max_lobe_index = o.max_lobe;
  lo.sd.steps_per_period = o.sd_steps;
  lo.sd.steps_per_mode_period = o.sd_steps_per_mode_period;
  lo.sd.max_depth = MmToM(o.sd_max_depth_mm);
  lo.sd_modes = o.sd_modes;
  lo.threads = o.threads;
  return lo;
}

std::optional<Eigen::Vector3d> ParseToolAxis(const std::string& text) {
  std::stringstream ss(text);
  std::string item;
  std::vector<double> v;
  while (std::getline(ss, item, ',')) {
    double x = 0.0;
    if (!io::ParseFiniteNumber(item, &x)) break;
    v.push_back(x);
  }
  if (v.size() != 3 || Eigen::Vector3d(v[0], v[1], v[2]).norm() == 0.0) return std::nullopt;
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

std::string FitPanelTitle(const stability::DirectionFit& d) {
  std::ostringstream title;
  title << d.label << ": " << d.fit.fit.modes.size() << " modes";
  if (std::isfinite(d.fit.noise_rms)) {
    title << ", rms misfit " << io::FormatDouble(std::round(d.fit.noise_rms * 100.0) / 100.0) << " x noise";
  }
  title << "; " << calibration::DescribeUsable(d.fit.noise);
  return title.str();
}

StabilityLobesRun RunStabilityLobes(const StabilityLobesOptions& o, const MessageSink& tell,
                                    const stability::SdProgressSink& progress) {
  o.Validate();
  StabilityLobesRun run;
  run.cut = io::ReadCutFile(o.cut_path);
  for (const std::string& w : run.cut.implausible) {
    Tell(tell, Message::Kind::kWarning, w);
    run.input_findings.push_back(w);
  }
  const std::string axis_source = AxisSource(o);
  if (!o.robot_path.empty()) {
    io::RobotConfig cfg = workflows::LoadRobotConfigChecked(o.robot_path);
    for (const std::string& w : cfg.implausible) {
      Tell(tell, Message::Kind::kWarning, w);
      run.input_findings.push_back(w);
    }
    // The config's `uncertainty:` files when none were given (the ZOA only).
    run.uncertainty_files = !o.uncertainty_paths.empty() || o.method == stability::LobeMethod::kSd
                                ? o.uncertainty_paths
                                : cfg.uncertainty_files;
    const std::optional<dynamics::ParameterUncertainty> u =
        UseUncertaintyFiles(run.uncertainty_files, {}, &cfg, tell);
    std::vector<io::Posture> postures;
    run.tips = TipsFromRobotPostures(cfg.Build(), o.postures_path, o.pose_ids, run.cut, tell, &postures);
    if (u) {
      const stability::LobesOptions lo = MakeLobesOptions(run.cut, o);
      for (const io::Posture& p : postures) {
        run.bands.push_back(stability::ZoaLobeBand(cfg.description, cfg.parameters, p.id, p.q,
                                                   run.cut.feed_direction_B, lo, *u, o.uncertainty));
      }
    }
  } else if (!o.frf_path.empty()) {
    stability::MeasuredTipOptions mo;
    mo.frf_path = o.frf_path;
    mo.frf_y_path = o.frf_y_path;
    mo.pose_ids = o.pose_ids;
    // The cutting frame only when the FRFs need orienting.
    const io::CutSpec& cut = run.cut;
    mo.cutting_frame = [&cut, &o, axis_source] { return CutFrame(cut, o.tool_axis, axis_source); };
    mo.tool_axis_source = axis_source;
    mo.fit = true;  // always: the noise model's usable band serves the ZOA too
    mo.sd_modes = o.sd_modes;
    run.tips = TipsFromFrfFiles(mo, tell);
  } else {
    const Eigen::Matrix3d R = CutFrame(run.cut, o.tool_axis, axis_source);
    run.tips = TipsFromModalTableFile(o.modal_table_path, o.pose_ids, R, run.cut);
  }
  run.lobes = stability::ComputeLobes(run.tips, MakeLobesOptions(run.cut, o), tell, progress);
  for (const stability::ZoaBand& b : run.bands) {
    size_t at = 0;
    for (stability::LobeRow& r : run.lobes.rows) {
      if (r.id != b.id || r.method != "zoa" || at >= b.depth.size()) continue;
      r.depth_lower = b.depth[at].lower;
      r.depth_upper = b.depth[at].upper;
      ++at;
    }
    Tell(tell, Message::Kind::kNote,
        b.id + ": smallest critical depth (ZOA) " + FormatNumber(1e3 * b.min_depth.value, 4) + " mm, " +
            FormatNumber(100.0 * o.uncertainty.confidence, 3) + " % interval [" +
            FormatNumber(1e3 * b.min_depth.lower, 4) + ", " + FormatNumber(1e3 * b.min_depth.upper, 4) +
            "] mm: the safe depth at every speed is " + FormatNumber(1e3 * b.min_depth.lower, 4) + " mm (" +
            b.propagation.reason + ")");
    // A lower bound at or below zero is not a depth: the linear interval
    // does not hold (forced first order where the lobes bend; issue #37).
    double lowest = b.min_depth.lower, at_rpm = NAN;
    for (size_t i = 0; i < b.depth.size(); ++i) {
      if (b.depth[i].lower < lowest) {
        lowest = b.depth[i].lower;
        at_rpm = RadPerSecToRpm(b.speed_rad_s(static_cast<Eigen::Index>(i)));
      }
    }
    if (b.propagation.method_used == dynamics::PropagationMethod::kFirstOrder && !(lowest > 0.0)) {
      const std::string w =
          b.id + ": the first-order interval of the critical depth reaches " + FormatNumber(1e3 * lowest, 4) +
          " mm" + (std::isfinite(at_rpm) ? " at " + FormatNumber(at_rpm, 5) + " rpm" : std::string()) +
          ", which is not a depth: first order does not hold here (the lobes bend within the interval); use "
          "--uncertainty-method auto or monte-carlo";
      Tell(tell, Message::Kind::kWarning, w);
      run.input_findings.push_back(w);
    }
  }
  return run;
}

std::vector<LobeDiagramCurve> StabilityLobesRun::DiagramCurves() const {
  std::vector<LobeDiagramCurve> curves;
  for (const stability::TipDynamics& t : tips) {
    for (const std::string m : {"zoa", "sd"}) {
      LobeDiagramCurve c;
      for (const stability::LobeRow& r : lobes.rows) {
        if (r.id != t.id || r.method != m) continue;
        c.speed_rpm.push_back(RadPerSecToRpm(r.point.spindle_speed_rad_s));
        c.depth_mm.push_back(r.point.status == stability::LobeStatus::kOk ? MToMm(r.point.critical_depth) : NAN);
        if (!bands.empty() && m == "zoa") {
          c.lower_mm.push_back(MToMm(r.depth_lower));
          c.upper_mm.push_back(MToMm(r.depth_upper));
        }
      }
      if (c.speed_rpm.empty()) continue;
      c.label = t.id + " " + (m == "zoa" ? "ZOA" : "SD");
      c.markers = m == "sd";
      curves.push_back(std::move(c));
    }
  }
  return curves;
}

std::string StabilityLobesRun::CutDescription() const {
  const stability::MillingProcess& mp = cut.process;
  return std::to_string(mp.teeth) + " teeth, a_e/D = " + io::FormatDouble(mp.radial_immersion) +
         (mp.direction == stability::MillingDirection::kUp ? ", up-milling" : ", down-milling");
}

std::string StabilityLobesRun::BandNote(const StabilityLobesOptions& o) const {
  if (bands.empty()) return "";
  const dynamics::PropagationMethod m = bands.front().propagation.method_used;
  std::string method = m == dynamics::PropagationMethod::kMonteCarlo ? "Monte Carlo" : "first order";
  for (const stability::ZoaBand& b : bands) {
    if (b.propagation.method_used != m) method = "method per posture in the notes";
  }
  return FormatNumber(100.0 * o.uncertainty.confidence, 3) + " %, " + method;
}

void StabilityLobesRun::ModesInSourceFrame(std::vector<std::string>* ids,
                                           std::vector<std::vector<dynamics::Mode>>* modes) const {
  for (const stability::TipDynamics& t : tips) {
    ids->push_back(t.id);
    modes->push_back(stability::ModesInSourceFrame(t));
  }
}

nlohmann::json StabilityLobesRun::Summary(const StabilityLobesOptions& o) const {
  nlohmann::json j = io::LobesSummaryJson(tips, lobes, stability::SummarizeLobes(tips, lobes.rows));
  j["cut"] = o.cut_path;
  j["source"] = o.Source();
  if (!o.robot_path.empty()) {
    j["robot"] = o.robot_path;
    j["postures"] = o.postures_path;
  }
  if (!o.frf_path.empty()) j["frf"] = o.frf_path;
  if (!o.frf_y_path.empty()) j["frf_y"] = o.frf_y_path;
  if (!o.modal_table_path.empty()) j["modal_table"] = o.modal_table_path;
  j["method"] = stability::ToString(o.method);
  j["teeth"] = cut.process.teeth;
  j["radial_immersion"] = cut.process.radial_immersion;
  j["input_findings"] = input_findings;
  if (!bands.empty()) {
    nlohmann::json u;
    u["files"] = uncertainty_files;
    u["confidence"] = o.uncertainty.confidence;
    u["tips"] = nlohmann::json::array();
    for (const stability::ZoaBand& b : bands) {
      u["tips"].push_back({{"pose_id", b.id},
                           {"min_critical_depth_mm", 1e3 * b.min_depth.value},
                           {"min_critical_depth_mm_lower", 1e3 * b.min_depth.lower},
                           {"min_critical_depth_mm_upper", 1e3 * b.min_depth.upper},
                           {"method", dynamics::ToString(b.propagation.method_used)},
                           {"reason", b.propagation.reason},
                           {"failed_samples", b.propagation.failed_samples}});
    }
    j["uncertainty"] = u;
  }
  return j;
}

}  // namespace robomach::workflows
