// frf-calibrate: calibrates named model parameters (default m6, d6, alpha,
// beta) against measured tool-tip FRFs (CSV or UFF58) and writes the
// calibrated robot config and a report folder.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <map>

#include "cli_support.h"
#include "measured_data.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/report/calibration_report.h"
#include "robomach/report/json.h"
#include "robomach/workflows/frf_calibrate.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "frf-calibrate";
namespace fs = std::filesystem;

int Run(int argc, char** argv) {
  CLI::App app{
      "frf-calibrate: tune named model parameters to measured tool-tip FRFs (hammer tests).\n"
      "Reads a robot config, a posture file (docs/formats.md §1) and measured FRFs (CSV of docs/formats.md §3\n"
      "or UFF58 ASCII; mobility and accelerance are converted to receptance). Writes the calibrated\n"
      "config (the input plus a `parameters:` block) and a report folder: table3.csv/.md (natural\n"
      "frequency and peak amplitude per posture, model vs measurement, relative error), one\n"
      "<pose>.png overlay per posture (measured, model before, model after), stabilisation_<pose>.png\n"
      "(the modal fits' stabilisation diagrams), summary.json."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() + " Exit 3 also when the fit did not converge or a parameter is weakly identified, "
                                "or a measured receptance is outside 1e-12..1e-3 m/N (a unit mistake), or --uncertainty-out "
                                "was asked for and not written (no fitted parameter has a covariance).");
  std::string report_dir, summary_path, uncertainty_path;
  workflows::FrfCalibrateOptions o;
  o.pose_files_name = "--pose", o.validate_pose_files_name = "--validate-pose";  // in the readers' messages
  app.add_option("--robot", o.robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--postures", o.postures_path, "posture file CSV: pose_id,q1_deg..q6_deg")->required();
  app.add_option("--measured", o.measured_files, "measured FRFs, CSV or UFF58 (.uff/.unv); repeatable");
  app.add_option("--pose", o.pose_files, "a UFF58 file of one posture whose records lack pose=ID: ID=file.uff; repeatable");
  app.add_option("--out", o.out_path, "calibrated robot config YAML; '-' = stdout")->required();
  app.add_option("--report", report_dir, "report folder (created)")->required();
  app.add_option("--summary", summary_path, "also write the report's summary.json here ('-' = stdout)");
  app.add_option("--uncertainty-out", uncertainty_path,
                 "write the fitted parameters' estimates and covariance here (docs/formats.md §12), for "
                 "frf-predict, stability-lobes and stability-map --uncertainty");
  app.add_option("--validate", o.validate_files, "held-out measured FRFs scored with the calibrated model; repeatable");
  app.add_option("--validate-pose", o.validate_pose_files, "held-out UFF58 file of one posture: ID=file.uff; repeatable");
  app.add_option("--free", o.frees, "also fit this parameter (any name of the model, e.g. kq2_Nm_per_rad); repeatable");
  app.add_flag("--only-free", o.only_free, "fit only the --free parameters, not the default m6_kg, d6_m, alpha_s, beta_per_s");
  app.add_option("--robust-loss-sigma", o.robust_loss_sigma,
                 "Huber loss per line on the whole-curve objective, its scale in units of the noise (e.g. 3); 0: "
                 "plain least squares. A second line of defence against outlier lines the noise model kept")
      ->capture_default_str();
  app.add_option("--objective", o.objective, "modal-two-stage (frequencies, then peak amplitudes), modal-joint, whole-curve")
      ->check(OneOf({"modal-two-stage", "modal-joint", "whole-curve"}))->capture_default_str();
  app.add_option("--fmin-hz", o.fmin_hz, "lowest frequency used (modal fit and whole curve) [Hz]")->capture_default_str();
  app.add_option("--fmax-hz", o.fmax_hz, "highest frequency used [Hz]; default: all lines");
  app.add_option("--set", o.sets, "start value of a parameter, NAME=VALUE in its unit");
  app.add_option("--add", o.adds, "switch on an effect by name (its parameters may then be --free)");
  app.add_option("--max-iterations", o.max_iterations, "solver iterations per stage")->capture_default_str();
  NoiseCliOptions noise_opt;
  AddNoiseOptions(app, &noise_opt);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    RequireFolderOption("--report", report_dir);
    RequireInputFile("--robot", o.robot_path, "robot config", {io::FileKind::kYaml}, io::kRobotConfigFormat);
    RequireInputFile("--postures", o.postures_path, "posture file", {io::FileKind::kCsv}, io::kPostureCsvFormat);
    const std::vector<FieldSource> fields = {
        {"robot_path", "--robot"},   {"postures_path", "--postures"}, {"measured_files", "--measured"},
        {"pose_files", "--pose"},    {"validate_pose_files", "--validate-pose"}, {"frees", "--free"},
        {"only_free", "--only-free"}, {"sets", "--set"}, {"adds", "--add"}, {"objective", "--objective"},
        {"max_iterations", "--max-iterations"}, {"robust_loss_sigma", "--robust-loss-sigma"}, {"min_snr", "--min-snr"},
        {"fmin_hz", "--fmin-hz"}, {"fmax_hz", "--fmax-hz"}};
    FromFields(fields, [&] { o.Validate(); });  // the option values, with the options' names
    {
      std::vector<std::pair<std::string, std::string>> inputs = {{"--robot", o.robot_path},
                                                                 {"--postures", o.postures_path}};
      for (const auto& f : o.measured_files) inputs.emplace_back("--measured", f);
      for (const auto& f : o.validate_files) inputs.emplace_back("--validate", f);
      for (const auto& f : o.pose_files) inputs.emplace_back("--pose", f.substr(f.find('=') + 1));
      for (const auto& f : o.validate_pose_files) inputs.emplace_back("--validate-pose", f.substr(f.find('=') + 1));
      CheckDistinctPaths(inputs, {{"--out", o.out_path}, {"--summary", summary_path}, {"--uncertainty-out", uncertainty_path}},
                         {{"--report", report_dir}});
    }
    o.noise = noise_opt.Workflow();
    const workflows::FrfCalibrateRun run =
        FromNoiseFields(noise_opt, fields, [&] { return workflows::RunFrfCalibrate(o, MessagePrinter(kTool)); });

    // Outputs: each complete or absent (docs/formats.md §4).
    io::WriteFileAtomically(o.out_path, run.config_text);
    io::EnsureDirectory(report_dir);
    const fs::path dir(report_dir);
    std::vector<report::TableSet> sets_out = {{"fit", &run.features, run.fit_before, run.fit_after}};
    if (!run.holdout.empty()) {
      sets_out.push_back({"holdout", &run.holdout_features, run.holdout_before, run.holdout_after});
    }
    report::WriteTable3Csv((dir / "table3.csv").string(), sets_out);
    report::WriteTable3Markdown((dir / "table3.md").string(), sets_out,
                                "frf-calibrate: " + o.robot_path + " against the measured FRFs");
    std::vector<std::string> flags = run.flags;
    nlohmann::json summary = report::FrfCalibrateSummaryJson(run.result, run.options, sets_out, run.Misfit(), run.noise,
                                                             run.holdout_noise, noise_opt.model, noise_opt.min_snr,
                                                             o.robot_path);
    summary["calibrated_config"] = o.out_path;
    {
      std::string source = std::string(kTool) + " of " + o.robot_path + " on";
      for (const auto& f : o.measured_files) source += " " + f;
      for (const auto& f : o.pose_files) source += " " + f;
      summary["uncertainty_out"] = WriteFittedUncertainty(kTool, uncertainty_path, run.result, source);
      // Asked for and not written: a flag (exit 3), in the summary's flags too.
      if (summary["uncertainty_out"].contains("warning")) {
        flags.push_back(summary["uncertainty_out"]["warning"]);
        summary["misfit"]["flags"] = flags;
      }
    }
    io::WriteFileAtomically((dir / "summary.json").string(), SummaryText(summary));
    dynamics::PostureEvaluator eb(run.model_before), ea(run.model_after);
    std::vector<std::string> ids = run.all_measured.pose_ids();
    for (const std::string& pose : run.holdout.pose_ids()) ids.push_back(pose);
    const std::map<std::string, std::string> stems = FileStemsForIds(kTool, "--report", ids);
    for (const std::string& pose : run.all_measured.pose_ids()) {
      const bool held = !run.measured_read.frfs.ForPose(pose).size();
      const auto db = eb.Evaluate(run.postures.at(pose));
      const auto da = ea.Evaluate(run.postures.at(pose));
      report::PostureOverlay overlay = report::MakePostureOverlay(pose, run.all_measured, db, da);
      report::AddNoise(run.all_noise, &overlay);
      report::WriteOverlayPng((dir / (stems.at(pose) + ".png")).string(), overlay,
                              "frf-calibrate: posture " + pose + (held ? " (held out)" : "") +
                                  ", measured vs model before and after calibration");
    }
    for (const std::string& pose : run.measured.pose_ids()) {
      report::WriteStabilisationPng((dir / ("stabilisation_" + stems.at(pose) + ".png")).string(), pose, run.features);
    }
    for (const std::string& pose : run.holdout.pose_ids()) {
      if (run.measured.ForPose(pose).empty()) {
        report::WriteStabilisationPng((dir / ("stabilisation_" + stems.at(pose) + ".png")).string(), pose,
                                      run.holdout_features);
      }
    }
    if (!summary_path.empty()) io::WriteFileAtomically(summary_path, SummaryText(summary));
    // Matching, estimates and misfit on stderr, briefly.
    for (const std::string& line : run.ResultLines()) std::cerr << kTool << ": " << line << '\n';
    return flags.empty() ? kExitOk : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
