// kq-identify: joint stiffness of a robot from laser-tracker load tests
// (docs/formats.md §2), with uncertainty, outliers and a word on what the data
// cannot determine; or, with --plan N, a D-optimal test plan.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "cli_support.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/kq_files.h"
#include "robomach/io/number_format.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/workflows/kq_identify.h"
#include "robomach/report/residual_plot.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "kq-identify";

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
             "or outliers were found without --robust (the outputs are written). With --plan: a joint no plan\n"
             "can determine, the config's or the options' unit findings, or a --target-band-pct band the plan\n"
             "does not reach or cannot promise (a target that bends within it); a joint the plan leaves weakly\n"
             "determined, and a bend without --target-band-pct, are warnings with exit 0.");
  std::string robot_path, tracker_path, out_path, residuals_path, plot_path, json_path, uncertainty_path, robust,
      load_point = "tcp", target = "tcp", masses = "10,20,30", target_postures, target_quantity = "frequency", cut_path;
  double target_band_pct = 0.0, noise_mm = 0.01, rope_angle_deg = 45.0;
  int plan_n = 0;
  unsigned seed = 1;
  bool merge = false, as_parameters = false, verbose = false;
  app.add_option("--robot", robot_path, "robot config YAML (e.g. config/kr210.yaml); its stiffness is the prior")
      ->required();
  app.add_option("--tracker", tracker_path, "tracker load-test CSV (docs/formats.md §2)");
  app.add_option("--out", out_path, "kq.yaml to paste into the robot config (stdout if omitted); with --merge a full "
                                    "robot config; with --plan the plan CSV");
  app.add_option("--residuals", residuals_path, "residual of every case, CSV [mm]");
  app.add_option("--plot", plot_path, "residual plot, PNG")->check(PngFileName());
  app.add_option("--summary,--json", json_path, "summary JSON ('-' = stdout; --json is the old name): the full result (stiffness, covariance, residuals, advice; with --plan the plan's expected widths and warnings)");
  app.add_option("--robust", robust, "robust loss against outlier cases: cauchy or huber (outliers are then left out)")
      ->check(OneOf({"cauchy", "huber"}))->expected(0, 1)->default_str("cauchy");
  app.add_option("--noise-mm", noise_mm, "tracker noise, 1 sigma per coordinate [mm]")->capture_default_str();
  app.add_option("--uncertainty-out", uncertainty_path, "the fitted stiffnesses' estimates and covariance, YAML "
                                                        "(docs/formats.md §12), for frf-predict --uncertainty");
  app.add_flag("--merge", merge, "write a full robot config with the identified stiffness to --out");
  app.add_flag("--as-parameters", as_parameters,
               "write a parameters: block (kq1_Nm_per_rad ...) instead of joint_stiffness_Nm_per_rad");
  app.add_option("--plan", plan_n, "plan N test postures (D-optimal) instead of identifying");
  app.add_option("--load-point-mm", load_point,
                 "--plan: load point x,y,z in the tip frame [mm], or tcp")->capture_default_str();
  app.add_option("--target-mm", target, "--plan: tracker target x,y,z in the tip frame [mm], or tcp")
      ->capture_default_str();
  app.add_option("--masses-kg", masses, "--plan: masses hung at every direction [kg]")->capture_default_str();
  app.add_option("--max-rope-angle-deg", rope_angle_deg, "--plan: largest rope angle from vertical [deg], in (0, 90)")
      ->capture_default_str();
  app.add_option("--seed", seed, "--plan: seed of the candidate postures")->capture_default_str();
  app.add_option("--target-postures", target_postures, "--plan: a targeted plan (not D-optimal): the postures of the work region (posture CSV) whose --target-quantity must be known well");
  app.add_option("--target-quantity", target_quantity, "--plan --target-postures: frequency (the lowest natural frequency) or safe-depth (the ZOA lobes' smallest critical depth of --cut)")
      ->check(OneOf({"frequency", "safe-depth"}))->capture_default_str();
  app.add_option("--cut", cut_path, "--plan --target-quantity safe-depth: the cut file (docs/formats.md §5)");
  app.add_option("--target-band-pct", target_band_pct, "--plan --target-postures: the 95 % half-width wanted [%]; the plan says how many of its postures reach it (exit 3 when it does not, with about how many would)");
  app.add_flag("--verbose", verbose, "list ignored tracker columns on stderr");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  if (app.count("--robust") > 0 && robust.empty()) robust = "cauchy";  // "--robust" alone means cauchy

  return RunGuarded(kTool, [&]() -> int {
    // Before any file is looked at (the options first: exit 64).
    if (!(noise_mm > 0.0) || !std::isfinite(noise_mm)) throw UsageError("--noise-mm: expected a finite noise > 0 mm");
    CheckOptionRange("--plan", plan_n, 0, 500);  // 500 postures: ~15 s of planning
    if (app.count("--plan") > 0 && plan_n == 0) {
      throw UsageError("--plan 0: expected the number of postures to plan, 1 to 500 (without --plan, kq-identify "
                       "identifies from --tracker)");
    }
    // The two modes' options are not mixed silently (issue #35: --plan with
    // --tracker planned and ignored the file).
    if (plan_n != 0) {
      RefuseOptions(app, {"--tracker", "--residuals", "--plot", "--robust", "--merge", "--as-parameters",
                          "--uncertainty-out"},
                    " is for identifying from a tracker file, and --plan " + std::to_string(plan_n) +
                        " plans a test instead (no file is read): give one of the two");
    } else {
      RefuseOptions(app, {"--load-point-mm", "--target-mm", "--masses-kg", "--max-rope-angle-deg", "--seed",
                          "--target-postures", "--target-quantity", "--cut", "--target-band-pct"},
                    " is an option of --plan N (planning a test); without --plan, kq-identify identifies from "
                    "--tracker and does not use it");
    }
    RequireInputFile("--robot", robot_path, "robot config", {io::FileKind::kYaml}, io::kRobotConfigFormat);
    CheckDistinctPaths({{"--robot", robot_path}, {"--tracker", tracker_path}, {"--target-postures", target_postures},
                        {"--cut", cut_path}},
                       {{"--out", out_path}, {"--residuals", residuals_path}, {"--plot", plot_path},
                        {"--summary", json_path}, {"--uncertainty-out", uncertainty_path}});
    if (plan_n != 0) {
      if (json_path == "-" && (out_path.empty() || out_path == "-")) {
        throw UsageError("--summary - and the plan would both go to stdout: give the plan a file with --out");
      }
      // Parsed in this order (the first bad option is named); the points typed in [mm] are held in [m].
      const workflows::KqPlanOptions po{
          .robot_path = robot_path, .num_postures = plan_n, .noise_mm = noise_mm, .seed = seed,
          .load_point_m = ParsePointMm("--load-point-mm", load_point), .target_m = ParsePointMm("--target-mm", target),
          .masses_kg = ParseNumberList("--masses-kg", masses), .max_rope_angle_deg = rope_angle_deg,
          .num_postures_name = "--plan N", .points_name = "--load-point-mm, --target-mm", .noise_mm_name = "--noise-mm",
          .masses_name = "--masses-kg", .load_point_name = "--load-point-mm", .target_name = "--target-mm",
          .max_rope_angle_name = "--max-rope-angle-deg",
          .target_postures_path = target_postures, .target_quantity = target_quantity, .cut_path = cut_path,
          .target_half_width = target_band_pct / 100.0, .target_half_width_name = "--target-band-pct"};
      if (std::ranges::any_of(po.masses_kg, [](double m) { return !(m > 0.0); })) {
        throw UsageError("--masses-kg: expected positive numbers separated by commas, got \"" + masses + "\"");
      }
      if (!target_postures.empty()) {
        RequireInputFile("--target-postures", target_postures, "posture file", {io::FileKind::kCsv},
                         io::kPostureCsvFormat);
      }
      if (!cut_path.empty()) RequireInputFile("--cut", cut_path, "cut file", {io::FileKind::kYaml}, io::kCutFileFormat);
      if (target_postures.empty()) {
        RefuseOptions(app, {"--target-quantity", "--cut", "--target-band-pct"},
                      " describes the target of a targeted plan: give the work region's postures with "
                      "--target-postures (without it the plan is D-optimal)");
      } else if (target_quantity == "frequency" && !cut_path.empty()) {
        throw UsageError("--cut is for --target-quantity safe-depth; the lowest frequency needs no cut");
      }
      if (app.count("--target-band-pct") > 0 && !(target_band_pct > 0.0 && target_band_pct < 100.0)) {
        throw UsageError("--target-band-pct: expected the 95 % half-width wanted in percent (> 0 and < 100; 5 for "
                         "±5 %), got " + io::FormatDouble(target_band_pct));
      }
      ValidateOptions({{"num_postures", "--plan"}, {"noise_mm", "--noise-mm"}, {"masses_kg", "--masses-kg"},
                       {"target_quantity", "--target-quantity"}, {"cut_path", "--cut"}, {"target_half_width", "--target-band-pct"},
                       {"max_rope_angle_deg", "--max-rope-angle-deg"}},
                      [&] { po.Validate(); });
      const workflows::KqPlanResult plan = workflows::RunKqPlan(po, MessagePrinter(kTool));
      io::WriteLoadTestPlanCsv(out_path, plan.plan, plan.PlanHeader(po));
      for (const std::string& line : plan.lines) std::cerr << kTool << ": " << line << '\n';
      for (const std::string& w : plan.warnings) Warn(kTool, w);
      const int exit_code = plan.flagged() ? kExitFlagged : kExitOk;
      if (!json_path.empty()) WriteToolSummary(json_path, kTool, plan.Summary(), exit_code);
      return exit_code;
    }
    if (tracker_path.empty()) throw UsageError("--tracker is required (or --plan N)");
    if (merge && out_path.empty()) throw UsageError("--merge needs --out for the merged config");
    RequireInputFile("--tracker", tracker_path, "tracker file", {io::FileKind::kCsv}, io::kTrackerCsvFormat);
    const workflows::KqIdentifyOptions o{.robot_path = robot_path, .tracker_path = tracker_path, .noise_mm = noise_mm,
                                         .robust = robust, .noise_mm_name = "--noise-mm"};
    ValidateOptions({{"noise_mm", "--noise-mm"}}, [&] { o.Validate(); });
    StageProgressLines progress(kTool);
    const workflows::KqIdentifyResult run = workflows::RunKqIdentify(
        o, MessagePrinter(kTool), [cb = progress.Callback()](long done, long total) { cb("load cases", done, total); });
    progress.Finish();
    if (const std::string m = run.IgnoredColumnsMessage(o); verbose && !m.empty()) Warn(kTool, m);
    // The table, then each problem as a warning (the unit findings were
    // warned above), before any output is written: the summary lists them all.
    for (const std::string& line : workflows::KqReportLines(run.fit)) std::cerr << kTool << ": " << line << '\n';
    for (const std::string& a : run.fit.advice) Warn(kTool, a);
    const int exit_code = run.flagged() ? kExitFlagged : kExitOk;
    // Outputs, each complete or absent (docs/formats.md §4); --merge has --out.
    io::WriteFileAtomically(out_path.empty() ? "-" : out_path, merge ? run.MergedConfigText(o, out_path, uncertainty_path)
                                                                     : run.KqYamlText(o, as_parameters));
    if (!uncertainty_path.empty()) io::WriteParameterUncertainty(uncertainty_path, run.Uncertainty(o));
    if (!residuals_path.empty()) io::WriteKqResidualsCsv(residuals_path, run.fit, run.cases);
    if (!plot_path.empty()) {
      const identification::JointStiffnessResult& r = run.fit;
      report::CaseResidualsMm rm{.noise_sigma_mm = MToMm(r.noise_sigma_displacement),
                                 .threshold_mm = MToMm(r.outlier_threshold * r.noise_sigma_displacement)};
      for (const identification::CaseResidual& c : r.residuals) {
        rm.norm_mm.push_back(MToMm(c.norm));
        rm.outlier.push_back(c.outlier);
        rm.predicted_mm.push_back(1e3 * c.predicted);
        rm.measured_mm.push_back(1e3 * c.measured);
      }
      report::SaveCaseResidualFigure(plot_path, "kq-identify: " + tracker_path, rm);
    }
    if (!json_path.empty()) WriteToolSummary(json_path, kTool, run.Summary(), exit_code);
    return exit_code;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
