// tracker-synth: simulates a laser-tracker load-test campaign from a robot
// config and writes it in the tracker format (docs/formats.md §2), to rehearse a
// campaign or to test kq-identify.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <tuple>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/identification/campaign_synth.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/kq_files.h"
#include "robomach/io/number_format.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/tracker_file.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

using io::kMaxPlausibleLoadMassKg;  // load masses and tracker noise: the ranges kq-identify
using io::kMinPlausibleLoadMassKg;  // checks a tracker file with (io/tracker_file.h)
// Pulleys 0.5 - 5 m from the base (docs/plausibility.md).
constexpr double kMinPlausiblePulleyDistanceMm = 100.0, kMaxPlausiblePulleyDistanceMm = 20000.0;

constexpr char kTool[] = "tracker-synth";

int Run(int argc, char** argv) {
  CLI::App app{
      "tracker-synth: simulate a laser-tracker load-test campaign (docs/formats.md §2).\n"
      "For every posture, pulley and mass: the static deflection of the target under the rope\n"
      "force (large-displacement equilibrium with the config's joint stiffness), tracker readings\n"
      "with Gaussian noise, optional gross outliers. Seeded: the same options give the same file."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp());
  std::string robot_path, out_path, summary_path, postures_path, plan_path, masses = "10,20,30", load_point = "150,0,100",
                                                   target = "0,120,50", form = "rope";
  std::vector<std::string> pulleys{"1600,-1200,0", "1600,1200,0"}, sets;
  int num_postures = 12, outliers = 0;
  double noise_mm = 0.01, outlier_mm = 1.0, min_reach_mm = 1500.0;
  unsigned seed = 1;
  app.add_option("--robot", robot_path, "robot config YAML; its joint stiffness is the truth")->required();
  app.add_option("--out", out_path, "tracker CSV to write (stdout if omitted or '-')");
  app.add_option("--summary", summary_path,
                 "summary JSON (docs/formats.md §4.1): inputs, load cases, outliers, the true joint stiffness, "
                 "deflections; '-' = stdout");
  app.add_option("--postures", postures_path, "posture file CSV (docs/formats.md §1); default: random postures");
  app.add_option("--plan-file", plan_path,
                 "a plan from kq-identify --plan: its postures and pulleys (and load point and target "
                 "unless given here)");
  app.add_option("--num-postures", num_postures, "number of random postures (without --postures)")
      ->capture_default_str();
  app.add_option("--min-reach-mm", min_reach_mm,
                 "random postures: least horizontal distance of the load point from the base axis [mm]")
      ->capture_default_str();
  app.add_option("--masses-kg", masses, "masses hung at every posture and pulley [kg]")->capture_default_str();
  app.add_option("--pulley-mm", pulleys, "pulley position x,y,z in the base frame [mm], one per rope direction")
      ->capture_default_str();
  app.add_option("--load-point-mm", load_point, "load point x,y,z in the tip frame [mm], or tcp")
      ->capture_default_str();
  app.add_option("--target-mm", target, "tracker target x,y,z in the tip frame [mm], or tcp")->capture_default_str();
  app.add_option("--noise-mm", noise_mm, "tracker noise, 1 sigma per coordinate [mm]")->capture_default_str();
  app.add_option("--outliers", outliers, "number of cases with a gross error")->capture_default_str();
  app.add_option("--outlier-mm", outlier_mm, "size of that error [mm]")->capture_default_str();
  app.add_option("--form", form, "load columns: rope (mass_kg + rope points) or force (fx_N..fz_N)")
      ->check(OneOf({"rope", "force"}))
      ->capture_default_str();
  app.add_option("--seed", seed, "random seed (postures, noise, outliers)")->capture_default_str();
  app.add_option("--set", sets, "override a model parameter of the truth, NAME=VALUE (e.g. kq3_Nm_per_rad=4e6)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }

  return RunGuarded(kTool, [&]() -> int {
    if (!(noise_mm >= 0.0)) throw UsageError("--noise-mm: expected a noise >= 0 mm");
    if (outliers < 0) throw UsageError("--outliers: expected a count >= 0");
    if (num_postures < 1) throw UsageError("--num-postures: expected at least 1");
    CheckOptionRange("--noise-mm", noise_mm, 0.0, 1e3);
    CheckOptionRange("--outlier-mm", outlier_mm, 0.0, 1e4);
    RequireReadableFile(robot_path, "robot config");
    if (!postures_path.empty()) RequireReadableFile(postures_path, "posture file");
    CheckDistinctPaths({{"--robot", robot_path}, {"--postures", postures_path}, {"--plan-file", plan_path}},
                       {{"--out", out_path}, {"--summary", summary_path}});
    if (!plan_path.empty()) RequireReadableFile(plan_path, "plan file");
    if (!plan_path.empty() && !postures_path.empty()) {
      throw UsageError("--plan-file and --postures exclude each other");
    }
    // Laser trackers measure to 0.005 - 0.05 mm (1 sigma, Leica AT960 and
    // API Radian data sheets): a noise over 1 mm is um typed in the mm
    // option, one under 0.1 um is m (docs/plausibility.md).
    std::vector<std::string> implausible;
    if (const std::string w = io::TrackerNoiseUnitFinding("--noise-mm", noise_mm); !w.empty()) {
      implausible.push_back(w);
    }
    for (const std::string& w : implausible) Warn(kTool, w);
    io::RobotConfig cfg = LoadRobotConfigWarned(kTool, robot_path);
    for (const std::string& s : sets) {
      const auto [name, value] = ParseAssignment("--set", s);
      cfg.parameters.Set(name, value);
    }
    const auto model = cfg.Build();

    identification::CampaignOptions o;
    o.masses_kg = ParseNumberList("--masses-kg", masses);
    // Load tests hang tens of kilograms; beyond a tonne the linear model and
    // the static equilibrium of the simulation are meaningless.
    for (double m : o.masses_kg) {
      if (!(m >= 1e-3 && m <= 1e3)) {
        throw UsageError("--masses-kg " + io::FormatDouble(m) + ": expected masses in [0.001, 1000] kg" +
                         (m > 1e3 ? ": a mass in g typed in the kg option?" : ""));
      }
      const std::string w = ImplausibleOption("--masses-kg", m, kMinPlausibleLoadMassKg, kMaxPlausibleLoadMassKg, "kg",
                                              "load-test masses (5 - 300 kg)", "a mass in t typed in the kg option?",
                                              "a mass in g typed in the kg option, or a weight in N?");
      if (!w.empty()) {
        Warn(kTool, w);
        implausible.push_back(w);
      }
    }
    for (double m : o.masses_kg) {
      if (!(m > 0.0)) throw UsageError("--masses-kg: expected masses > 0 kg");
    }
    o.pulleys.clear();
    for (const auto& p : pulleys) {
      const auto v = ParsePointMm("--pulley-mm", p);
      if (!v) throw UsageError("--pulley-mm: expected x,y,z in mm");
      const std::string w = ImplausibleOption("--pulley-mm " + p + ": a distance from the base of", MToMm(v->norm()),
                                              kMinPlausiblePulleyDistanceMm, kMaxPlausiblePulleyDistanceMm, "mm",
                                              "load-test pulleys (0.5 - 5 m from the base)",
                                              "a position in m typed in the mm option?",
                                              "a position in um typed in the mm option?");
      if (!w.empty()) {
        Warn(kTool, w);
        implausible.push_back(w);
      }
      o.pulleys.push_back(*v);
    }
    o.p_load_tip = ParsePointMm("--load-point-mm", load_point);
    o.p_target_tip = ParsePointMm("--target-mm", target);
    for (const auto& [opt, p] : {std::pair{"--load-point-mm", o.p_load_tip}, {"--target-mm", o.p_target_tip}}) {
      if (p && p->norm() > 2.0) throw UsageError(std::string(opt) + ": expected a point within 2000 mm of the flange");
    }
    o.tracker_noise = MmToM(noise_mm);
    o.seed = seed;
    o.num_outliers = outliers;
    o.outlier_size = MmToM(outlier_mm);
    o.force_form = form == "force";
    o.min_reach = MmToM(min_reach_mm);

    std::vector<std::string> ids;
    std::vector<Eigen::VectorXd> qs;
    std::vector<std::vector<Eigen::Vector3d>> plan_pulleys;
    if (!plan_path.empty()) {
      // The plan CSV of kq-identify --plan.
      io::LoadTestPlanFile plan = io::ReadLoadTestPlanCsv(plan_path, model->num_joints());
      ids = std::move(plan.pose_ids);
      qs = std::move(plan.q);
      plan_pulleys = std::move(plan.pulleys);
      const auto& meta = plan.metadata;
      // The plan's load point and target, unless the options replace them:
      // then said, since the plan was chosen for its own.
      for (const auto& [option, key, point] :
           {std::tuple{"--load-point-mm", "load_point_mm", &o.p_load_tip}, {"--target-mm", "target_mm", &o.p_target_tip}}) {
        if (!meta.count(key)) continue;
        if (app.count(option) == 0) {
          *point = ParsePointMm(plan_path + ": " + key, meta.at(key));
        } else if (ParsePointMm(plan_path + ": " + key, meta.at(key)) != *point) {
          Warn(kTool, std::string(option) + " replaces the plan's " + key + " " + meta.at(key) + " (" + plan_path +
                          "): the plan's postures and rope directions were chosen for its own");
        }
      }
    } else if (!postures_path.empty()) {
      for (const auto& p : io::ReadPostureFile(postures_path, model->num_joints())) {
        ids.push_back(p.id);
        qs.push_back(p.q);
      }
    } else {
      ValidateOptions({{"count", "--num-postures"}},
                      [&] { qs = identification::CampaignPostures(*model, num_postures, o, seed); });
      for (size_t p = 0; p < qs.size(); ++p) ids.push_back("P" + std::to_string(p + 1));
    }
    std::vector<int> bad;
    const auto ms = plan_pulleys.empty()
                        ? identification::SimulateCampaign(*model, ids, qs, model->joint_stiffness(), o, &bad)
                        : identification::SimulateCampaign(*model, ids, qs, plan_pulleys,
                                                           model->joint_stiffness(), o, &bad);

    std::vector<std::pair<std::string, std::string>> meta{
        {"generator", "tracker-synth (robomach)"},
        {"robot", robot_path},
        {"seed", std::to_string(seed)},
        {"tracker_noise_mm", io::FormatDouble(noise_mm)}};
    for (int j = 0; j < model->num_joints(); ++j) {
      meta.emplace_back("truth_kq" + std::to_string(j + 1) + "_Nm_per_rad",
                        io::FormatDouble(model->joint_stiffness()(j)));
    }
    std::string bad_ids;
    for (int c : bad) bad_ids += (bad_ids.empty() ? "" : " ") + ms[c].case_id;
    if (!bad.empty()) meta.emplace_back("outlier_cases", bad_ids);
    io::WriteTrackerFile(out_path.empty() ? "-" : out_path, ms, meta);
    if (!summary_path.empty()) {
      nlohmann::json j;
      j["tool"] = kTool;
      j["robot"] = robot_path;
      j["postures_source"] = !plan_path.empty() ? "plan" : !postures_path.empty() ? "postures" : "random";
      if (!plan_path.empty()) j["plan_file"] = plan_path;
      if (!postures_path.empty()) j["postures"] = postures_path;
      j["out"] = out_path.empty() ? "-" : out_path;
      j["seed"] = seed;
      j["tracker_noise_mm"] = noise_mm;
      j["masses_kg"] = o.masses_kg;
      j["form"] = form;
      j["outliers_asked"] = outliers;
      j["outlier_mm"] = outlier_mm;
      j["load_cases"] = ms.size();
      j["postures_count"] = ids.size();
      j["pose_ids"] = ids;
      std::vector<std::string> outlier_cases;
      for (int c : bad) outlier_cases.push_back(ms[c].case_id);
      j["outlier_cases"] = outlier_cases;
      std::vector<double> kq(model->joint_stiffness().data(),
                             model->joint_stiffness().data() + model->joint_stiffness().size());
      j["truth_kq_Nm_per_rad"] = kq;
      // Deflection of the target under load, |p1 - p0| with the tracker noise.
      double dmin = INFINITY, dmax = 0.0;
      for (const auto& m : ms) {
        const double d = MToMm((m.p1 - m.p0).norm());
        dmin = std::min(dmin, d);
        dmax = std::max(dmax, d);
      }
      if (!ms.empty()) {
        j["deflection_min_mm"] = dmin;
        j["deflection_max_mm"] = dmax;
      }
      io::WriteFileAtomically(summary_path, SummaryText(j));
    }
    std::cerr << kTool << ": " << ms.size() << " load cases (" << ids.size() << " postures x "
              << (plan_pulleys.empty() ? o.pulleys.size() : plan_pulleys[0].size()) << " rope directions x " << o.masses_kg.size() << " masses)"
              << (bad.empty() ? "" : "; outliers: " + bad_ids) << "\n";
    return cfg.implausible.empty() && implausible.empty() ? kExitOk : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
