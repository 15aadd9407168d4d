// frf-calibrate: calibrates named model parameters (default m6, d6, alpha,
// beta) against measured tool-tip FRFs (CSV or UFF58) and writes the
// calibrated robot config and a report folder.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <sstream>

#include "cli_support.h"
#include "measured_data.h"
#include "robomach/common/errors.h"
#include "robomach/calibration/frf_calibration.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/report/calibration_report.h"
#include "robomach/report/json.h"

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
  std::string robot_path, postures_path, out_path, report_dir, summary_path, uncertainty_path,
      objective = "modal-two-stage";
  std::vector<std::string> measured_files, pose_files, validate_files, validate_pose_files, frees, sets, adds;
  bool only_free = false;
  calibration::CalibrationOptions opt;
  app.add_option("--robot", robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--postures", postures_path, "posture file CSV: pose_id,q1_deg..q6_deg")->required();
  app.add_option("--measured", measured_files, "measured FRFs, CSV or UFF58 (.uff/.unv); repeatable");
  app.add_option("--pose", pose_files, "a UFF58 file of one posture whose records lack pose=ID: ID=file.uff; repeatable");
  app.add_option("--out", out_path, "calibrated robot config YAML; '-' = stdout")->required();
  app.add_option("--report", report_dir, "report folder (created)")->required();
  app.add_option("--summary", summary_path, "also write the report's summary.json here ('-' = stdout)");
  app.add_option("--uncertainty-out", uncertainty_path,
                 "write the fitted parameters' estimates and covariance here (docs/formats.md §12), for "
                 "frf-predict, stability-lobes and stability-map --uncertainty");
  app.add_option("--validate", validate_files, "held-out measured FRFs scored with the calibrated model; repeatable");
  app.add_option("--validate-pose", validate_pose_files, "held-out UFF58 file of one posture: ID=file.uff; repeatable");
  app.add_option("--free", frees, "also fit this parameter (any name of the model, e.g. kq2_Nm_per_rad); repeatable");
  app.add_flag("--only-free", only_free, "fit only the --free parameters, not the default m6_kg, d6_m, alpha_s, beta_per_s");
  app.add_option("--robust-loss-sigma", opt.robust_scale,
                 "Huber loss per line on the whole-curve objective, its scale in units of the noise (e.g. 3); 0: "
                 "plain least squares. A second line of defence against outlier lines the noise model kept")
      ->capture_default_str();
  app.add_option("--objective", objective, "modal-two-stage (frequencies, then peak amplitudes), modal-joint, whole-curve")
      ->check(OneOf({"modal-two-stage", "modal-joint", "whole-curve"}))->capture_default_str();
  app.add_option("--fmin-hz", opt.fmin_hz, "lowest frequency used (modal fit and whole curve) [Hz]")->capture_default_str();
  app.add_option("--fmax-hz", opt.fmax_hz, "highest frequency used [Hz]; default: all lines");
  app.add_option("--set", sets, "start value of a parameter, NAME=VALUE in its unit");
  app.add_option("--add", adds, "switch on an effect by name (its parameters may then be --free)");
  app.add_option("--max-iterations", opt.max_iterations, "solver iterations per stage")->capture_default_str();
  NoiseCliOptions noise_opt;
  AddNoiseOptions(app, &noise_opt);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    RequireFolderOption("--report", report_dir);
    RequireInputFile("--robot", robot_path, "robot config", {io::FileKind::kYaml}, io::kRobotConfigFormat);
    RequireInputFile("--postures", postures_path, "posture file", {io::FileKind::kCsv}, io::kPostureCsvFormat);
    CheckOptionRange("--max-iterations", opt.max_iterations, 1, 100000);
    CheckOptionRange("--robust-loss-sigma", opt.robust_scale, 0.0, 1e6);
    {
      std::vector<std::pair<std::string, std::string>> inputs = {{"--robot", robot_path},
                                                                 {"--postures", postures_path}};
      for (const auto& f : measured_files) inputs.emplace_back("--measured", f);
      for (const auto& f : validate_files) inputs.emplace_back("--validate", f);
      for (const auto& f : pose_files) inputs.emplace_back("--pose", f.substr(f.find('=') + 1));
      for (const auto& f : validate_pose_files) inputs.emplace_back("--validate-pose", f.substr(f.find('=') + 1));
      CheckDistinctPaths(inputs, {{"--out", out_path}, {"--summary", summary_path}, {"--uncertainty-out", uncertainty_path}},
                         {{"--report", report_dir}});
    }
    if (measured_files.empty() && pose_files.empty()) {
      throw UsageError("no measured FRFs: give --measured FILE or --pose ID=file.uff");
    }
    opt.objective = calibration::ParseObjective(objective);
    if (only_free) opt.free_parameters.clear();
    for (const std::string& f : frees) {
      if (std::find(opt.free_parameters.begin(), opt.free_parameters.end(), f) == opt.free_parameters.end()) {
        opt.free_parameters.push_back(f);
      }
    }
    if (opt.free_parameters.empty()) throw UsageError("no free parameters (--only-free without --free)");
    opt.modal_fit.fmin_hz = opt.fmin_hz;
    opt.modal_fit.fmax_hz = opt.fmax_hz;

    io::RobotConfig cfg = LoadRobotConfigWarned(kTool, robot_path);
    ApplyAddsAndSets(adds, sets, &cfg);
    for (const std::string& name : opt.free_parameters) {
      if (!cfg.parameters.Has(name)) {
        throw UsageError("--free " + name + ": unknown parameter; known: " + cfg.parameters.NameList());
      }
    }
    const auto model_before = cfg.Build();
    calibration::PostureMap postures;
    std::map<std::string, int> posture_line;
    std::vector<std::string> posture_units;  // radians under _deg headers, ...
    for (const io::Posture& p : io::ReadPostureFile(postures_path, model_before->num_joints(), &posture_units)) {
      postures[p.id] = p.q;
      posture_line[p.id] = p.line;
    }
    const MeasuredData measured_read = ReadMeasuredFiles(kTool, measured_files, pose_files, "measured FRF file");
    const MeasuredData holdout_read =
        ReadMeasuredFiles(kTool, validate_files, validate_pose_files, "validation FRF file", "--validate-pose");
    for (const auto* set : {&measured_read.frfs, &holdout_read.frfs}) {
      for (const std::string& id : set->pose_ids()) {
        if (!postures.count(id)) {
          std::string known;
          for (const auto& [k, q] : postures) known += (known.empty() ? "" : ", ") + k;
          throw InputError({postures_path, 0, 0}, "posture " + id + " of the " +
                                                      (set == &measured_read.frfs ? "measured" : "validation") +
                                                      " FRFs is not in this posture file (it has " + known + ")");
        }
      }
    }
    // The noise of every FRF, and the lines every fit uses (issue #10).
    const calibration::NoiseModels noise = EstimateNoiseModels(kTool, measured_read, noise_opt);
    const dynamics::FrfSet measured = FitData(measured_read, noise);
    calibration::NoiseModels holdout_noise;
    dynamics::FrfSet holdout;
    if (!holdout_read.frfs.empty()) {
      holdout_noise = EstimateNoiseModels(kTool, holdout_read, noise_opt);
      holdout = FitData(holdout_read, holdout_noise);
    }

    std::cerr << kTool << ": modal fit of " << measured.size() << " measured FRFs\n";
    const calibration::MeasuredFeatures features = calibration::ExtractFeatures(measured, opt.modal_fit);
    for (const auto& [key, fit] : features.fits) {
      if (fit.status != calibration::ModalFitStatus::kOk) {
        Warn(kTool, "modal fit of " + key.ToString() + ": " + fit.message);
      }
    }
    std::cerr << kTool << ": calibrating (" << calibration::ObjectiveName(opt.objective) << ") ";
    for (const auto& n : opt.free_parameters) std::cerr << n << ' ';
    std::cerr << '\n';
    const calibration::CalibrationResult result =
        calibration::Calibrate(cfg.description, cfg.parameters, postures, measured, features, opt);
    const auto model_after = dynamics::RobotModel::Build(cfg.description, result.parameters);

    std::vector<report::TableSet> sets_out;
    report::TableSet fit_set;
    fit_set.label = "fit";
    fit_set.features = &features;
    fit_set.before = calibration::CompareWithMeasurement(model_before, postures, measured, features, opt.matching,
                                                         opt.fmin_hz, opt.fmax_hz);
    fit_set.after = calibration::CompareWithMeasurement(model_after, postures, measured, features, opt.matching,
                                                        opt.fmin_hz, opt.fmax_hz);
    sets_out.push_back(fit_set);
    calibration::MeasuredFeatures holdout_features;
    if (!holdout.empty()) {
      holdout_features = calibration::ExtractFeatures(holdout, opt.modal_fit);
      report::TableSet h;
      h.label = "holdout";
      h.features = &holdout_features;
      h.before = calibration::CompareWithMeasurement(model_before, postures, holdout, holdout_features,
                                                     opt.matching, opt.fmin_hz, opt.fmax_hz);
      h.after = calibration::CompareWithMeasurement(model_after, postures, holdout, holdout_features, opt.matching,
                                                    opt.fmin_hz, opt.fmax_hz);
      sets_out.push_back(h);
    }

    // Outputs: each complete or absent (docs/formats.md §4).
    bool effects_left_out = false;
    const std::string config_text = io::CalibratedConfigText(
        robot_path, out_path, io::ParametersYaml(result.parameters, dynamics::DefaultParameters(cfg.description)),
        adds, &effects_left_out);
    if (effects_left_out) {
      Warn(kTool, "the config already has an `effects:` list; add the effects given with --add to " + out_path +
                      " by hand");
    }
    io::WriteFileAtomically(out_path, config_text);
    io::EnsureDirectory(report_dir);
    const fs::path dir(report_dir);
    report::WriteTable3Csv((dir / "table3.csv").string(), sets_out);
    report::WriteTable3Markdown((dir / "table3.md").string(), sets_out,
                                "frf-calibrate: " + robot_path + " against the measured FRFs");
    const calibration::CalibrationVerdict verdict = calibration::JudgeCalibration(result, measured, opt);
    std::vector<std::string> flags = measured_read.unit_findings;  // implausible units, warned when read
    flags.insert(flags.end(), holdout_read.unit_findings.begin(), holdout_read.unit_findings.end());
    flags.insert(flags.end(), cfg.implausible.begin(), cfg.implausible.end());  // warned when read
    for (const std::string& w : posture_units) {
      Warn(kTool, w);
      flags.push_back(w);
    }
    for (const Finding& f : verdict.findings) {
      Warn(kTool, f.message);
      flags.push_back(f.message);
    }
    nlohmann::json summary = report::CalibrationSummaryJson(result, opt, sets_out);
    summary["misfit"] = {{"start", result.misfit_start},
                         {"calibrated", result.misfit_final},
                         {"rms_per_residual_in_noise_units", verdict.rms_per_residual_in_noise_units},
                         {"starts_tried", result.starts_tried},
                         {"start_used", result.start_used},
                         {"flags", flags}};
    summary["noise"] = report::NoiseSummaryJson(noise, noise_opt.model, noise_opt.min_snr);
    if (!holdout_noise.empty()) summary["holdout_noise"] = report::NoiseSummaryJson(holdout_noise, noise_opt.model, noise_opt.min_snr);
    summary["robot"] = robot_path;
    summary["calibrated_config"] = out_path;
    {
      std::string source = std::string(kTool) + " of " + robot_path + " on";
      for (const auto& f : measured_files) source += " " + f;
      for (const auto& f : pose_files) source += " " + f;
      summary["uncertainty_out"] = WriteFittedUncertainty(kTool, uncertainty_path, result, source);
      // Asked for and not written: a flag (exit 3), in the summary's flags too.
      if (summary["uncertainty_out"].contains("warning")) {
        flags.push_back(summary["uncertainty_out"]["warning"]);
        summary["misfit"]["flags"] = flags;
      }
    }
    io::WriteFileAtomically((dir / "summary.json").string(), SummaryText(summary));
    dynamics::PostureEvaluator eb(model_before), ea(model_after);
    // Overlays show every measured line with the noise model, not only the usable ones.
    dynamics::FrfSet all = measured_read.frfs;
    calibration::NoiseModels all_noise = noise;
    for (const auto& [k, f] : holdout_read.frfs) {
      if (!all.contains(k)) all.Insert(k, f);
    }
    for (const auto& [k, n] : holdout_noise) all_noise.emplace(k, n);
    std::vector<std::string> ids = all.pose_ids();
    for (const std::string& pose : holdout.pose_ids()) ids.push_back(pose);
    const std::map<std::string, std::string> stems = FileStemsForIds(kTool, "--report", ids);
    for (const std::string& pose : all.pose_ids()) {
      const auto db = eb.Evaluate(postures.at(pose));
      const auto da = ea.Evaluate(postures.at(pose));
      const bool held = !measured_read.frfs.ForPose(pose).size();
      report::PostureOverlay overlay = report::MakePostureOverlay(pose, all, db, da);
      report::AddNoise(all_noise, &overlay);
      report::WriteOverlayPng((dir / (stems.at(pose) + ".png")).string(), overlay,
                              "frf-calibrate: posture " + pose + (held ? " (held out)" : "") +
                                  ", measured vs model before and after calibration");
    }
    for (const std::string& pose : measured.pose_ids()) {
      report::WriteStabilisationPng((dir / ("stabilisation_" + stems.at(pose) + ".png")).string(), pose, features);
    }
    for (const std::string& pose : holdout.pose_ids()) {
      if (measured.ForPose(pose).empty()) {
        report::WriteStabilisationPng((dir / ("stabilisation_" + stems.at(pose) + ".png")).string(), pose,
                                      holdout_features);
      }
    }
    if (!summary_path.empty()) io::WriteFileAtomically(summary_path, SummaryText(summary));
    // Matching and errors on stderr, briefly.
    for (const auto& s : sets_out) {
      std::ostringstream m;
      m.precision(3);
      m << kTool << ": " << s.label << ": " << s.after.matches.size()
        << " matched modes; largest error after calibration: frequency " << 100 * s.after.max_abs_freq_error
        << " %, peak amplitude " << 100 * s.after.max_abs_peak_error << " % (before: "
        << 100 * s.before.max_abs_freq_error << " %, " << 100 * s.before.max_abs_peak_error << " %)\n";
      std::cerr << m.str();
    }
    for (const auto& e : result.estimates) {
      std::ostringstream m;
      m.precision(6);
      m << kTool << ": " << e.name << " = " << e.value << " ± " << e.std_dev << " " << e.unit << " (start "
        << e.initial << ")" << (e.weakly_identified ? " WEAKLY IDENTIFIED" : "") << (e.at_bound ? " AT BOUND" : "")
        << '\n';
      std::cerr << m.str();
    }
    {
      std::ostringstream m;
      m.precision(4);
      m << kTool << ": whole-curve misfit (chi^2";
      if (!noise.empty()) m << ", in units of the noise";
      m << ") " << result.misfit_start << " at the start, " << result.misfit_final << " calibrated ("
        << result.starts_tried << " start" << (result.starts_tried > 1 ? "s" : "") << ", result from: "
        << result.start_used << ")\n";
      std::cerr << m.str();
    }
    return flags.empty() ? kExitOk : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
