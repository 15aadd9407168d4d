#include "robomach/report/audit_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "robomach/audit/error_patterns.h"
#include "robomach/common/number_format.h"
#include "robomach/common/option_validate.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/file_names.h"
#include "robomach/report/audit_patterns_report.h"
#include "robomach/report/calibration_report.h"
#include "robomach/report/html.h"
#include "robomach/report/json.h"

namespace robomach::report {
namespace {

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


// The call's arguments, handed to every section of the report together.
struct ReportInputs {
  const audit::AuditResult& r;
  const dynamics::RobotDescription& description;
  const calibration::PostureMap& postures;
  const dynamics::FrfSet& measured_fit;
  const dynamics::FrfSet& measured_all;
  const calibration::NoiseModels& noise;
  const AuditReportOptions& ro;
};

// What several sections share, derived once from the inputs before any
// section is written: the model after, the pictures' model, the warnings and
// the headline, the error patterns, the errors per posture, the YAML to paste
// and what the overlays show.
struct ReportBasis {
  const audit::CandidateResult* best{nullptr};  // named or accepted candidate
  const audit::ModelErrors* after{nullptr};     // its errors, else the errors before
  bool pictures_configured{false};
  std::shared_ptr<const dynamics::RobotModel> base_model;  // the pictures' model
  std::vector<std::string> warnings;
  std::string headline;
  AuditPatternsReport pr;
  std::map<std::string, double> pb, pa;  // error per posture before, after
  std::string yaml;
  const audit::CandidateResult* shown{nullptr};  // the model drawn thin in the overlays
  std::string before_label, after_label;
  size_t worst{0};  // the FRF the current model fits worst
  bool has_worst{false};
  std::map<std::string, std::string> stems;  // posture id -> file-name stem
};

// The caller's warnings, then the calibration's bounds and the audit's own,
// each once.
std::vector<std::string> Warnings(const ReportInputs& in) {
  std::vector<std::string> warnings = in.ro.input_warnings;
  const auto warn_once = [&](const std::string& w) {
    if (std::find(warnings.begin(), warnings.end(), w) == warnings.end()) warnings.push_back(w);
  };
  for (const auto& f : in.r.baseline_on_bound) warn_once(f.message);
  for (const auto& w : in.r.warnings) warn_once(w);
  return warnings;
}

// The headline, with the previous audit's errors beside these (--compare).
std::string Headline(const ReportInputs& in) {
  const audit::AuditResult& r = in.r;
  const AuditReportOptions& ro = in.ro;
  std::string headline = r.headline;
  if (!ro.previous.is_null() && ro.previous.contains("error_before")) {
    std::ostringstream m;
    m.precision(3);
    const auto prev = [&](const char* key) {
      return ro.previous.contains(key) && ro.previous[key].is_number() ? ro.previous[key].get<double>() : NAN;
    };
    const double nf = ro.previous.contains("noise_floor") && ro.previous["noise_floor"].is_number()
                          ? ro.previous["noise_floor"].get<double>()
                          : 1.0;
    m << " Previous audit (" << ro.compare_dir << "): " << prev("error_before") / nf << " x the noise floor";
    const double pa = prev("error_after") / nf;
    if (std::isfinite(pa) && pa != prev("error_before") / nf) m << ", " << pa << " with its named change";
    m << "; now " << r.errors_before.total_rms_log_mag / r.noise_floor << ".";
    headline += m.str();
  }
  return headline;
}

// The YAML to paste: the accepted candidate's effects, or else the
// effects switched on with --add, with their calibrated values.
std::string PasteYaml(const ReportInputs& in, const audit::CandidateResult* best) {
  std::string yaml;
  if (best) {
    yaml = audit::EffectYaml(*best);
  } else if (!in.ro.added_effects.empty()) {
    audit::CandidateResult added;
    added.effects = in.ro.added_effects;
    added.fit = in.r.baseline_fit;
    yaml = audit::EffectYaml(added);
  }
  return yaml;
}

// What the overlays show beside the measured FRFs, and the worst FRF.
void ChooseOverlays(const ReportInputs& in, ReportBasis* b) {
  const audit::AuditResult& r = in.r;
  // Overlays: the calibrated current model against the named or accepted
  // candidate; without one, against the best-ranked candidate, labelled
  // as not accepted, so that the unexplained pattern can be seen; with no
  // candidate fitted, the current model alone.
  const audit::CandidateResult* best = b->best;
  const audit::CandidateResult* shown = best ? best : (r.candidates.empty() ? nullptr : &r.candidates[0]);
  b->shown = shown;
  b->before_label = b->pictures_configured ? "current model (as configured)" : "current model (calibrated)";
  b->after_label =
      shown ? "with " + shown->name() +
                  (!best ? " (not accepted)"
                         : r.grade == audit::AuditGrade::kMostlyExplained ? " (mostly explains)" : "")
            : "";
  // The FRF the current model fits worst (whole-curve error before).
  size_t worst = 0;
  for (size_t i = 1; i < r.errors_before.curves.size(); ++i) {
    if (r.errors_before.curves[i].rms_log_mag > r.errors_before.curves[worst].rms_log_mag) worst = i;
  }
  b->worst = worst;
  b->has_worst = !r.errors_before.curves.empty();
  // Posture IDs become file names through io::SafeFileStems (no path
  // separators, no ".."; docs/conventions.md); the tool notes the changed ones.
  b->stems = io::SafeFileStems(in.measured_fit.pose_ids());
}

// The shared part of the report (ReportBasis), with the error patterns; says
// so through ro.progress.
ReportBasis MakeBasis(const ReportInputs& in) {
  const audit::AuditResult& r = in.r;
  const AuditReportOptions& ro = in.ro;
  ReportBasis b;
  // The candidate the report shows as the model after: the named one
  // (explained or mostly explained), else the accepted one.
  b.best = audit::AcceptedCandidate(r);
  b.after = b.best ? &b.best->errors : &r.errors_before;

  // ---- where it fails: trends, error map, modes without a counterpart.
  if (ro.progress) ro.progress("error patterns: trends against posture descriptors, mode error map, unmatched modes");
  // The pictures' model: the calibrated one, or the model as configured when
  // the calibration ended on a bound (AuditResult::pictures_from).
  b.pictures_configured = r.pictures_from == "configured" && r.pictures_parameters.size() > 0;
  b.base_model =
      dynamics::RobotModel::Build(in.description, b.pictures_configured ? r.pictures_parameters : r.baseline_fit.parameters);
  b.warnings = Warnings(in);
  b.headline = Headline(in);
  const calibration::MeasuredFeatures& features = r.features;
  audit::ErrorPatternOptions popt;
  popt.fmin_hz = ro.fmin_hz;
  popt.fmax_hz = ro.fmax_hz;
  const audit::ErrorPatterns patterns =
      audit::AnalyzeErrorPatterns(r, b.base_model, in.postures, in.measured_fit, features, popt);
  b.pr = MakeAuditPatternsReport(patterns, r.noise_floor, "model-audit");
  b.pb = PerPosture(r.errors_before, in.measured_fit.pose_ids());
  b.pa = PerPosture(*b.after, in.measured_fit.pose_ids());
  b.yaml = PasteYaml(in, b.best);
  ChooseOverlays(in, &b);
  return b;
}

// Numbers that are undefined (no candidate) are null.
json NumberOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// summary.json's `baseline` and `baseline_calibration`.
void AddBaselineJson(const audit::AuditResult& r, json* j) {
  // The baseline the user can trust (issue #33): the model as configured,
  // the calibration parameters on a bound, and which model the pictures show.
  (*j)["baseline"] = {{"error_configured", r.errors_configured.total_rms_log_mag},
                      {"error_calibrated", r.errors_before.total_rms_log_mag},
                      {"pictures_from", r.pictures_from},
                      {"on_bound", json::array()}};
  for (const auto& f : r.baseline_on_bound) {
    (*j)["baseline"]["on_bound"].push_back(
        {{"name", f.name}, {"value", f.value}, {"bound", f.lower ? "lower" : "upper"}, {"message", f.message}});
  }
  (*j)["baseline_calibration"] = {{"status", robomach::ToString(r.baseline_fit.status)},
                                  {"message", r.baseline_fit.message},
                                  {"parameters", json::object()}};
  for (const auto& e : r.baseline_fit.estimates) {
    (*j)["baseline_calibration"]["parameters"][e.name] = {{"value", e.value}, {"std", e.std_dev}};
  }
}

// summary.json's `postures`, and `compare` with --compare.
void AddPosturesJson(const ReportInputs& in, const ReportBasis& b, json* j) {
  const AuditReportOptions& ro = in.ro;
  for (const auto& [id, e] : b.pb) {
    (*j)["postures"][id] = {{"error_before", e}, {"error_after", b.pa.at(id)}};
    if (b.pr.posture_descriptors.contains(id)) (*j)["postures"][id]["descriptors"] = b.pr.posture_descriptors[id];
  }
  if (!ro.previous.is_null()) {
    // The previous audit's errors next to these, per posture and in total.
    (*j)["compare"] = {{"report", ro.compare_dir},
                       {"error_before", ro.previous["error_before"]},
                       {"error_after", ro.previous["error_after"]},
                       {"postures", json::object()}};
    for (const auto& [id, e] : b.pb) {
      if (ro.previous["postures"].contains(id)) {
        (*j)["compare"]["postures"][id] = {{"error_before", ro.previous["postures"][id]["error_before"]},
                                           {"error_after", ro.previous["postures"][id]["error_after"]}};
      }
    }
  }
}

// summary.json's `candidates`, best first.
json CandidatesJson(const audit::AuditResult& r) {
  json out = json::array();
  for (const auto& c : r.candidates) {
    json cj{{"name", c.name()},
            {"kind", c.is_parameter_hypothesis() ? "parameters"
                     : c.name().rfind("virtual_joint_", 0) == 0 ? "virtual_joint"
                                                               : "effect"},
            {"bic_change", c.bic_change}, {"error_after", c.errors.total_rms_log_mag},
            {"plausible", c.plausible}, {"note", c.note}, {"parameters", json::object()},
            {"not_identifiable", c.not_identifiable}, {"held_calibration", c.held_calibration},
            {"start", c.start}};
    for (const auto& e : c.fit.estimates) cj["parameters"][e.name] = {{"value", e.value}, {"std", e.std_dev}};
    out.push_back(cj);
  }
  return out;
}

// summary.json's `verdict`, with the parameter changes.
json VerdictJson(const audit::AuditResult& r, const std::string& headline) {
  json v = {{"grade", audit::ToString(r.grade)},
            {"missing_effects", r.missing_effects},
            {"explained", r.explained},
            {"headline", headline},
            {"text", r.verdict},
            {"parameter_changes", json::array()},
            {"description", r.graded >= 0 ? json(audit::DescribeCandidate(r.candidates[r.graded], r.configured))
                                          : json(nullptr)},
            {"pattern", r.pattern},
            {"candidate", r.graded >= 0 ? json(r.candidates[r.graded].name()) : json(nullptr)},
            {"error_before_noise_units", NumberOrNull(r.error_before_noise_units)},
            {"remainder_noise_units", NumberOrNull(r.remainder_noise_units)},
            {"fraction_removed", NumberOrNull(r.fraction_removed)},
            {"bic_gap", NumberOrNull(r.bic_gap)},
            {"runner_up", r.runner_up},
            {"reasons", r.reasons},
            {"next_steps", r.next_steps}};
  for (const auto& pc : r.parameter_changes) {
    v["parameter_changes"].push_back({{"name", pc.name},
                                      {"unit", pc.unit},
                                      {"configured", pc.configured},
                                      {"fitted", NumberOrNull(pc.fitted)},
                                      {"std", NumberOrNull(pc.std_dev)},
                                      {"ratio", NumberOrNull(pc.ratio())}});
  }
  return v;
}

// summary.json's `virtual_joint_screen`.
json VirtualJointScreenJson(const audit::AuditResult& r) {
  json v = {{"baseline", NumberOrNull(r.virtual_joint_screen_baseline)}, {"joints", json::array()}};
  for (const auto& s : r.virtual_joint_screen) {
    v["joints"].push_back({{"effect", s.effect},
                           {"stiffness", NumberOrNull(s.stiffness)},
                           {"predicted_error", NumberOrNull(s.predicted_error)},
                           {"fitted", s.fitted}});
  }
  return v;
}

// summary.json's `parameter_uncertainty`.
json UncertaintyJson(const audit::UncertaintyAllowance& u) {
  json values = json::object();
  for (const auto& n : u.parameters) values[n] = u.at.Get(n);
  return {{"parameters", u.parameters},
          {"left_out", u.left_out},
          {"confidence", u.confidence},
          {"rank", u.rank},
          {"chi2", u.chi2},
          {"distance", NumberOrNull(u.distance)},
          {"radius", NumberOrNull(u.radius)},
          {"values_at_most_favourable_point", values},
          {"error_noise_units", NumberOrNull(u.error_noise_units)},
          {"fraction_removed", NumberOrNull(u.fraction_removed)},
          {"covers_failure", u.covers_failure},
          {"sentence", u.sentence}};
}

// ---- summary.json (stable keys; see README)
json SummaryJson(const ReportInputs& in, const ReportBasis& b) {
  const audit::AuditResult& r = in.r;
  const AuditReportOptions& ro = in.ro;
  json j;
  j["robot"] = ro.robot_path;
  j["effects_in_model"] = json::array();
  for (const auto& e : in.description.effects) j["effects_in_model"].push_back(e.name);
  j["error_before"] = r.errors_before.total_rms_log_mag;
  j["error_after"] = b.after->total_rms_log_mag;
  j["noise_floor"] = r.noise_floor;
  // With a noise model every error is in units of the noise (1: a model
  // that is right); with --noise-model none, an rms of ln|H| differences.
  j["error_units"] = in.noise.empty() ? "log_magnitude" : "noise_sigma";
  j["noise"] = NoiseSummaryJson(in.noise, ro.noise_model, ro.min_snr);
  j["warnings"] = b.warnings;
  j["significant_failure"] = r.significant_failure;
  AddBaselineJson(r, &j);
  AddPosturesJson(in, b, &j);
  j["trends"] = b.pr.trends;
  j["mode_error_map"] = b.pr.mode_error_map;
  j["unmatched_model_modes"] = b.pr.unmatched_model_modes;
  j["unmatched_measured_modes"] = b.pr.unmatched_measured_modes;
  j["candidates"] = CandidatesJson(r);
  j["verdict"] = VerdictJson(r, b.headline);
  j["virtual_joint_screen"] = VirtualJointScreenJson(r);
  if (!ro.written_config.empty()) j["written_config"] = ro.written_config;
  if (!ro.uncertainty_out.is_null()) j["uncertainty_out"] = ro.uncertainty_out;
  if (r.uncertainty) j["parameter_uncertainty"] = UncertaintyJson(*r.uncertainty);
  j["yaml"] = b.yaml;
  return j;
}

// ---- errors.csv: the whole-curve error of each FRF before and after, and
// its worst band.
std::string ErrorsCsv(const audit::AuditResult& r, const audit::ModelErrors& after) {
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
  return ecsv.str();
}

// ---- candidates.csv: the ranking, one line per candidate.
std::string CandidatesCsv(const audit::AuditResult& r) {
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
  return ccsv.str();
}

// index.html's head and first lines: the headline and the worst FRF's picture.
void HtmlHeadline(const ReportInputs& in, const ReportBasis& b, std::ostream& h) {
  const audit::AuditResult& r = in.r;
  h << "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>model-audit</title><style>"
       "body{font-family:sans-serif;max-width:70em;margin:auto}table{border-collapse:collapse}"
       "td,th{border:1px solid #999;padding:2px 6px;text-align:right}pre{background:#eee;padding:6px}"
       ".headline{font-size:1.3em;padding:8px;border-left:6px solid "
    << (r.grade == audit::AuditGrade::kUnexplained         ? "#c0392b"
        : r.grade == audit::AuditGrade::kMostlyExplained ? "#e67e22"
                                                          : "#27ae60")
    << ";background:#f6f6f6}img{max-width:100%}"
       "</style></head><body><h1>model-audit: " << HtmlEscape(in.ro.robot_path) << "</h1>\n";
  {
    // The library's plain-text arrows and times signs, typeset.
    std::string line = HtmlEscape(b.headline);
    for (const auto& [from, to] : {std::pair<std::string, std::string>{" -&gt; ", " → "}, {" x the noise", " × the noise"}}) {
      for (size_t at = line.find(from); at != std::string::npos; at = line.find(from, at + to.size())) {
        line.replace(at, from.size(), to);
      }
    }
    h << "<p class=\"headline\">" << line << "</p>\n";
  }
  if (b.has_worst) {
    const size_t worst = b.worst;
    const audit::CandidateResult* shown = b.shown;
    const auto& wc = r.errors_before.curves[worst];
    // The error of the curve drawn thin (the shown candidate's), if any.
    const bool has_after = shown && worst < shown->errors.curves.size();
    h << "<p><img src=\"worst_frf.png\" alt=\"worst FRF before and after\"><br>The FRF the current model fits "
         "worst, "
      << HtmlEscape(KeyLabel(wc.key)) << " (error " << FormatNumber(wc.rms_log_mag / r.noise_floor, 3) << " × the noise floor";
    if (has_after) {
      h << "; " << FormatNumber(shown->errors.curves[worst].rms_log_mag / r.noise_floor, 3) << " with "
        << HtmlEscape(shown->name());
    }
    h << "): measured (wide, with its noise where known), the " << b.before_label << " (dashed)";
    if (shown) {
      h << " and the model with " << HtmlEscape(shown->name()) << " (" << (b.best ? "" : "not accepted; ") << "thin line)";
    }
    h << ".</p>\n";
  }
}

// index.html: what to do, right after the verdict and its picture (issue
// #33, #35), and the warnings.
void HtmlWhatToDo(const ReportInputs& in, const ReportBasis& b, std::ostream& h) {
  const AuditReportOptions& ro = in.ro;
  const audit::CandidateResult* best = b.best;
  if (!b.yaml.empty()) {
    h << "<h2>What to do: " << (best ? (best->is_parameter_hypothesis() ? "set the fitted parameters" : "add the effect")
                                      : "the added effects, calibrated")
      << "</h2>";
    if (!ro.written_config.empty()) {
      h << "<p>The config with the change is written to <code>" << HtmlEscape(ro.written_config)
        << "</code> (--write-config): every tool loads it as it is.</p>";
    }
    h << "<p>Or append these lines to the robot config (they hold the effect and every parameter fitted with it; "
         "merge them into its <code>effects:</code> and <code>parameters:</code> blocks if it has them, or use "
         "model-audit --write-config):</p><pre>"
      << HtmlEscape(b.yaml) << "</pre>\n";
  }
  if (!b.warnings.empty()) {
    h << "<h2>Warnings</h2><ul>";
    for (const auto& w : b.warnings) h << "<li>" << HtmlEscape(w) << "</li>";
    h << "</ul>\n";
  }
}

// index.html's verdict: its parts, the parameter uncertainty, what to try
// next, the grading and the whole-curve error.
void HtmlVerdict(const ReportInputs& in, const ReportBasis& b, std::ostream& h) {
  const audit::AuditResult& r = in.r;
  const AuditReportOptions& ro = in.ro;
  h << "<h2>Verdict</h2>\n";
  if (r.grade == audit::AuditGrade::kMostlyExplained) {
    // The verdict's parts one by one (summary.json's verdict.text has them
    // in one sentence).
    h << "<p>Likely reasons for the remainder:</p><ul>";
    for (const auto& reason : r.reasons) h << "<li>" << HtmlEscape(reason) << "</li>";
    h << "</ul>\n<p>Pattern of the remainder: " << HtmlEscape(r.pattern) << ".</p>\n";
  } else {
    h << "<p>" << HtmlEscape(r.verdict) << "</p>\n";
  }
  if (r.uncertainty) {
    // Issue #37 §4 (in verdict.text too; the mostly-explained layout above lists parts).
    const audit::UncertaintyAllowance& u = *r.uncertainty;
    h << "<p><b>Parameter uncertainty:</b> " << HtmlEscape(u.sentence) << ".";
    if (!u.left_out.empty()) {
      h << " Not moved:";
      for (const auto& l : u.left_out) h << ' ' << HtmlEscape(l) << ';';
    }
    h << "</p>\n";
  }
  if (!r.next_steps.empty()) {
    h << "<p>What to try next:</p><ul>";
    for (const auto& n : r.next_steps) h << "<li>" << HtmlEscape(n) << "</li>";
    h << "</ul>\n";
  }
  if (r.graded >= 0) {
    h << "<p>Graded on " << HtmlEscape(r.candidates[r.graded].name()) << ": error " << FormatNumber(r.error_before_noise_units, 3)
      << " → " << FormatNumber(r.remainder_noise_units, 3) << " × the noise floor, "
      << FormatNumber(100.0 * r.fraction_removed, 3) << " % of the excess misfit (error/noise − 1) removed; BIC "
      << FormatNumber(r.bic_gap, 4) << " below the runner-up, " << HtmlEscape(r.runner_up) << ". \"Mostly explained\" takes "
      << FormatNumber(100.0 * ro.mostly_explained_fraction, 3) << " % or more and a BIC gap above "
      << FormatNumber(ro.clear_bic_gap, 3) << " (very strong evidence, Kass &amp; Raftery 1995).</p>\n";
  }
  h << "<p>Whole-curve error (rms of ln|H<sub>model</sub>| − "
    << "ln|H<sub>measured</sub>|" << (in.noise.empty() ? "" : ", each line in units of its noise: 1 is a model that is right")
    << "): before " << FormatNumber(r.errors_before.total_rms_log_mag) << ", after "
    << FormatNumber(b.after->total_rms_log_mag) << "; noise floor " << FormatNumber(r.noise_floor) << " ("
    << (r.significant_failure ? "significant failure" : "consistent with the noise") << ").</p>\n";
}

// index.html's baseline: the model as configured and calibrated, which the
// pictures show, and the parameters on a bound.
void HtmlBaseline(const ReportInputs& in, const ReportBasis& b, std::ostream& h) {
  const audit::AuditResult& r = in.r;
  h << "<h2>The baseline</h2><p>The model as configured: error " << FormatNumber(r.errors_configured.total_rms_log_mag)
    << "; calibrated (m6, d6, alpha, beta and any effect given with --add): " << FormatNumber(r.errors_before.total_rms_log_mag)
    << ". The pictures of where it fails (the mode table and error map, the overlays) show the "
    << (b.pictures_configured ? "model as configured, because the calibration ended with a parameter on a bound"
                              : "calibrated model")
    << ".</p>\n";
  if (!r.baseline_on_bound.empty()) {
    h << "<ul>";
    for (const auto& f : r.baseline_on_bound) h << "<li>" << HtmlEscape(f.message) << "</li>";
    h << "</ul>\n";
  }
}

// index.html's error tables: per posture (with --compare's previous audit),
// then per FRF with its worst band.
void HtmlErrorTables(const ReportInputs& in, const ReportBasis& b, std::ostream& h) {
  const audit::AuditResult& r = in.r;
  const AuditReportOptions& ro = in.ro;
  const audit::CandidateResult* best = b.best;
  h << "<h2>Error per posture</h2><table><tr><th>posture</th><th>before</th><th>after</th>";
  if (!ro.previous.is_null()) h << "<th>previous before</th><th>previous after</th>";
  h << "</tr>\n";
  for (const auto& [id, e] : b.pb) {
    // "after" only where a change is named or accepted (issue #33: with no
    // candidate the column repeated "before").
    h << "<tr><td>" << HtmlEscape(id) << "</td><td>" << FormatNumber(e) << "</td><td>"
      << (best ? FormatNumber(b.pa.at(id)) : std::string("–")) << "</td>";
    if (!ro.previous.is_null()) {
      const bool has = ro.previous["postures"].contains(id);
      h << "<td>" << (has ? FormatNumber(ro.previous["postures"][id]["error_before"].get<double>()) : "–") << "</td><td>"
        << (has ? FormatNumber(ro.previous["postures"][id]["error_after"].get<double>()) : "–") << "</td>";
    }
    h << "</tr>\n";
  }
  h << "<tr><th>total</th><th>" << FormatNumber(r.errors_before.total_rms_log_mag) << "</th><th>"
    << (best ? FormatNumber(b.after->total_rms_log_mag) : std::string("–")) << "</th>";
  if (!ro.previous.is_null()) {
    h << "<th>" << FormatNumber(ro.previous["error_before"].get<double>()) << "</th><th>"
      << FormatNumber(ro.previous["error_after"].get<double>()) << "</th>";
  }
  h << "</tr></table>\n<h2>Error per posture and direction, worst band</h2><table><tr><th>FRF</th><th>before</th>"
       "<th>after</th><th>worst band [Hz]</th><th>its error</th></tr>\n";
  for (size_t i = 0; i < r.errors_before.curves.size(); ++i) {
    const auto& c = r.errors_before.curves[i];
    h << "<tr><td>" << HtmlEscape(KeyLabel(c.key)) << "</td><td>" << FormatNumber(c.rms_log_mag) << "</td><td>"
      << (best ? FormatNumber(b.after->curves[i].rms_log_mag) : std::string("–")) << "</td>";
    if (!c.bands.empty()) {
      h << "<td>" << FormatNumber(c.bands[0].fmin_hz, 3) << "–" << FormatNumber(c.bands[0].fmax_hz, 3) << "</td><td>"
        << FormatNumber(c.bands[0].rms_log_mag) << "</td>";
    } else {
      h << "<td></td><td></td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n";
}

// index.html's mode table (measured against the current model), then the
// error-pattern sections.
void HtmlModes(const ReportInputs& in, const ReportBasis& b, std::ostream& h) {
  h << "<h2>Modes (" << HtmlEscape(b.before_label) << ")</h2><table><tr><th>FRF</th><th>measured [Hz]</th>"
       "<th>frequency error</th><th>damping meas.</th><th>damping model</th><th>peak error</th></tr>\n";
  for (const auto& m : in.r.modes_before.matches) {
    h << "<tr><td>" << HtmlEscape(KeyLabel(m.key)) << "</td><td>" << FormatNumber(m.measured_freq_hz) << "</td><td>"
      << FormatNumber(100 * m.freq_error(), 3) << " %</td><td>" << FormatNumber(m.measured_damping, 3) << "</td><td>"
      << FormatNumber(m.model_damping, 3) << "</td><td>" << FormatNumber(100 * m.peak_error(), 3) << " %</td></tr>\n";
  }
  h << "</table>\n" << b.pr.html;
}

// index.html's candidates, best first, and the virtual-joint screen.
void HtmlCandidates(const audit::AuditResult& r, std::ostream& h) {
  h << "<h2>Candidate effects (best first)</h2>";
  if (r.candidates.empty()) h << "<p>None tried.</p>";
  h << "<table><tr><th>rank</th><th>candidate</th><th>ΔBIC</th><th>error after</th><th>plausible</th>"
       "<th>fitted parameters (±1σ)</th></tr>\n";
  for (size_t i = 0; i < r.candidates.size(); ++i) {
    const auto& c = r.candidates[i];
    h << "<tr><td>" << i + 1 << "</td><td>" << HtmlEscape(c.name()) << "</td><td>" << FormatNumber(c.bic_change, 6)
      << "</td><td>" << FormatNumber(c.errors.total_rms_log_mag) << "</td><td>" << (c.plausible ? "yes" : "no: " + HtmlEscape(c.note))
      << "</td><td style=\"text-align:left\">";
    for (const auto& e : c.fit.estimates) {
      if (e.name.find('.') != std::string::npos) h << HtmlEscape(e.name) << " = " << FormatNumber(e.value) << " ± " << FormatNumber(e.std_dev, 2) << "<br>";
    }
    h << "</td></tr>\n";
  }
  h << "</table>\n";
  if (!r.virtual_joint_screen.empty()) {
    h << "<h2>Compliance along the chain: the virtual-joint screen</h2><p>Each elastic virtual joint added to the "
         "calibrated model at stiffnesses a factor of 4 apart, with a linearised re-adjustment of the calibration "
         "parameters: the rms whole-curve residual in units of the noise (the calibrated model: "
      << FormatNumber(r.virtual_joint_screen_baseline, 4) << "). The best were fitted as candidates.</p><table>"
         "<tr><th>virtual joint</th><th>where</th><th>best stiffness</th><th>screened error</th><th>fitted</th></tr>\n";
    for (size_t i = 0; i < r.virtual_joint_screen.size() && i < 10; ++i) {
      const auto& v = r.virtual_joint_screen[i];
      audit::CandidateResult named;
      named.effects = {v.effect};
      h << "<tr><td>" << HtmlEscape(v.effect) << "</td><td style=\"text-align:left\">"
        << HtmlEscape(audit::DescribeVirtualJoint(v.effect)) << "</td><td>" << FormatNumber(v.stiffness, 2)
        << "</td><td>" << FormatNumber(v.predicted_error, 4) << "</td><td>" << (v.fitted ? "yes" : "") << "</td></tr>\n";
    }
    h << "</table>\n";
  }
}

// index.html's noise model and usable band per FRF (with a noise model), and
// the overlays per posture; the end of the page.
void HtmlNoiseAndOverlays(const ReportInputs& in, const ReportBasis& b, std::ostream& h) {
  if (!in.noise.empty()) {
    h << "<h2>Noise model and usable band per FRF</h2><p>Lines used where |H| ≥ " << FormatNumber(in.ro.min_snr)
      << " × the additive noise floor (--min-snr).</p><table><tr><th>FRF</th><th>noise model</th></tr>\n";
    for (const auto& [key, n] : in.noise) {
      h << "<tr><td>" << HtmlEscape(KeyLabel(key)) << "</td><td style=\"text-align:left\">" << HtmlEscape(n.description)
        << "</td></tr>\n";
    }
    h << "</table>\n";
  }
  h << "<h2>Overlays per posture</h2><p>Measured FRFs (wide band), the " << HtmlEscape(b.before_label) << " (dashed)"
    << (b.shown ? " and the model " + HtmlEscape(b.after_label) + " (thin line)" : std::string())
    << "; vertical lines: the natural frequencies of the " << (b.shown ? "latter" : "model") << ".</p>\n";
  for (const auto& id : in.measured_fit.pose_ids()) {
    h << "<p><img src=\"overlay_" << HtmlEscape(b.stems.at(id)) << ".png\" alt=\"overlay " << HtmlEscape(id)
      << "\"></p>\n";
  }
  h << "</body></html>\n";
}

// ---- index.html (self-contained; PNGs by relative path): the verdict in
// one sentence and the worst FRF before and after first, the tables after.
std::string IndexHtml(const ReportInputs& in, const ReportBasis& b) {
  std::ostringstream h;
  HtmlHeadline(in, b, h);
  HtmlWhatToDo(in, b, h);
  HtmlVerdict(in, b, h);
  HtmlBaseline(in, b, h);
  HtmlErrorTables(in, b, h);
  HtmlModes(in, b, h);
  HtmlCandidates(in.r, h);
  HtmlNoiseAndOverlays(in, b, h);
  return h.str();
}

// The overlay `o` restricted to the FRF `wk`: the worst FRF's picture.
PostureOverlay OverlayOfFrf(const PostureOverlay& o, const dynamics::FrfKey& wk) {
  PostureOverlay w = o;
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
  return w;
}

// The overlay PNGs: one per posture, and the worst FRF alone.
void WriteOverlays(const fs::path& dir, const ReportInputs& in, const ReportBasis& b) {
  const audit::AuditResult& r = in.r;
  const audit::CandidateResult* shown = b.shown;
  const std::string& before_label = b.before_label;
  const std::string& after_label = b.after_label;
  dynamics::PostureEvaluator eb(b.base_model);
  std::unique_ptr<dynamics::PostureEvaluator> ea;
  if (shown) {
    const auto [desc, params] = audit::CandidateModel(in.description, *shown);
    ea = std::make_unique<dynamics::PostureEvaluator>(dynamics::RobotModel::Build(desc, params));
  }
  for (const std::string& pose : in.measured_fit.pose_ids()) {
    const auto db = eb.Evaluate(in.postures.at(pose));
    // Every measured line with its noise, not only the usable ones.
    PostureOverlay o = ea ? MakePostureOverlay(pose, in.measured_all, db,
                                                               ea->Evaluate(in.postures.at(pose)))
                                  : MakePostureOverlay(pose, in.measured_all, db);
    AddNoise(in.noise, &o);
    if (b.has_worst && pose == r.errors_before.curves[b.worst].key.pose_id) {
      // The worst FRF alone: its row of the posture's overlay.
      const dynamics::FrfKey& wk = r.errors_before.curves[b.worst].key;
      const PostureOverlay w = OverlayOfFrf(o, wk);
      WriteOverlayPng((dir / "worst_frf.png").string(), w,
                              "model-audit: worst FRF " + KeyLabel(wk) + ", measured vs " + before_label +
                                  (shown ? " and " + after_label : std::string()),
                              before_label, after_label);
    }
    WriteOverlayPng((dir / ("overlay_" + b.stems.at(pose) + ".png")).string(), o,
                            "model-audit: posture " + pose + ", measured vs " + before_label +
                                (shown ? " and " + after_label : std::string()),
                            before_label, after_label);
  }
}

// Files of an earlier run in this folder that this run does not
// rewrite would be taken for its results: remove them.
void RemoveStaleFiles(const fs::path& dir, const ReportBasis& b) {
  const AuditPatternFiles names;
  std::vector<fs::path> stale;
  std::set<std::string> poses;  // the file-name stems of this run's postures
  for (const auto& [id, stem] : b.stems) poses.insert(stem);
  if (b.yaml.empty()) stale.push_back(dir / "effects.yaml");
  if (b.pr.mode_error_map_png.empty()) stale.push_back(dir / names.mode_error_map_png);
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string n = entry.path().filename().string();
    if (n.rfind("overlay_", 0) == 0 && entry.path().extension() == ".png" &&
        !poses.count(n.substr(8, n.size() - 12))) {
      stale.push_back(entry.path());
    }
  }
  for (const auto& f : stale) fs::remove(f);
}

// The report's text files, complete before any file is written.
struct ReportTexts {
  json summary;
  std::string errors_csv, candidates_csv, index_html;
};

// Every file but the overlays, each written atomically.
void WriteFiles(const fs::path& dir, const ReportBasis& b, const ReportTexts& t) {
  const AuditPatternFiles names;
  const AuditPatternsReport& pr = b.pr;
  if (!b.yaml.empty()) {
    io::WriteFileAtomically((dir / "effects.yaml").string(), "# model-audit: add to the robot config\n" + b.yaml);
  }
  io::WriteFileAtomically((dir / "errors.csv").string(), t.errors_csv);
  io::WriteFileAtomically((dir / "candidates.csv").string(), t.candidates_csv);
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
  io::WriteFileAtomically((dir / "index.html").string(), t.index_html);
  io::WriteFileAtomically((dir / "summary.json").string(), DumpJson(t.summary));
}

}  // namespace

void AuditReportOptions::Validate() const {
  CheckOptionBand("fmin_hz", fmin_hz, "fmax_hz", fmax_hz);
}

AuditReport WriteAuditReport(const std::string& dir_path, const audit::AuditResult& r,
                             const dynamics::RobotDescription& description, const calibration::PostureMap& postures,
                             const dynamics::FrfSet& measured_fit, const dynamics::FrfSet& measured_all,
                             const calibration::NoiseModels& noise, const AuditReportOptions& ro) {
  ro.Validate();
  const ReportInputs in{r, description, postures, measured_fit, measured_all, noise, ro};
  const ReportBasis b = MakeBasis(in);
  ReportTexts t;
  t.summary = SummaryJson(in, b);
  t.errors_csv = ErrorsCsv(r, *b.after);
  t.candidates_csv = CandidatesCsv(r);
  t.index_html = IndexHtml(in, b);

  // ---- write (each file complete or absent)
  io::EnsureDirectory(dir_path);
  const fs::path dir(dir_path);
  WriteOverlays(dir, in, b);
  RemoveStaleFiles(dir, b);
  WriteFiles(dir, b, t);

  AuditReport out;
  out.summary = std::move(t.summary);
  out.effects_yaml = b.yaml;
  for (const auto& c : r.candidates) out.failed_candidate |= c.fit.status == calibration::FitStatus::kFailed;
  return out;
}

}  // namespace robomach::report
