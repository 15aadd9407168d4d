#include "robomach/workflows/tracker_synth.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "robomach/common/errors.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/kq_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/tracker_file.h"
#include "robomach/workflows/option_text.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::workflows {
namespace {

// Pulleys 0.5 - 5 m from the base (docs/plausibility.md).
constexpr double kMinPlausiblePulleyDistanceMm = 100.0, kMaxPlausiblePulleyDistanceMm = 20000.0;

}  // namespace

void TrackerSynthOptions::Validate() const {
  CheckOptionRange("noise_mm", noise_mm, 0.0, 1e3);
  if (outliers < 0) throw OptionError("outliers", "outliers: expected a count >= 0, got " + std::to_string(outliers));
  if (num_postures < 1) {
    throw OptionError("num_postures", "num_postures: expected at least 1, got " + std::to_string(num_postures));
  }
  CheckOptionRange("outlier_mm", outlier_mm, 0.0, 1e4);
  // A distance from the base axis; 0 lets the postures come anywhere.
  CheckOptionRange("min_reach_mm", min_reach_mm, 0.0, 1e5);
  if (form != "rope" && form != "force") {
    throw OptionError("form", "form: expected rope or force, got '" + form + "'");
  }
}

TrackerSynthRun RunTrackerSynth(const TrackerSynthOptions& o, const MessageSink& tell) {
  o.Validate();
  if (!o.plan_path.empty() && !o.postures_path.empty()) {
    throw OptionError("plan_path", "plan_path and postures_path exclude each other");
  }
  TrackerSynthRun r;
  const auto finding = [&](const std::string& w) {
    if (w.empty()) return;
    Tell(tell, Message::Kind::kWarning, w);
    r.unit_findings.push_back(w);
  };
  // Laser trackers measure to 0.005 - 0.05 mm (1 sigma, Leica AT960 and
  // API Radian data sheets): a noise over 1 mm is um typed in the mm
  // option, one under 0.1 um is m (docs/plausibility.md).
  finding(io::TrackerNoiseUnitFinding(o.Name("noise_mm"), o.noise_mm));
  r.config = workflows::LoadRobotConfigChecked(o.robot_path);
  for (const std::string& w : r.config.implausible) Tell(tell, Message::Kind::kWarning, w);
  for (const std::string& s : o.sets) {
    const size_t eq = s.find('=');
    double v = 0.0;
    if (eq == std::string::npos || eq == 0 || !io::ParseFiniteNumber(s.substr(eq + 1), &v)) {
      throw OptionError("sets", "sets " + s + ": expected NAME=VALUE with a number, e.g. m6_kg=30");
    }
    r.config.parameters.Set(s.substr(0, eq), v);  // an unknown name: bad input (its std::invalid_argument)
  }
  r.model = r.config.Build();

  identification::CampaignOptions& c = r.campaign;
  c.masses_kg = ParseNumberList("masses_kg", o.masses_kg);
  // Load tests hang tens of kilograms; beyond a tonne the linear model and
  // the static equilibrium of the simulation are meaningless.
  for (double m : c.masses_kg) {
    if (!(m >= 1e-3 && m <= 1e3)) {
      throw OptionError("masses_kg", "masses_kg " + FormatDouble(m) + ": expected masses in [0.001, 1000] kg" +
                                         (m > 1e3 ? ": a mass in g typed in the kg option?" : ""));
    }
    finding(ImplausibleOption(o.Name("masses_kg"), m, io::kMinPlausibleLoadMassKg, io::kMaxPlausibleLoadMassKg, "kg",
                        "load-test masses (5 - 300 kg)", "a mass in t typed in the kg option?",
                        "a mass in g typed in the kg option, or a weight in N?"));
  }
  c.pulleys.clear();
  for (const std::string& p : o.pulley_mm) {
    const auto v = ParsePointMm("pulley_mm", p);
    if (!v) throw OptionError("pulley_mm", "pulley_mm: expected x,y,z in mm");
    finding(ImplausibleOption(o.Name("pulley_mm") + " " + p + ": a distance from the base of", MToMm(v->norm()),
                        kMinPlausiblePulleyDistanceMm, kMaxPlausiblePulleyDistanceMm, "mm",
                        "load-test pulleys (0.5 - 5 m from the base)", "a position in m typed in the mm option?",
                        "a position in um typed in the mm option?"));
    c.pulleys.push_back(*v);
  }
  c.p_load_tip = ParsePointMm("load_point_mm", o.load_point_mm.value_or(kDefaultLoadPointMm));
  c.p_target_tip = ParsePointMm("target_mm", o.target_mm.value_or(kDefaultTargetMm));
  for (const auto& [field, p] : {std::pair{"load_point_mm", c.p_load_tip}, {"target_mm", c.p_target_tip}}) {
    if (p && p->norm() > 2.0) {
      throw OptionError(field, std::string(field) + ": expected a point within 2000 mm of the flange");
    }
  }
  c.tracker_noise = MmToM(o.noise_mm);
  c.seed = o.seed;
  c.num_outliers = o.outliers;
  c.outlier_size = MmToM(o.outlier_mm);
  c.force_form = o.form == "force";
  c.min_reach = MmToM(o.min_reach_mm);

  std::vector<Eigen::VectorXd> qs;
  std::vector<std::vector<Eigen::Vector3d>> plan_pulleys;
  if (!o.plan_path.empty()) {
    r.postures_source = "plan";
    io::LoadTestPlanFile plan = io::ReadLoadTestPlanCsv(o.plan_path, r.model->num_joints());
    r.pose_ids = std::move(plan.pose_ids);
    qs = std::move(plan.q);
    plan_pulleys = std::move(plan.pulleys);
    const auto& meta = plan.metadata;
    const auto plan_point = [&](const std::string& key) -> std::optional<Eigen::Vector3d> {
      // An OptionError here is bad data in the plan file.
      return AtLocation<OptionError>({o.plan_path, 0, 0}, "", [&] { return ParsePointMm(key, meta.at(key)); });
    };
    // The plan's load point and target, unless the options replace them:
    // then said, since the plan was chosen for its own.
    // The plan's keys are the fields' names.
    for (const auto& [key, given, point] :
         {std::tuple{"load_point_mm", o.load_point_mm.has_value(), &c.p_load_tip},
          std::tuple{"target_mm", o.target_mm.has_value(), &c.p_target_tip}}) {
      if (!meta.count(key)) continue;
      if (!given) {
        *point = plan_point(key);
      } else if (plan_point(key) != *point) {
        Tell(tell, Message::Kind::kWarning,
             o.Name(key) + " replaces the plan's " + key + " " + meta.at(key) + " (" + o.plan_path +
                 "): the plan's postures and rope directions were chosen for its own");
      }
    }
  } else if (!o.postures_path.empty()) {
    r.postures_source = "postures";
    for (const auto& p : io::ReadPostureFile(o.postures_path, r.model->num_joints())) {
      r.pose_ids.push_back(p.id);
      qs.push_back(p.q);
    }
  } else {
    r.postures_source = "random";
    try {
      qs = identification::CampaignPostures(*r.model, o.num_postures, c, o.seed);
    } catch (const std::invalid_argument& e) {
      // "count 40: only ...": the library's count is num_postures.
      const std::string m = e.what();
      if (m.rfind("count ", 0) != 0) throw;
      throw OptionError("num_postures", "num_postures" + m.substr(5) + " (the least reach is " +
                                            o.Name("min_reach_mm") + " " + FormatNumber(o.min_reach_mm, 6) + ")");
    }
    for (size_t p = 0; p < qs.size(); ++p) r.pose_ids.push_back("P" + std::to_string(p + 1));
  }
  r.rope_directions = plan_pulleys.empty() ? c.pulleys.size() : plan_pulleys[0].size();
  const Eigen::VectorXd& kq = r.model->joint_stiffness();
  r.measurements = plan_pulleys.empty()
                       ? identification::SimulateCampaign(*r.model, r.pose_ids, qs, kq, c, &r.outlier_cases)
                       : identification::SimulateCampaign(*r.model, r.pose_ids, qs, plan_pulleys, kq, c,
                                                          &r.outlier_cases);
  return r;
}

std::vector<std::pair<std::string, std::string>> TrackerSynthRun::Metadata(const TrackerSynthOptions& o) const {
  std::vector<std::pair<std::string, std::string>> meta{{"generator", "tracker-synth (robomach)"},
                                                        {"robot", o.robot_path},
                                                        {"seed", std::to_string(o.seed)},
                                                        {"tracker_noise_mm", FormatDouble(o.noise_mm)}};
  for (int j = 0; j < model->num_joints(); ++j) {
    meta.emplace_back("truth_kq" + std::to_string(j + 1) + "_Nm_per_rad", FormatDouble(model->joint_stiffness()(j)));
  }
  std::string ids;
  for (int c : outlier_cases) ids += (ids.empty() ? "" : " ") + measurements[c].case_id;
  if (!outlier_cases.empty()) meta.emplace_back("outlier_cases", ids);
  return meta;
}

nlohmann::json TrackerSynthRun::Summary(const TrackerSynthOptions& o) const {
  nlohmann::json j;
  j["robot"] = o.robot_path;
  j["postures_source"] = postures_source;
  if (!o.plan_path.empty()) j["plan_file"] = o.plan_path;
  if (!o.postures_path.empty()) j["postures"] = o.postures_path;
  j["seed"] = o.seed;
  j["tracker_noise_mm"] = o.noise_mm;
  j["masses_kg"] = campaign.masses_kg;
  j["form"] = o.form;
  j["outliers_asked"] = o.outliers;
  j["outlier_mm"] = o.outlier_mm;
  j["load_cases"] = measurements.size();
  j["postures_count"] = pose_ids.size();
  j["pose_ids"] = pose_ids;
  std::vector<std::string> cases;
  for (int c : outlier_cases) cases.push_back(measurements[c].case_id);
  j["outlier_cases"] = cases;
  const Eigen::VectorXd& kq = model->joint_stiffness();
  j["truth_kq_Nm_per_rad"] = std::vector<double>(kq.data(), kq.data() + kq.size());
  // Deflection of the target under load, |p1 - p0| with the tracker noise.
  double dmin = INFINITY, dmax = 0.0;
  for (const auto& m : measurements) {
    const double d = MToMm((m.p1 - m.p0).norm());
    dmin = std::min(dmin, d);
    dmax = std::max(dmax, d);
  }
  if (!measurements.empty()) {
    j["deflection_min_mm"] = dmin;
    j["deflection_max_mm"] = dmax;
  }
  return j;
}

std::string TrackerSynthRun::CountsLine() const {
  std::string ids;
  for (int c : outlier_cases) ids += (ids.empty() ? "" : " ") + measurements[c].case_id;
  return std::to_string(measurements.size()) + " load cases (" + std::to_string(pose_ids.size()) + " postures x " +
         std::to_string(rope_directions) + " rope directions x " + std::to_string(campaign.masses_kg.size()) +
         " masses)" + (outlier_cases.empty() ? "" : "; outliers: " + ids);
}

}  // namespace robomach::workflows
