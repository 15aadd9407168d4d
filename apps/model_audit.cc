// model-audit: compares a calibrated model with measured tool-tip FRFs,
// shows where it fails, ranks the library effects that could explain the
// failure and writes the YAML lines that add the best one (issue #5).
#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "cli_support.h"
#include "measured_data.h"
#include "robomach/audit/error_patterns.h"
#include "robomach/audit/model_audit.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/report/audit_patterns_report.h"
#include "robomach/report/calibration_report.h"
#include "robomach/report/html.h"
#include "robomach/report/posture_json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "model-audit";
namespace fs = std::filesystem;
using nlohmann::json;

std::string KeyLabel(const dynamics::FrfKey& k) {
  return k.pose_id + " " + AxisName(k.response) + AxisName(k.excitation);
}

// rms log-magnitude error per posture (audit::ErrorPerPosture), by id.
std::map<std::string, double> PerPosture(const audit::ModelErrors& e, const std::vector<std::string>& ids) {
  const Eigen::VectorXd v = audit::ErrorPerPosture(e, ids);
  std::map<std::string, double> out;
  for (size_t i = 0; i < ids.size(); ++i) out[ids[i]] = v(static_cast<Eigen::Index>(i));
  return out;
}

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
      "the failure is significant, adds each library effect not in the model, fits it with the calibration\n"
      "parameters and ranks the candidates by BIC (greedily a second one). Also reports the trends of the\n"
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
             "m/N (a unit mistake).");
  std::string robot_path, postures_path, report_dir, compare_dir, candidates_list, summary_path;
  std::vector<std::string> measured_files, pose_files, adds;
  audit::AuditOptions opt;
  app.add_option("--robot", robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--postures", postures_path, "posture file CSV: pose_id,q1_deg..q6_deg")->required();
  app.add_option("--measured", measured_files, "measured FRFs, CSV or UFF58 (.uff/.unv/.ufb); repeatable");
  app.add_option("--pose", pose_files, "a UFF58 file of one posture whose records lack pose=ID: ID=file.uff; repeatable");
  app.add_option("--report", report_dir, "report folder (created)")->required();
  app.add_option("--summary", summary_path, "also write the report's summary.json here ('-' = stdout, after the effects YAML)");
  app.add_option("--add", adds, "switch on an effect before the audit (e.g. the winner of a previous one); its fittable parameters are calibrated too; repeatable");
  app.add_option("--compare", compare_dir, "a previous audit's report folder: its errors are shown next to these");
  app.add_option("--candidates", candidates_list, "comma-separated effects to try; default: every library effect not in the model");
  app.add_option("--fmin-hz", opt.fmin_hz, "lowest frequency used [Hz]")->capture_default_str();
  app.add_option("--fmax-hz", opt.fmax_hz, "highest frequency used [Hz]; default: all lines");
  app.add_option("--max-iterations", opt.max_iterations, "solver iterations per fit")->capture_default_str();
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
    {
      std::set<std::string> seen;
      for (const std::string& a : adds) {
        if (!seen.insert(a).second) throw UsageError("--add " + a + " is given twice");
      }
    }
    RequireFolderOption("--report", report_dir);
    RequireFolderOption("--compare", compare_dir);
    if (fs::exists(report_dir) && !fs::is_directory(report_dir)) {
      throw UsageError("--report " + report_dir + " exists and is not a folder");
    }
    {
      std::vector<std::pair<std::string, std::string>> inputs = {{"--robot", robot_path},
                                                                  {"--postures", postures_path}};
      for (const auto& f : measured_files) inputs.push_back({"--measured", f});
      for (const auto& f : pose_files) inputs.push_back({"--pose", f.substr(f.find('=') + 1)});
      CheckDistinctPaths(inputs, {{"--report", report_dir}, {"--summary", summary_path}});
    }
    if (measured_files.empty() && pose_files.empty()) {
      throw UsageError("no measured FRFs: give --measured FILE or --pose ID=file.uff");
    }
    std::stringstream cl(candidates_list);
    for (std::string n; std::getline(cl, n, ',');) {
      if (n.empty()) continue;
      FromOption("--candidates", [&] { dynamics::EffectRegistry::Instance().Create(n); });
      opt.candidates.push_back(n);
    }
    opt.progress = [](const std::string& s) { std::cerr << kTool << ": " << s << '\n'; };
    json previous;
    if (!compare_dir.empty()) previous = ReadPreviousSummary(compare_dir);

    io::RobotConfig cfg = io::LoadRobotConfig(robot_path);
    for (const std::string& name : adds) {
      std::tie(cfg.description, cfg.parameters) =
          FromOption("--add " + name, [&] { return audit::WithEffect(cfg.description, cfg.parameters, name); });
      // An effect switched on here starts at its defaults, so its fittable
      // parameters are calibrated with the others.
      for (const auto& spec : cfg.parameters.specs()) {
        if (spec.fittable && spec.name.rfind(name + ".", 0) == 0) opt.calibration_parameters.push_back(spec.name);
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
    // The candidate the report shows as the model after: the named one
    // (explained or mostly explained), else the accepted one.
    const bool named = r.grade == audit::AuditGrade::kExplained || r.grade == audit::AuditGrade::kMostlyExplained;
    const audit::CandidateResult* best =
        named ? &r.candidates[r.graded] : (r.best >= 0 ? &r.candidates[r.best] : nullptr);
    const audit::ModelErrors& after = best ? best->errors : r.errors_before;

    // ---- where it fails: trends, error map, modes without a counterpart.
    opt.progress("error patterns: trends against posture descriptors, mode error map, unmatched modes");
    const auto base_model = dynamics::RobotModel::Build(cfg.description, r.baseline_fit.parameters);
    const calibration::MeasuredFeatures& features = r.features;
    audit::ErrorPatternOptions popt;
    popt.fmin_hz = opt.fmin_hz;
    popt.fmax_hz = opt.fmax_hz;
    const audit::ErrorPatterns patterns = audit::AnalyzeErrorPatterns(r, base_model, postures, measured, features, popt);
    const report::AuditPatternsReport pr = report::MakeAuditPatternsReport(patterns, r.noise_floor, "model-audit");

    // ---- summary.json (stable keys; see README)
    json j;
    j["robot"] = robot_path;
    j["effects_in_model"] = json::array();
    for (const auto& e : cfg.description.effects) j["effects_in_model"].push_back(e.name);
    j["error_before"] = r.errors_before.total_rms_log_mag;
    j["error_after"] = after.total_rms_log_mag;
    j["noise_floor"] = r.noise_floor;
    // With a noise model every error is in units of the noise (1: a model
    // that is right); with --noise-model none, an rms of ln|H| differences.
    j["error_units"] = noise.empty() ? "log_magnitude" : "noise_sigma";
    j["noise"] = report::NoiseSummaryJson(noise, noise_opt.model, noise_opt.min_snr);
    j["warnings"] = r.warnings;
    j["significant_failure"] = r.significant_failure;
    j["baseline_calibration"] = {{"status", calibration::FitStatusName(r.baseline_fit.status)},
                                 {"message", r.baseline_fit.message},
                                 {"parameters", json::object()}};
    for (const auto& e : r.baseline_fit.estimates) {
      j["baseline_calibration"]["parameters"][e.name] = {{"value", e.value}, {"std", e.std_dev}};
    }
    if (r.baseline_fit.status != calibration::FitStatus::kConverged) {
      Warn(kTool, "the calibration of the current model did not converge (" + r.baseline_fit.message +
                      "); its errors are those of the last iterate");
    }
    const auto pb = PerPosture(r.errors_before, measured.pose_ids()), pa = PerPosture(after, measured.pose_ids());
    for (const auto& [id, e] : pb) {
      j["postures"][id] = {{"error_before", e}, {"error_after", pa.at(id)}};
      if (pr.posture_descriptors.contains(id)) j["postures"][id]["descriptors"] = pr.posture_descriptors[id];
    }
    if (!previous.is_null()) {
      // The previous audit's errors next to these, per posture and in total.
      j["compare"] = {{"report", compare_dir},
                      {"error_before", previous["error_before"]},
                      {"error_after", previous["error_after"]},
                      {"postures", json::object()}};
      for (const auto& [id, e] : pb) {
        if (previous["postures"].contains(id)) {
          j["compare"]["postures"][id] = {{"error_before", previous["postures"][id]["error_before"]},
                                          {"error_after", previous["postures"][id]["error_after"]}};
        }
      }
    }
    j["trends"] = pr.trends;
    j["mode_error_map"] = pr.mode_error_map;
    j["unmatched_model_modes"] = pr.unmatched_model_modes;
    j["unmatched_measured_modes"] = pr.unmatched_measured_modes;
    j["candidates"] = json::array();
    for (const auto& c : r.candidates) {
      json cj{{"name", c.name()}, {"bic_change", c.bic_change}, {"error_after", c.errors.total_rms_log_mag},
              {"plausible", c.plausible}, {"note", c.note}, {"parameters", json::object()},
              {"not_identifiable", c.not_identifiable}, {"held_calibration", c.held_calibration},
              {"start", c.start}};
      for (const auto& e : c.fit.estimates) cj["parameters"][e.name] = {{"value", e.value}, {"std", e.std_dev}};
      j["candidates"].push_back(cj);
    }
    // Numbers that are undefined (no candidate) are null.
    const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    j["verdict"] = {{"grade", audit::AuditGradeName(r.grade)},
                    {"missing_effects", r.missing_effects},
                    {"explained", r.explained},
                    {"headline", r.headline},
                    {"text", r.verdict},
                    {"pattern", r.pattern},
                    {"candidate", r.graded >= 0 ? json(r.candidates[r.graded].name()) : json(nullptr)},
                    {"error_before_noise_units", number(r.error_before_noise_units)},
                    {"remainder_noise_units", number(r.remainder_noise_units)},
                    {"fraction_removed", number(r.fraction_removed)},
                    {"bic_gap", number(r.bic_gap)},
                    {"runner_up", r.runner_up},
                    {"reasons", r.reasons}};
    // The YAML to paste: the accepted candidate's effects, or else the
    // effects switched on with --add, with their calibrated values.
    std::string yaml;
    if (best) {
      yaml = audit::EffectYaml(*best);
    } else if (!adds.empty()) {
      audit::CandidateResult added;
      added.effects = adds;
      added.fit = r.baseline_fit;
      yaml = audit::EffectYaml(added);
    }
    j["yaml"] = yaml;

    // ---- errors.csv, candidates.csv
    std::ostringstream ecsv;
    ecsv << "pose_id,response,excitation,lines,error_before,error_after,worst_band_fmin_hz,worst_band_fmax_hz,"
            "worst_band_error\n";
    for (size_t i = 0; i < r.errors_before.curves.size(); ++i) {
      const auto& c = r.errors_before.curves[i];
      ecsv << c.key.pose_id << ',' << AxisName(c.key.response) << ',' << AxisName(c.key.excitation) << ','
           << c.lines << ',' << FormatNumber(c.rms_log_mag, 6) << ',' << FormatNumber(after.curves[i].rms_log_mag, 6);
      if (!c.bands.empty()) {
        ecsv << ',' << FormatNumber(c.bands[0].fmin_hz, 6) << ',' << FormatNumber(c.bands[0].fmax_hz, 6) << ','
             << FormatNumber(c.bands[0].rms_log_mag, 6);
      } else {
        ecsv << ",,,";
      }
      ecsv << '\n';
    }
    std::ostringstream ccsv;
    ccsv << "rank,candidate,bic_change,error_after,plausible,note\n";
    for (size_t i = 0; i < r.candidates.size(); ++i) {
      const auto& c = r.candidates[i];
      std::string note = c.note;
      std::replace(note.begin(), note.end(), ',', ';');
      std::replace(note.begin(), note.end(), '\n', ' ');
      ccsv << i + 1 << ',' << c.name() << ',' << FormatNumber(c.bic_change, 8) << ',' << FormatNumber(c.errors.total_rms_log_mag, 6)
           << ',' << (c.plausible ? "yes" : "no") << ',' << note << '\n';
    }

    // Overlays: the calibrated current model against the named or accepted
    // candidate; without one, against the best-ranked candidate, labelled
    // as not accepted, so that the unexplained pattern can be seen; with no
    // candidate fitted, the current model alone.
    const audit::CandidateResult* shown = best ? best : (r.candidates.empty() ? nullptr : &r.candidates[0]);
    const std::string before_label = "current model (calibrated)";
    const std::string after_label =
        shown ? "with " + shown->name() +
                    (!best ? " (not accepted)"
                           : r.grade == audit::AuditGrade::kMostlyExplained ? " (mostly explains)" : "")
              : "";
    // The FRF the current model fits worst (whole-curve error before).
    size_t worst = 0;
    for (size_t i = 1; i < r.errors_before.curves.size(); ++i) {
      if (r.errors_before.curves[i].rms_log_mag > r.errors_before.curves[worst].rms_log_mag) worst = i;
    }
    const bool has_worst = !r.errors_before.curves.empty();

    // ---- index.html (self-contained; PNGs by relative path): the verdict in
    // one sentence and the worst FRF before and after first, the tables after.
    std::ostringstream h;
    h << "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>model-audit</title><style>"
         "body{font-family:sans-serif;max-width:70em;margin:auto}table{border-collapse:collapse}"
         "td,th{border:1px solid #999;padding:2px 6px;text-align:right}pre{background:#eee;padding:6px}"
         ".headline{font-size:1.3em;padding:8px;border-left:6px solid "
      << (r.grade == audit::AuditGrade::kUnexplained         ? "#c0392b"
          : r.grade == audit::AuditGrade::kMostlyExplained ? "#e67e22"
                                                            : "#27ae60")
      << ";background:#f6f6f6}img{max-width:100%}"
         "</style></head><body><h1>model-audit: " << report::HtmlEscape(robot_path) << "</h1>\n";
    {
      // The library's plain-text arrows and times signs, typeset.
      std::string line = report::HtmlEscape(r.headline);
      for (const auto& [from, to] : {std::pair<std::string, std::string>{" -&gt; ", " → "}, {" x the noise", " × the noise"}}) {
        for (size_t at = line.find(from); at != std::string::npos; at = line.find(from, at + to.size())) {
          line.replace(at, from.size(), to);
        }
      }
      h << "<p class=\"headline\">" << line << "</p>\n";
    }
    if (has_worst) {
      const auto& wc = r.errors_before.curves[worst];
      // The error of the curve drawn thin (the shown candidate's), if any.
      const bool has_after = shown && worst < shown->errors.curves.size();
      h << "<p><img src=\"worst_frf.png\" alt=\"worst FRF before and after\"><br>The FRF the current model fits "
           "worst, "
        << report::HtmlEscape(KeyLabel(wc.key)) << " (error " << FormatNumber(wc.rms_log_mag / r.noise_floor, 3) << " × the noise floor";
      if (has_after) {
        h << "; " << FormatNumber(shown->errors.curves[worst].rms_log_mag / r.noise_floor, 3) << " with "
          << report::HtmlEscape(shown->name());
      }
      h << "): measured (wide, with its noise where known), the calibrated current model (dashed)";
      if (shown) {
        h << " and the model with " << report::HtmlEscape(shown->name()) << " (" << (best ? "" : "not accepted; ") << "thin line)";
      }
      h << ".</p>\n";
    }
    h << "<h2>Verdict</h2>\n";
    if (r.grade == audit::AuditGrade::kMostlyExplained) {
      // The verdict's parts one by one (summary.json's verdict.text has them
      // in one sentence).
      h << "<p>Likely reasons for the remainder:</p><ul>";
      for (const auto& reason : r.reasons) h << "<li>" << report::HtmlEscape(reason) << "</li>";
      h << "</ul>\n<p>Pattern of the remainder: " << report::HtmlEscape(r.pattern) << ".</p>\n";
    } else {
      h << "<p>" << report::HtmlEscape(r.verdict) << "</p>\n";
    }
    if (r.graded >= 0) {
      h << "<p>Graded on " << report::HtmlEscape(r.candidates[r.graded].name()) << ": error " << FormatNumber(r.error_before_noise_units, 3)
        << " → " << FormatNumber(r.remainder_noise_units, 3) << " × the noise floor, "
        << FormatNumber(100.0 * r.fraction_removed, 3) << " % of the excess misfit (error/noise − 1) removed; BIC "
        << FormatNumber(r.bic_gap, 4) << " below the runner-up, " << report::HtmlEscape(r.runner_up) << ". \"Mostly explained\" takes "
        << FormatNumber(100.0 * opt.mostly_explained_fraction, 3) << " % or more and a BIC gap above "
        << FormatNumber(opt.clear_bic_gap, 3) << " (very strong evidence, Kass &amp; Raftery 1995).</p>\n";
    }
    h << "<p>Whole-curve error (rms of ln|H<sub>model</sub>| − "
      << "ln|H<sub>measured</sub>|" << (noise.empty() ? "" : ", each line in units of its noise: 1 is a model that is right")
      << "): before " << FormatNumber(r.errors_before.total_rms_log_mag) << ", after "
      << FormatNumber(after.total_rms_log_mag) << "; noise floor " << FormatNumber(r.noise_floor) << " ("
      << (r.significant_failure ? "significant failure" : "consistent with the noise") << ").</p>\n";
    if (!noise.empty()) {
      h << "<h2>Noise model and usable band per FRF</h2><p>Lines used where |H| ≥ " << FormatNumber(noise_opt.min_snr)
        << " × the additive noise floor (--min-snr).</p><table><tr><th>FRF</th><th>noise model</th></tr>\n";
      for (const auto& [key, n] : noise) {
        h << "<tr><td>" << report::HtmlEscape(KeyLabel(key)) << "</td><td style=\"text-align:left\">" << report::HtmlEscape(n.description)
          << "</td></tr>\n";
      }
      h << "</table>\n";
    }
    h << "<h2>Error per posture</h2><table><tr><th>posture</th><th>before</th><th>after</th>";
    if (!previous.is_null()) h << "<th>previous before</th><th>previous after</th>";
    h << "</tr>\n";
    for (const auto& [id, e] : pb) {
      h << "<tr><td>" << report::HtmlEscape(id) << "</td><td>" << FormatNumber(e) << "</td><td>" << FormatNumber(pa.at(id)) << "</td>";
      if (!previous.is_null()) {
        const bool has = previous["postures"].contains(id);
        h << "<td>" << (has ? FormatNumber(previous["postures"][id]["error_before"].get<double>()) : "–") << "</td><td>"
          << (has ? FormatNumber(previous["postures"][id]["error_after"].get<double>()) : "–") << "</td>";
      }
      h << "</tr>\n";
    }
    h << "<tr><th>total</th><th>" << FormatNumber(r.errors_before.total_rms_log_mag) << "</th><th>"
      << FormatNumber(after.total_rms_log_mag) << "</th>";
    if (!previous.is_null()) {
      h << "<th>" << FormatNumber(previous["error_before"].get<double>()) << "</th><th>"
        << FormatNumber(previous["error_after"].get<double>()) << "</th>";
    }
    h << "</tr></table>\n<h2>Error per posture and direction, worst band</h2><table><tr><th>FRF</th><th>before</th>"
         "<th>after</th><th>worst band [Hz]</th><th>its error</th></tr>\n";
    for (size_t i = 0; i < r.errors_before.curves.size(); ++i) {
      const auto& c = r.errors_before.curves[i];
      h << "<tr><td>" << report::HtmlEscape(KeyLabel(c.key)) << "</td><td>" << FormatNumber(c.rms_log_mag) << "</td><td>"
        << FormatNumber(after.curves[i].rms_log_mag) << "</td>";
      if (!c.bands.empty()) {
        h << "<td>" << FormatNumber(c.bands[0].fmin_hz, 3) << "–" << FormatNumber(c.bands[0].fmax_hz, 3) << "</td><td>"
          << FormatNumber(c.bands[0].rms_log_mag) << "</td>";
      } else {
        h << "<td></td><td></td>";
      }
      h << "</tr>\n";
    }
    h << "</table>\n<h2>Modes (current model, calibrated)</h2><table><tr><th>FRF</th><th>measured [Hz]</th>"
         "<th>frequency error</th><th>damping meas.</th><th>damping model</th><th>peak error</th></tr>\n";
    for (const auto& m : r.modes_before.matches) {
      h << "<tr><td>" << report::HtmlEscape(KeyLabel(m.key)) << "</td><td>" << FormatNumber(m.measured_freq_hz) << "</td><td>"
        << FormatNumber(100 * m.freq_error(), 3) << " %</td><td>" << FormatNumber(m.measured_damping, 3) << "</td><td>"
        << FormatNumber(m.model_damping, 3) << "</td><td>" << FormatNumber(100 * m.peak_error(), 3) << " %</td></tr>\n";
    }
    h << "</table>\n" << pr.html << "<h2>Candidate effects (best first)</h2>";
    if (r.candidates.empty()) h << "<p>None tried.</p>";
    h << "<table><tr><th>rank</th><th>candidate</th><th>ΔBIC</th><th>error after</th><th>plausible</th>"
         "<th>fitted parameters (±1σ)</th></tr>\n";
    for (size_t i = 0; i < r.candidates.size(); ++i) {
      const auto& c = r.candidates[i];
      h << "<tr><td>" << i + 1 << "</td><td>" << report::HtmlEscape(c.name()) << "</td><td>" << FormatNumber(c.bic_change, 6)
        << "</td><td>" << FormatNumber(c.errors.total_rms_log_mag) << "</td><td>" << (c.plausible ? "yes" : "no: " + report::HtmlEscape(c.note))
        << "</td><td style=\"text-align:left\">";
      for (const auto& e : c.fit.estimates) {
        if (e.name.find('.') != std::string::npos) h << report::HtmlEscape(e.name) << " = " << FormatNumber(e.value) << " ± " << FormatNumber(e.std_dev, 2) << "<br>";
      }
      h << "</td></tr>\n";
    }
    h << "</table>\n";
    if (!yaml.empty()) {
      h << "<h2>" << (best ? "Add the effect" : "The added effects, calibrated")
        << "</h2><p>Append to the robot config (merge into its <code>effects:</code> list if it has one):</p><pre>"
        << report::HtmlEscape(yaml) << "</pre>\n";
    }
    h << "<h2>Overlays per posture</h2><p>Measured FRFs (wide band), the calibrated current model (dashed)"
      << (shown ? " and the model " + report::HtmlEscape(after_label) + " (thin line)" : std::string())
      << "; vertical lines: the natural frequencies of the " << (shown ? "latter" : "model") << ".</p>\n";
    for (const auto& id : measured.pose_ids()) {
      h << "<p><img src=\"overlay_" << report::HtmlEscape(id) << ".png\" alt=\"overlay " << report::HtmlEscape(id) << "\"></p>\n";
    }
    h << "</body></html>\n";

    // ---- write (each file complete or absent)
    io::EnsureDirectory(report_dir);
    const fs::path dir(report_dir);
    const report::AuditPatternFiles names;
    {
      dynamics::PostureEvaluator eb(base_model);
      std::unique_ptr<dynamics::PostureEvaluator> ea;
      if (shown) {
        dynamics::RobotDescription desc = cfg.description;
        for (const auto& e : shown->effects) desc.effects.push_back({e, {}});
        ea = std::make_unique<dynamics::PostureEvaluator>(dynamics::RobotModel::Build(desc, shown->fit.parameters));
      }
      for (const std::string& pose : measured.pose_ids()) {
        const auto db = eb.Evaluate(postures.at(pose));
        // Every measured line with its noise, not only the usable ones.
        report::PostureOverlay o = ea ? report::MakePostureOverlay(pose, measured_read.frfs, db,
                                                                   ea->Evaluate(postures.at(pose)))
                                      : report::MakePostureOverlay(pose, measured_read.frfs, db);
        report::AddNoise(noise, &o);
        if (has_worst && pose == r.errors_before.curves[worst].key.pose_id) {
          // The worst FRF alone: its row of the posture's overlay.
          const dynamics::FrfKey& wk = r.errors_before.curves[worst].key;
          report::PostureOverlay w = o;
          w.keys.clear(), w.freq_hz.clear(), w.measured.clear(), w.before.clear(), w.after.clear();
          w.noise_sigma.clear(), w.usable.clear();
          for (size_t k = 0; k < o.keys.size(); ++k) {
            if (!(o.keys[k] == wk)) continue;
            w.keys.push_back(o.keys[k]);
            w.freq_hz.push_back(o.freq_hz[k]);
            w.measured.push_back(o.measured[k]);
            w.before.push_back(o.before[k]);
            if (k < o.after.size()) w.after.push_back(o.after[k]);
            if (k < o.noise_sigma.size()) w.noise_sigma.push_back(o.noise_sigma[k]);
            if (k < o.usable.size()) w.usable.push_back(o.usable[k]);
          }
          report::WriteOverlayPng((dir / "worst_frf.png").string(), w,
                                  "model-audit: worst FRF " + KeyLabel(wk) + ", measured vs " + before_label +
                                      (shown ? " and " + after_label : std::string()),
                                  before_label, after_label);
        }
        report::WriteOverlayPng((dir / ("overlay_" + pose + ".png")).string(), o,
                                "model-audit: posture " + pose + ", measured vs " + before_label +
                                    (shown ? " and " + after_label : std::string()),
                                before_label, after_label);
      }
    }
    // Files of an earlier run in this folder that this run does not
    // rewrite would be taken for its results: remove them.
    {
      std::vector<fs::path> stale;
      const std::vector<std::string> ids = measured.pose_ids();
      const std::set<std::string> poses(ids.begin(), ids.end());
      if (yaml.empty()) stale.push_back(dir / "effects.yaml");
      if (pr.mode_error_map_png.empty()) stale.push_back(dir / names.mode_error_map_png);
      for (const auto& entry : fs::directory_iterator(dir)) {
        const std::string n = entry.path().filename().string();
        if (n.rfind("overlay_", 0) == 0 && entry.path().extension() == ".png" &&
            !poses.count(n.substr(8, n.size() - 12))) {
          stale.push_back(entry.path());
        }
      }
      for (const auto& f : stale) fs::remove(f);
    }
    if (!yaml.empty()) {
      io::WriteFileAtomically((dir / "effects.yaml").string(), "# model-audit: add to the robot config\n" + yaml);
    }
    io::WriteFileAtomically((dir / "errors.csv").string(), ecsv.str());
    io::WriteFileAtomically((dir / "candidates.csv").string(), ccsv.str());
    io::WriteFileAtomically((dir / names.trends_csv).string(), pr.trends_csv);
    io::WriteFileAtomically((dir / names.posture_descriptors_csv).string(), pr.posture_descriptors_csv);
    io::WriteFileAtomically((dir / names.mode_errors_csv).string(), pr.mode_errors_csv);
    io::WriteFileAtomically((dir / names.unmatched_modes_csv).string(), pr.unmatched_modes_csv);
    auto write_png = [&](const std::string& name, const std::vector<unsigned char>& png) {
      io::WriteFileAtomically((dir / name).string(),
                              std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
    };
    write_png(names.trends_png, pr.trends_png);
    if (!pr.mode_error_map_png.empty()) write_png(names.mode_error_map_png, pr.mode_error_map_png);
    io::WriteFileAtomically((dir / "index.html").string(), h.str());
    io::WriteFileAtomically((dir / "summary.json").string(), report::DumpJson(j));
    if (!summary_path.empty() && summary_path != "-") io::WriteFileAtomically(summary_path, report::DumpJson(j));

    std::cerr << kTool << ": " << r.verdict << '\n';
    for (const auto& w : r.warnings) Warn(kTool, w);
    bool failed_candidate = false;
    for (const auto& c : r.candidates) failed_candidate |= c.fit.status == calibration::FitStatus::kFailed;
    if (failed_candidate) Warn(kTool, "a candidate's fit failed; its row in candidates.csv says why");
    io::WriteFileAtomically("-", yaml);
    if (summary_path == "-") io::WriteFileAtomically("-", report::DumpJson(j));
    // measured_read.unit_findings: receptances outside the plausible range, warned when read.
    return (r.significant_failure && !r.explained) || !r.warnings.empty() || failed_candidate ||
                   !measured_read.unit_findings.empty()
               ? kExitFlagged
               : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
