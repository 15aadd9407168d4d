// model-audit: compares a calibrated model with measured tool-tip FRFs,
// shows where it fails, ranks the library effects that could explain the
// failure and writes the YAML lines that add the best one (issue #5).
#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <set>

#include "cli_support.h"
#include "measured_data.h"
#include "robomach/audit/model_audit.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/dynamics/effect.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/report/audit_report.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "model-audit";
namespace fs = std::filesystem;
using nlohmann::json;

json ReadPreviousSummary(const std::string& dir) {
  const std::string path = (fs::path(dir) / "summary.json").string();
  RequireReadableFile(path, "--compare summary");
  std::ifstream in(path);
  try {
    json j = json::parse(in);
    if (!j.contains("error_before") || !j.contains("postures")) {
      throw InputError({path, 1, 0}, "not a model-audit summary (no error_before/postures keys)");
    }
    return j;
  } catch (const json::parse_error& e) {
    throw InputError({path, 0, 0}, std::string("invalid JSON: ") + e.what());
  }
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
  std::string robot_path, postures_path, report_dir, compare_dir, candidates_list, summary_path, write_config,
      uncertainty_out;
  std::vector<std::string> measured_files, pose_files, adds, uncertainty_paths;
  audit::AuditOptions opt;
  app.add_option("--robot", robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--postures", postures_path, "posture file CSV: pose_id,q1_deg..q6_deg")->required();
  app.add_option("--measured", measured_files, "measured FRFs, CSV or UFF58 (.uff/.unv/.ufb); repeatable");
  app.add_option("--pose", pose_files, "a UFF58 file of one posture whose records lack pose=ID: ID=file.uff; repeatable");
  app.add_option("--report", report_dir, "report folder (created)")->required();
  app.add_option("--summary", summary_path, "also write the report's summary.json here ('-' = stdout, after the effects YAML)");
  app.add_option("--add", adds, "switch on an effect before the audit (e.g. the winner of a previous one); its fittable parameters are calibrated too; repeatable");
  app.add_option("--compare", compare_dir, "a previous audit's report folder: its errors are shown next to these");
  app.add_option("--write-config", write_config,
                 "write the robot config with the named change: the effect (or the parameters found off) and every "
                 "calibration value fitted with it; with no failure, the calibrated current model; with no named "
                 "change, nothing (a warning says so). Loadable by every tool");
  app.add_option("--uncertainty", uncertainty_paths,
                 "parameter-uncertainty YAML (docs/formats.md §12, e.g. kq-identify --uncertainty-out); repeatable; "
                 "default: the files the robot config names (uncertainty:). Their estimates replace the config's "
                 "values, and the verdict says which part of the misfit those parameters could explain within their "
                 "confidence region (a misfit they cover is not evidence of a missing effect)");
  app.add_option("--confidence", opt.uncertainty_confidence, "confidence level of that region, in (0, 1)")
      ->capture_default_str();
  app.add_option("--uncertainty-out", uncertainty_out,
                 "write the parameters fitted with the named change (with no failure: the calibration's) and their "
                 "covariance here (docs/formats.md §12), for the predicting tools' --uncertainty");
  bool no_parameters = false;
  app.add_flag("--no-parameter-hypotheses", no_parameters,
               "do not try freeing the model's joint stiffnesses (kq1..kqn) as explanations");
  int virtual_joints = opt.virtual_joints_fitted;
  app.add_option("--virtual-joints", virtual_joints,
                 "how many of the best virtual joints (compliance along the chain) to fit after the screen; 0: none")
      ->capture_default_str();
  app.add_option("--candidates", candidates_list,
                 "comma-separated candidates, the whole list: effects (virtual_joint_<place>_<axis> too) and joint "
                 "stiffnesses (kq2_Nm_per_rad); default: every library effect not in the model, every joint stiffness "
                 "and the virtual-joint screen");
  app.add_option("--fmin-hz", opt.fmin_hz, "lowest frequency used [Hz]")->capture_default_str();
  app.add_option("--fmax-hz", opt.fmax_hz, "highest frequency used [Hz]; default: all lines");
  app.add_option("--max-iterations", opt.max_iterations, "solver iterations per fit")->capture_default_str();
  app.add_option("--robust-loss-sigma", opt.robust_scale,
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
    RequireReadableFile(robot_path, "robot config");
    RequireReadableFile(postures_path, "posture file");
    // Option values, with the options' names (before minutes of fitting).
    CheckOptionRange("--fmin-hz", opt.fmin_hz, 0.0, 1e9);
    if (!(opt.fmax_hz > opt.fmin_hz)) {
      throw UsageError("--fmax-hz must be above --fmin-hz (" + FormatNumber(opt.fmin_hz) + " Hz), got " +
                       FormatNumber(opt.fmax_hz));
    }
    CheckOptionRange("--max-iterations", opt.max_iterations, 1, 100000);
    CheckOptionRange("--virtual-joints", virtual_joints, 0, 50);
    CheckOptionRange("--robust-loss-sigma", opt.robust_scale, 0.0, 1e6);
    if (!(opt.uncertainty_confidence > 0.0 && opt.uncertainty_confidence < 1.0)) {
      throw UsageError("--confidence: expected a level between 0 and 1 (0.95 for 95 %), got " +
                       FormatNumber(opt.uncertainty_confidence));
    }
    for (const std::string& p : uncertainty_paths) {
      RequireInputFile("--uncertainty", p, "parameter-uncertainty file", {io::FileKind::kYaml},
                       io::kUncertaintyFileFormat);
    }
    opt.virtual_joints_fitted = virtual_joints;
    opt.try_parameters = !no_parameters;
    {
      std::set<std::string> seen;
      for (const std::string& a : adds) {
        if (!seen.insert(a).second) throw UsageError("--add " + a + " is given twice");
      }
    }
    RequireFolderOption("--report", report_dir);
    if (!write_config.empty()) {
      // Before minutes of fitting: the written config's folder must exist.
      const fs::path parent = fs::path(write_config).parent_path();
      if (!parent.empty() && !fs::is_directory(parent)) {
        throw UsageError("--write-config " + write_config + ": the folder " + parent.string() + " does not exist");
      }
    }
    RequireFolderOption("--compare", compare_dir);
    {
      std::vector<std::pair<std::string, std::string>> inputs = {{"--robot", robot_path},
                                                                  {"--postures", postures_path}};
      for (const auto& f : measured_files) inputs.push_back({"--measured", f});
      for (const auto& f : pose_files) inputs.push_back({"--pose", f.substr(f.find('=') + 1)});
      for (const auto& f : uncertainty_paths) inputs.push_back({"--uncertainty", f});
      CheckDistinctPaths(inputs,
                         {{"--summary", summary_path}, {"--write-config", write_config},
                          {"--uncertainty-out", uncertainty_out}},
                         {{"--report", report_dir}});
    }
    if (measured_files.empty() && pose_files.empty()) {
      throw UsageError("no measured FRFs: give --measured FILE or --pose ID=file.uff");
    }
    std::stringstream cl(candidates_list);
    for (std::string n; std::getline(cl, n, ',');) {
      if (n.empty()) continue;
      const bool is_parameter = n.rfind("kq", 0) == 0 && n.find('.') == std::string::npos;
      if (!is_parameter) FromOption("--candidates", [&] { dynamics::EffectRegistry::Instance().Create(n); });
      opt.candidates.push_back(n);
    }
    opt.progress = [](const std::string& s) { std::cerr << kTool << ": " << s << '\n'; };
    json previous;
    if (!compare_dir.empty()) previous = ReadPreviousSummary(compare_dir);

    io::RobotConfig cfg = LoadRobotConfigWarned(kTool, robot_path);
    for (const std::string& name : adds) {
      std::tie(cfg.description, cfg.parameters) =
          FromOption("--add " + name, [&] { return audit::WithEffect(cfg.description, cfg.parameters, name); });
      // An effect switched on here starts at its defaults, so its fittable
      // parameters are calibrated with the others.
      for (const auto& spec : cfg.parameters.specs()) {
        if (spec.fittable && spec.name.rfind(name + ".", 0) == 0) opt.calibration_parameters.push_back(spec.name);
      }
    }
    {
      // The parameters' uncertainty (issue #37 §4), its estimates the audited values.
      const std::vector<std::string>& paths = uncertainty_paths.empty() ? cfg.uncertainty_files : uncertainty_paths;
      if (!paths.empty()) {
        opt.parameter_uncertainty = io::ReadParameterUncertainties(paths);
        const std::string changed = FromOption("--uncertainty", [&] {
          return dynamics::UseEstimates(opt.parameter_uncertainty, &cfg.parameters);
        });
        if (!changed.empty()) Note(kTool, changed);
      }
    }
    calibration::PostureMap postures;
    for (const io::Posture& p : io::ReadPostureFile(postures_path, cfg.description.arm.num_joints())) {
      postures[p.id] = p.q;
    }
    const MeasuredData measured_read = ReadMeasuredFiles(kTool, measured_files, pose_files, "measured FRF file");
    for (const auto& [key, frf] : measured_read.frfs) {
      if (!postures.count(key.pose_id)) {
        throw InputError({postures_path, 0, 0}, "posture " + key.pose_id + " of " + measured_read.file.at(key) +
                                                    " is not in this posture file");
      }
    }
    // The noise of every FRF and the lines every fit and error uses (issue #10).
    const calibration::NoiseModels noise = EstimateNoiseModels(kTool, measured_read, noise_opt);
    const dynamics::FrfSet measured = FitData(measured_read, noise);
    if (measured.empty()) {
      // Every FRF read, none with a usable line under the noise model.
      const std::string first = measured_read.file.begin()->second;
      throw InputError({first, 0, 0}, "no measured FRF has a usable line (the noise model found none above the "
                                      "noise floor; see --min-snr and docs/noise-model.md)");
    }
    {
      int lines = 0;
      for (const auto& [key, frf] : measured) lines += frf.Band(opt.fmin_hz, opt.fmax_hz).size();
      if (lines < 3) {
        throw InputError({measured_read.file.begin()->second, 0, 0},
                         "the measured FRFs have " + std::to_string(lines) + " lines in the band " +
                             FormatNumber(opt.fmin_hz) + ".." + FormatNumber(opt.fmax_hz) + " Hz (--fmin-hz, --fmax-hz); need at least 3");
      }
    }

    const audit::AuditResult r = audit::RunAudit(cfg.description, cfg.parameters, postures, measured, opt);
    if (r.baseline_fit.status != calibration::FitStatus::kConverged) {
      Warn(kTool, "the calibration of the current model did not converge (" + r.baseline_fit.message +
                      "); its errors are those of the last iterate");
    }
    report::AuditReportOptions ro;
    ro.robot_path = robot_path;
    ro.added_effects = adds;
    ro.noise_model = noise_opt.model;
    ro.min_snr = noise_opt.min_snr;
    ro.fmin_hz = opt.fmin_hz;
    ro.fmax_hz = opt.fmax_hz;
    ro.mostly_explained_fraction = opt.mostly_explained_fraction;
    ro.clear_bic_gap = opt.clear_bic_gap;
    ro.previous = previous;
    ro.compare_dir = compare_dir;
    ro.progress = opt.progress;
    // The config with the named change (issue #33 §6): built and checked
    // (loaded back) before anything is written.
    std::string config_text;
    // The change the audit names (--write-config and --uncertainty-out):
    // the named candidate, or with no failure the calibrated current model.
    const audit::CandidateResult* named =
        r.grade == audit::AuditGrade::kExplained || r.grade == audit::AuditGrade::kMostlyExplained
            ? audit::AcceptedCandidate(r)
            : nullptr;
    const bool has_change = named || r.grade == audit::AuditGrade::kNoFailure;
    if (!write_config.empty()) {
      if (has_change) {
        audit::CandidateResult change;
        if (named) {
          change = *named;
        } else {
          change.fit = r.baseline_fit;  // no failure: the calibrated current model
        }
        const auto [desc, params] = audit::CandidateModel(cfg.description, change);
        std::vector<std::string> effects = adds;
        for (const std::string& e : change.effects) effects.push_back(e);
        bool left_out = false;
        config_text = io::CalibratedConfigText(
            robot_path, write_config, io::ParametersYaml(params, dynamics::DefaultParameters(desc)), effects, &left_out,
            "Written by robomach model-audit --write-config: " +
                (named ? audit::DescribeCandidate(*named, r.configured) : std::string("the calibrated current model")) +
                ", with the calibration values fitted with it.");
        if (left_out) {
          Warn(kTool, "the config's `effects:` list is a flow list; add " + [&] {
            std::string l;
            for (const auto& e : effects) l += (l.empty() ? "" : ", ") + e;
            return l;
          }() + " to " + write_config + " by hand");
        }
        ro.written_config = write_config;
      } else {
        Warn(kTool, "--write-config " + write_config + " not written: the audit names no change (" +
                        audit::AuditGradeName(r.grade) + ")");
      }
    }
    bool uncertainty_not_written = false;  // asked for and not written: exit 3
    if (!uncertainty_out.empty()) {
      if (has_change) {
        ro.uncertainty_out = WriteFittedUncertainty(
            kTool, uncertainty_out, named ? named->fit : r.baseline_fit,
            std::string(kTool) + " of " + robot_path + ": " +
                (named ? audit::DescribeCandidate(*named, r.configured) : std::string("the calibrated current model")));
      } else {
        Warn(kTool, "--uncertainty-out " + uncertainty_out + " not written: the audit names no change (" +
                        audit::AuditGradeName(r.grade) + ")");
      }
      uncertainty_not_written = ro.uncertainty_out.is_null() || ro.uncertainty_out.contains("warning");
    }
    for (const audit::BoundFlag& f : r.baseline_on_bound) Warn(kTool, f.message);
    ro.input_warnings = WarningsGiven();
    FileStemsForIds(kTool, "--report", measured.pose_ids());  // notes: the overlays' file names
    const report::AuditReport rep = report::WriteAuditReport(report_dir, r, cfg.description, postures, measured,
                                                             measured_read.frfs, noise, ro);
    const json& j = rep.summary;
    const std::string& yaml = rep.effects_yaml;
    if (!summary_path.empty() && summary_path != "-") io::WriteFileAtomically(summary_path, report::DumpJson(j));
    if (!config_text.empty()) io::WriteFileAtomically(write_config, config_text);

    std::cerr << kTool << ": " << r.verdict << '\n';  // always; a finding when unexplained
    const RunFindings verdict = audit::JudgeAudit(r);
    for (const Finding& f : verdict.findings) {
      if (f.message != r.verdict) Warn(kTool, f.message);
    }
    io::WriteFileAtomically("-", yaml);
    if (summary_path == "-") io::WriteFileAtomically("-", report::DumpJson(j));
    // measured_read.unit_findings: receptances outside the plausible range, warned when read.
    return verdict.flagged() || uncertainty_not_written || !measured_read.unit_findings.empty() ||
                   !cfg.implausible.empty()
               ? kExitFlagged
               : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
