// model-audit: compares a calibrated model with measured tool-tip FRFs,
// shows where it fails, ranks the library effects that could explain the
// failure and writes the YAML lines that add the best one (issue #5).
#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli_support.h"
#include "measured_data.h"
#include "robomach/common/errors.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/report/audit_report.h"
#include "robomach/report/json.h"
#include "robomach/workflows/model_audit.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "model-audit";
namespace fs = std::filesystem;
using nlohmann::json;

json ReadPreviousSummary(const std::string& dir) {
  const std::string path = (fs::path(dir) / "summary.json").string();
  RequireReadableFile(path, "--compare summary");
  std::ifstream in(path);
  json j = AtLocation<json::parse_error>({path, 0, 0}, "invalid JSON: ", [&] { return json::parse(in); });
  if (!j.contains("error_before") || !j.contains("postures")) {
    throw InputError({path, 1, 0}, "not a model-audit summary (no error_before/postures keys)");
  }
  return j;
}

int Run(int argc, char** argv) {
  CLI::App app{
      "model-audit: where a robot model fails against measured tool-tip FRFs, and which physical effect\n"
      "of the library is missing. Calibrates the model (whole curve), reports the rms log-magnitude error\n"
      "per posture and direction with its worst bands, the per-mode errors and a noise-floor estimate; if\n"
      "the failure is significant, frees each joint stiffness (and the best pairs), screens an elastic virtual\n"
      "joint at every place and axis of the chain and fits the best, adds each library effect not in the model,\n"
      "fits each with the calibration parameters and ranks the candidates by BIC (greedily a second effect). A\n"
      "joint stiffness that explains the data is named as a parameter that is off. Also reports the trends of the\n"
      "error against posture descriptors, an error map of postures against modes, and modes without a\n"
      "counterpart either way. Writes REPORT/summary.json, index.html, errors.csv, candidates.csv,\n"
      "trends.csv, posture_descriptors.csv, mode_errors.csv, unmatched_modes.csv, trends.png,\n"
      "mode_error_map.png, worst_frf.png, overlay_<pose>.png and (with an accepted or named candidate)\n"
      "effects.yaml. The verdict is graded: no failure; explained (the named effect brings the error\n"
      "within 1.3 x the noise); mostly explained (the named effect removes at least 80 % of the error\n"
      "above the noise and is ahead of every alternative with as many effects or fewer by a BIC gap\n"
      "above 10); or unexplained."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             " Exit 3 when the failure is significant and not explained within the noise: unexplained, or mostly "
             "explained (the effect is named and effects.yaml written, but a misfit remains), or a fit failed (the "
             "report is complete; candidates.csv says which and why), or a measured receptance is outside 1e-12..1e-3 "
             "m/N (a unit mistake), or --uncertainty has nothing the audit can move, or --uncertainty-out was asked "
             "for and not written (no named change).");
  std::string report_dir, compare_dir, candidates_list, summary_path, uncertainty_out;
  workflows::ModelAuditOptions o;
  o.pose_files_name = "--pose";
  app.add_option("--robot", o.robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--postures", o.postures_path, "posture file CSV: pose_id,q1_deg..q6_deg")->required();
  app.add_option("--measured", o.measured_files, "measured FRFs, CSV or UFF58 (.uff/.unv/.ufb); repeatable");
  app.add_option("--pose", o.pose_files, "a UFF58 file of one posture whose records lack pose=ID: ID=file.uff; repeatable");
  app.add_option("--report", report_dir, "report folder (created)")->required();
  app.add_option("--summary", summary_path, "also write the report's summary.json here ('-' = stdout, after the effects YAML)");
  app.add_option("--add", o.adds, "switch on an effect before the audit (e.g. the winner of a previous one); its fittable parameters are calibrated too; repeatable");
  app.add_option("--compare", compare_dir, "a previous audit's report folder: its errors are shown next to these");
  app.add_option("--write-config", o.write_config,
                 "write the robot config with the named change: the effect (or the parameters found off) and every "
                 "calibration value fitted with it; with no failure, the calibrated current model; with no named "
                 "change, nothing (a warning says so). Loadable by every tool");
  app.add_option("--uncertainty", o.uncertainty_paths,
                 "parameter-uncertainty YAML (docs/formats.md §12, e.g. kq-identify --uncertainty-out); repeatable; "
                 "default: the files the robot config names (uncertainty:). Their estimates replace the config's "
                 "values, and the verdict says which part of the misfit those parameters could explain within their "
                 "confidence region (a misfit they cover is not evidence of a missing effect)");
  app.add_option("--confidence", o.confidence, "confidence level of that region, in (0, 1)")->capture_default_str();
  app.add_option("--uncertainty-out", uncertainty_out,
                 "write the parameters fitted with the named change (with no failure: the calibration's) and their "
                 "covariance here (docs/formats.md §12), for the predicting tools' --uncertainty");
  app.add_flag("--no-parameter-hypotheses", o.no_parameter_hypotheses,
               "do not try freeing the model's joint stiffnesses (kq1..kqn) as explanations");
  app.add_option("--virtual-joints", o.virtual_joints,
                 "how many of the best virtual joints (compliance along the chain) to fit after the screen; 0: none")
      ->capture_default_str();
  app.add_option("--candidates", candidates_list,
                 "comma-separated candidates, the whole list: effects (virtual_joint_<place>_<axis> too) and joint "
                 "stiffnesses (kq2_Nm_per_rad); default: every library effect not in the model, every joint stiffness "
                 "and the virtual-joint screen");
  app.add_option("--fmin-hz", o.fmin_hz, "lowest frequency used [Hz]")->capture_default_str();
  app.add_option("--fmax-hz", o.fmax_hz, "highest frequency used [Hz]; default: all lines");
  app.add_option("--max-iterations", o.max_iterations, "solver iterations per fit")->capture_default_str();
  app.add_option("--robust-loss-sigma", o.robust_loss_sigma,
                 "Huber loss per line in every fit, its scale in units of the noise (e.g. 3); 0: plain least squares "
                 "(errors and BIC stay plain)")
      ->capture_default_str();
  NoiseCliOptions noise_opt;
  AddNoiseOptions(app, &noise_opt);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    RequireReadableFile(o.robot_path, "robot config");
    RequireReadableFile(o.postures_path, "posture file");
    std::stringstream cl(candidates_list);
    for (std::string n; std::getline(cl, n, ',');) if (!n.empty()) o.candidates.push_back(n);
    const std::vector<FieldSource> fields = {
        {"measured_files", "--measured"}, {"pose_files", "--pose"}, {"adds", "--add"}, {"candidates", "--candidates"},
        {"fmin_hz", "--fmin-hz"}, {"fmax_hz", "--fmax-hz"}, {"max_iterations", "--max-iterations"},
        {"virtual_joints", "--virtual-joints"}, {"robust_loss_sigma", "--robust-loss-sigma"},
        {"confidence", "--confidence"}, {"uncertainty_paths", "--uncertainty"}, {"min_snr", "--min-snr"}};
    // Option values, with the options' names (before minutes of fitting).
    FromFields(fields, [&] { o.Validate(); });
    for (const std::string& p : o.uncertainty_paths) {
      RequireInputFile("--uncertainty", p, "parameter-uncertainty file", {io::FileKind::kYaml},
                       io::kUncertaintyFileFormat);
    }
    RequireFolderOption("--report", report_dir);
    // Before minutes of fitting: the written config's folder must exist.
    const fs::path parent = fs::path(o.write_config).parent_path();
    if (!parent.empty() && !fs::is_directory(parent)) {
      throw UsageError("--write-config " + o.write_config + ": the folder " + parent.string() + " does not exist");
    }
    RequireFolderOption("--compare", compare_dir);
    {
      std::vector<std::pair<std::string, std::string>> inputs = {{"--robot", o.robot_path},
                                                                  {"--postures", o.postures_path}};
      for (const auto& f : o.measured_files) inputs.push_back({"--measured", f});
      for (const auto& f : o.pose_files) inputs.push_back({"--pose", f.substr(f.find('=') + 1)});
      for (const auto& f : o.uncertainty_paths) inputs.push_back({"--uncertainty", f});
      CheckDistinctPaths(inputs, {{"--summary", summary_path}, {"--write-config", o.write_config},
                                  {"--uncertainty-out", uncertainty_out}}, {{"--report", report_dir}});
    }
    const json previous = compare_dir.empty() ? json() : ReadPreviousSummary(compare_dir);
    o.noise = noise_opt.Workflow();
    const auto progress = [](const std::string& s) { std::cerr << kTool << ": " << s << '\n'; };
    const workflows::ModelAuditRun run = FromNoiseFields(
        noise_opt, fields, [&] { return workflows::RunModelAudit(o, MessagePrinter(kTool), progress); });
    const audit::AuditResult& r = run.audit;
    report::AuditReportOptions ro{.robot_path = o.robot_path, .added_effects = o.adds, .noise_model = noise_opt.model,
                                  .min_snr = noise_opt.min_snr, .fmin_hz = o.fmin_hz, .fmax_hz = o.fmax_hz,
                                  .mostly_explained_fraction = run.audit_options.mostly_explained_fraction,
                                  .clear_bic_gap = run.audit_options.clear_bic_gap, .previous = previous,
                                  .compare_dir = compare_dir, .progress = progress};
    const std::string no_change = " not written: the audit names no change (" + audit::ToString(r.grade) + ")";
    if (!o.write_config.empty()) {
      if (run.change) ro.written_config = o.write_config;
      else Warn(kTool, "--write-config " + o.write_config + no_change);
    }
    bool uncertainty_not_written = false;  // asked for and not written: exit 3
    if (!uncertainty_out.empty()) {
      if (run.change) {
        ro.uncertainty_out = WriteFittedUncertainty(
            kTool, uncertainty_out, run.change->fit, std::string(kTool) + " of " + o.robot_path + ": " + run.change_description);
      } else {
        Warn(kTool, "--uncertainty-out " + uncertainty_out + no_change);
      }
      uncertainty_not_written = ro.uncertainty_out.is_null() || ro.uncertainty_out.contains("warning");
    }
    for (const audit::BoundFlag& f : r.baseline_on_bound) Warn(kTool, f.message);
    ro.input_warnings = WarningsGiven();
    FileStemsForIds(kTool, "--report", run.measured.pose_ids());  // notes: the overlays' file names
    const report::AuditReport rep = report::WriteAuditReport(report_dir, r, run.config.description, run.postures,
                                                             run.measured, run.measured_read.frfs, run.noise, ro);
    if (!summary_path.empty() && summary_path != "-") io::WriteFileAtomically(summary_path, report::DumpJson(rep.summary));
    if (!run.config_text.empty()) io::WriteFileAtomically(o.write_config, run.config_text);
    std::cerr << kTool << ": " << r.verdict << '\n';  // always; a finding when unexplained
    for (const Finding& f : run.verdict.findings) {
      if (f.message != r.verdict) Warn(kTool, f.message);
    }
    io::WriteFileAtomically("-", rep.effects_yaml);
    if (summary_path == "-") io::WriteFileAtomically("-", report::DumpJson(rep.summary));
    // The measured receptances' unit findings were warned when read.
    return run.flagged() || uncertainty_not_written ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
