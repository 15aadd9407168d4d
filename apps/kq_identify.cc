// kq-identify: joint stiffness of a robot from laser-tracker load tests
// (docs/formats.md §2), with uncertainty, outliers and a word on what the data
// cannot determine; or, with --plan N, a D-optimal test plan.
#include <CLI/CLI.hpp>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/identification/compliance_model.h"
#include "robomach/identification/joint_stiffness.h"
#include "robomach/identification/test_plan.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/kq_files.h"
#include "robomach/io/kq_yaml.h"
#include "robomach/io/number_format.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/tracker_file.h"
#include "robomach/report/plot.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "kq-identify";

std::string Sci(double v, int digits = 3) {
  if (!std::isfinite(v)) return "inf";
  std::ostringstream s;
  s << std::scientific << std::setprecision(digits) << v;
  return s.str();
}

void PrintReport(const identification::JointStiffnessResult& r, std::ostream& os) {
  os << kTool << ": " << r.num_cases << " load cases, fit " << identification::ToString(r.status)
     << " (" << r.iterations << " iterations): " << r.solver_message << "\n";
  os << kTool << ": joint  stiffness [N·m/rad]  std dev    rel.    95 % interval             determination\n";
  for (int j = 0; j < r.num_joints; ++j) {
    std::ostringstream rel;
    if (std::isfinite(r.relative_std(j))) rel << std::fixed << std::setprecision(1) << 100 * r.relative_std(j) << " %";
    else rel << "-";
    os << kTool << ":   " << j + 1 << "    " << Sci(r.joint_stiffness(j)) << "          " << Sci(r.std_dev(j), 1)
       << "   " << std::setw(7) << rel.str() << "  [" << Sci(r.lower_95(j), 2) << ", " << Sci(r.upper_95(j), 2)
       << "]  " << identification::ToString(r.determination[j]) << "\n";
  }
  os << kTool << ": RMS residual " << std::fixed << std::setprecision(4) << 1e3 * r.rms_residual
     << " mm (all cases " << 1e3 * r.rms_residual_all << " mm; displacement noise " << 1e3 * r.noise_sigma_displacement
     << " mm per coordinate), chi2/dof " << std::setprecision(2) << r.reduced_chi2
     << ", condition number of the scaled problem " << std::setprecision(1) << r.condition_number << "\n";
}

void PlotResiduals(const std::string& path, const identification::JointStiffnessResult& r,
                   double threshold_over_sigma, const std::string& title) {
  report::Figure fig(1, 2, 640, 420);
  fig.title = title;
  report::Axes& a = fig.at(0, 0);
  a.title = "residual per load case";
  a.x_label = "case (file order)";
  a.y_label = "|measured - predicted| [mm]";
  report::Series in, out, noise, thr;
  in.label = "cases";
  in.markers = true;
  in.color = report::PaletteColor(0);
  out.label = "outliers";
  out.markers = true;
  out.color = report::PaletteColor(1);
  for (size_t c = 0; c < r.residuals.size(); ++c) {
    report::Series& s = r.residuals[c].outlier ? out : in;
    s.x.push_back(static_cast<double>(c + 1));
    s.y.push_back(MToMm(r.residuals[c].norm));
  }
  const double n = static_cast<double>(r.residuals.size());
  // E|r| for 3 Gaussian components of σ is σ·2√(2/π) ≈ 1.6 σ.
  noise.x = {1.0, n};
  noise.y = {MToMm(1.596 * r.noise_sigma_displacement), MToMm(1.596 * r.noise_sigma_displacement)};
  noise.label = "expected from tracker noise";
  noise.dashed = true;
  noise.color = report::PaletteColor(2);
  thr.x = {1.0, n};
  thr.y = {MToMm(threshold_over_sigma * r.noise_sigma_displacement),
           MToMm(threshold_over_sigma * r.noise_sigma_displacement)};
  thr.label = "outlier threshold";
  thr.dashed = true;
  thr.color = report::PaletteColor(1);
  a.series = {in, noise, thr};
  if (!out.x.empty()) a.series.push_back(out);

  report::Axes& b = fig.at(0, 1);
  b.title = "displacement components";
  b.x_label = "predicted [mm]";
  b.y_label = "measured [mm]";
  report::Series pts, diag;
  pts.markers = true;
  pts.label = "x, y, z of every case";
  pts.color = report::PaletteColor(0);
  double lo = 0.0, hi = 0.0;
  for (const auto& x : r.residuals) {
    for (int k = 0; k < 3; ++k) {
      pts.x.push_back(MToMm(x.predicted(k)));
      pts.y.push_back(MToMm(x.measured(k)));
      lo = std::min({lo, pts.x.back(), pts.y.back()});
      hi = std::max({hi, pts.x.back(), pts.y.back()});
    }
  }
  diag.x = {lo, hi};
  diag.y = {lo, hi};
  diag.label = "measured = predicted";
  diag.dashed = true;
  diag.color = report::PaletteColor(2);
  b.series = {diag, pts};
  fig.SavePng(path);
}

int RunPlan(const io::RobotConfig& cfg, int num_postures, double noise_mm, unsigned seed,
            const std::optional<Eigen::Vector3d>& load_point, const std::optional<Eigen::Vector3d>& target,
            const std::vector<double>& masses_kg, double max_rope_angle_deg, const std::string& out_path) {
  const auto model = cfg.Build();
  identification::PlanOptions o;
  o.num_postures = num_postures;
  o.tracker_noise = MmToM(noise_mm);
  o.seed = seed;
  o.p_load_tip = load_point;
  o.p_target_tip = target;
  o.masses_kg = masses_kg;
  o.max_rope_angle = DegToRad(max_rope_angle_deg);
  const identification::TestPlan plan = identification::PlanLoadTests(*model, o);
  io::LoadTestPlanHeader header;
  header.num_postures = num_postures;
  header.robot_config = cfg.path;
  header.tracker_noise_mm = noise_mm;
  header.masses_kg = masses_kg;
  header.load_point = load_point;
  header.target = target;
  io::WriteLoadTestPlanCsv(out_path, plan, header);
  std::cerr << kTool << ": plan of " << num_postures << " postures x " << o.directions_per_posture
            << " rope directions x " << masses_kg.size() << " masses = " << plan.cases.size()
            << " load cases; expected standard deviations for a tracker noise of " << noise_mm << " mm:\n";
  for (int j = 0; j < model->num_joints(); ++j) {
    std::ostringstream rel;
    if (std::isfinite(plan.expected_relative_std(j))) {
      rel << std::fixed << std::setprecision(2) << 100 * plan.expected_relative_std(j) << " %";
    } else {
      rel << "not determined";
    }
    std::cerr << kTool << ":   joint " << j + 1 << ": k = " << Sci(model->joint_stiffness()(j)) << " N·m/rad, std dev "
              << Sci(plan.expected_std_dev(j), 2) << " N·m/rad (" << rel.str() << ")\n";
  }
  for (const Finding& f : plan.findings) {
    Warn(kTool, f.message + (f.input_index == model->num_joints() - 1 ? " (--load-point-mm, --target-mm)" : ""));
  }
  for (int j = 0; j < model->num_joints(); ++j) {
    if (plan.expected_determination[j] != identification::Determination::kWeak) continue;
    std::ostringstream m;
    m << "joint " << j + 1 << " would be weakly determined (±" << std::fixed << std::setprecision(0)
      << 100 * plan.expected_relative_std(j) << " % at 1 sigma): plan more postures (--plan N)"
      << (j == model->num_joints() - 1 ? " or put the load point and the target farther off the tool axis" : "");
    Warn(kTool, m.str());
  }
  return ExitCodeFor(plan.status());
}

std::vector<double> ParsePositiveList(const std::string& option, const std::string& text) {
  const std::vector<double> v = ParseNumberList(option, text);
  for (double x : v) {
    if (!(x > 0.0)) {
      throw UsageError(option + ": expected positive numbers separated by commas, got \"" + text + "\"");
    }
  }
  return v;
}

int Run(int argc, char** argv) {
  CLI::App app{
      "kq-identify: joint stiffness from laser-tracker load tests.\n"
      "Reads a robot config and a tracker file (docs/formats.md §2: force components fx_N..fz_N, or\n"
      "mass_kg with rope points ax_mm..bz_mm) and fits the diagonal joint stiffness of\n"
      "D = J_T Kq^-1 J_L^T W. Reports every joint's stiffness with standard deviation, 95 %\n"
      "interval and whether the data determine it; residuals per case; outliers.\n"
      "With --plan N it plans N test postures and rope directions instead (D-optimal)."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             "\nExit code 3 also means: a joint is weakly or not determined, the fit did not converge,\n"
             "or outliers were found without --robust (the outputs are written).");
  std::string robot_path, tracker_path, out_path, residuals_path, plot_path, json_path, robust,
      load_point = "tcp", target = "tcp", masses = "10,20,30";
  double noise_mm = 0.01, rope_angle_deg = 45.0;
  int plan_n = 0;
  unsigned seed = 1;
  bool merge = false, as_parameters = false, verbose = false;
  app.add_option("--robot", robot_path, "robot config YAML (e.g. config/kr210.yaml); its stiffness is the prior")
      ->required();
  app.add_option("--tracker", tracker_path, "tracker load-test CSV (docs/formats.md §2)");
  app.add_option("--out", out_path,
                 "kq.yaml to paste into the robot config (stdout if omitted); with --merge a full robot "
                 "config; with --plan the plan CSV");
  app.add_option("--residuals", residuals_path, "residual of every case, CSV [mm]");
  app.add_option("--plot", plot_path, "residual plot, PNG")->check(PngFileName());
  app.add_option("--summary,--json", json_path, "summary JSON ('-' = stdout; --json is the old name): the full result (stiffness, covariance, residuals, advice)");
  app.add_option("--robust", robust,
                 "robust loss against outlier cases: cauchy or huber (outliers are then left out)")
      ->check(OneOf({"cauchy", "huber"}))
      ->expected(0, 1)
      ->default_str("cauchy");
  app.add_option("--noise-mm", noise_mm, "tracker noise, 1 sigma per coordinate [mm]")->capture_default_str();
  app.add_flag("--merge", merge, "write a full robot config with the identified stiffness to --out");
  app.add_flag("--as-parameters", as_parameters,
               "write a parameters: block (kq1_Nm_per_rad ...) instead of joint_stiffness_Nm_per_rad");
  app.add_option("--plan", plan_n, "plan N test postures (D-optimal) instead of identifying");
  app.add_option("--load-point-mm", load_point,
                 "--plan: load point x,y,z in the tip frame [mm], or tcp")->capture_default_str();
  app.add_option("--target-mm", target, "--plan: tracker target x,y,z in the tip frame [mm], or tcp")
      ->capture_default_str();
  app.add_option("--masses-kg", masses, "--plan: masses hung at every direction [kg]")->capture_default_str();
  app.add_option("--max-rope-angle-deg", rope_angle_deg, "--plan: largest rope angle from vertical [deg]")
      ->capture_default_str();
  app.add_option("--seed", seed, "--plan: seed of the candidate postures")->capture_default_str();
  app.add_flag("--verbose", verbose, "list ignored tracker columns on stderr");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  // "--robust" alone means cauchy.
  if (app.count("--robust") > 0 && robust.empty()) robust = "cauchy";

  return RunGuarded(kTool, [&]() -> int {
    if (!(noise_mm > 0.0) || !std::isfinite(noise_mm)) {
      throw UsageError("--noise-mm: expected a finite noise > 0 mm");
    }
    CheckOptionRange("--plan", plan_n, 0, 500);  // 500 postures: ~15 s of planning
    // The two modes' options are not mixed silently (issue #35: --plan with
    // --tracker planned and ignored the file).
    if (plan_n != 0) {
      for (const char* name : {"--tracker", "--residuals", "--plot", "--summary", "--robust", "--merge",
                               "--as-parameters"}) {
        if (app.count(name) > 0) {
          throw UsageError(std::string(name) + " is for identifying from a tracker file, and --plan " +
                           std::to_string(plan_n) + " plans a test instead (no file is read): give one of the two");
        }
      }
    } else {
      for (const char* name : {"--load-point-mm", "--target-mm", "--masses-kg", "--max-rope-angle-deg", "--seed"}) {
        if (app.count(name) > 0) {
          throw UsageError(std::string(name) + " is an option of --plan N (planning a test); without --plan, "
                           "kq-identify identifies from --tracker and does not use it");
        }
      }
    }
    RequireInputFile("--robot", robot_path, "robot config", {io::FileKind::kYaml}, io::kRobotConfigFormat);
    CheckDistinctPaths({{"--robot", robot_path}, {"--tracker", tracker_path}},
                       {{"--out", out_path}, {"--residuals", residuals_path}, {"--plot", plot_path},
                        {"--summary", json_path}});
    const io::RobotConfig cfg = LoadRobotConfigWarned(kTool, robot_path);
    if (plan_n != 0) {
      if (plan_n < 1) throw UsageError("--plan: expected a number of postures >= 1");
      const int rc = RunPlan(cfg, plan_n, noise_mm, seed, ParsePointMm("--load-point-mm", load_point),
                             ParsePointMm("--target-mm", target), ParsePositiveList("--masses-kg", masses),
                             rope_angle_deg, out_path);
      return rc == kExitOk && !cfg.implausible.empty() ? kExitFlagged : rc;
    }
    if (tracker_path.empty()) throw UsageError("--tracker is required (or --plan N)");
    if (merge && out_path.empty()) throw UsageError("--merge needs --out for the merged config");
    RequireInputFile("--tracker", tracker_path, "tracker file", {io::FileKind::kCsv}, io::kTrackerCsvFormat);
    const auto model = cfg.Build();
    if (!model->effects().empty()) {
      Warn(kTool, robot_path + " enables effects with their own compliance; the load-test model "
                  "D = J_T Kq^-1 J_L^T W has joint compliance only, so the identified stiffness absorbs "
                  "theirs");
    }
    const io::TrackerFile tf = io::ReadTrackerFile(tracker_path, model->num_joints());
    // Unit mistakes in the file and in --noise-mm: said, flagged, and kept
    // with the advice (summary and report).
    std::vector<std::string> implausible = tf.unit_warnings;
    if (const std::string w = io::TrackerNoiseUnitFinding("--noise-mm", noise_mm); !w.empty()) {
      implausible.push_back(w);
    }
    for (const std::string& w : implausible) Warn(kTool, w);
    if (verbose && !tf.unknown_columns.empty()) {
      std::string cols;
      for (const auto& c : tf.unknown_columns) cols += (cols.empty() ? "" : ", ") + c;
      Warn(kTool, tracker_path + ": ignored columns: " + cols);
    }
    std::vector<identification::LoadCase> cases;
    for (const auto& m : tf.measurements) cases.push_back(identification::ToLoadCase(m));
    // Joints outside their limits: the first three cases named, the rest
    // counted (radians under _deg put every case outside: one line, not 72).
    int outside = 0;
    for (const auto& c : cases) {
      for (int j : model->chain().JointsOutsideLimits(c.q)) {
        if (++outside <= 3) {
          Warn(kTool, tracker_path + ":" + std::to_string(c.line) + ": case " + c.case_id + ": joint " +
                          std::to_string(j + 1) + " is outside its limits");
        }
      }
    }
    if (outside > 3) {
      Warn(kTool, tracker_path + ": " + std::to_string(outside - 3) + " more joints outside their limits (" +
                      std::to_string(outside) + " in all)");
    }
    identification::IdentificationOptions opt;
    opt.tracker_noise = MmToM(noise_mm);
    if (robust == "cauchy") opt.loss = identification::RobustLoss::kCauchy;
    if (robust == "huber") opt.loss = identification::RobustLoss::kHuber;
    ProgressLine progress(kTool, "load cases", static_cast<long>(cases.size()));
    identification::JointStiffnessResult r = identification::IdentifyJointStiffness(
        *model, cases, opt, [&](long done, long) { progress.Update(done); });
    progress.Finish();
    // The table, then each problem as a warning (the unit findings were
    // warned above), before any output is written: the summary lists them all.
    PrintReport(r, std::cerr);
    for (const std::string& a : r.advice) Warn(kTool, a);
    r.advice.insert(r.advice.begin(), implausible.begin(), implausible.end());
    const int exit_code = r.flagged() || !cfg.implausible.empty() || !implausible.empty() ? kExitFlagged : kExitOk;

    // Outputs, each complete or absent (docs/formats.md §4).
    const std::vector<std::string> header{
        "kq-identify: joint stiffness identified from " + tracker_path + " with robot " + robot_path,
        "tracker noise " + io::FormatDouble(noise_mm) + " mm (1 sigma per coordinate); loss " +
            (robust.empty() ? std::string("least squares") : robust)};
    if (merge) {
      std::vector<std::string> h = header;
      for (const auto& a : r.advice) h.push_back("NOTE: " + a);
      io::WriteFileAtomically(out_path, io::MergeJointStiffness(robot_path, r.joint_stiffness, out_path, h));
    } else {
      io::KqYamlOptions ko;
      ko.as_parameters = as_parameters;
      ko.header_comments = header;
      const std::string yaml = io::JointStiffnessYaml(r, ko);
      io::WriteFileAtomically(out_path.empty() ? "-" : out_path, yaml);
    }
    if (!residuals_path.empty()) io::WriteKqResidualsCsv(residuals_path, r, cases);
    if (!plot_path.empty()) {
      PlotResiduals(plot_path, r, r.outlier_threshold, "kq-identify: " + tracker_path);
    }
    if (!json_path.empty()) {
      nlohmann::json j = io::KqSummaryJson(r);
      j["tool"] = kTool;
      j["flagged"] = exit_code == kExitFlagged;
      j["exit_code"] = exit_code;
      io::WriteFileAtomically(json_path, SummaryText(j));
    }
    return exit_code;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
