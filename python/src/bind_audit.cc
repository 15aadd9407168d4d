// Python bindings of the model audit (model-audit's call) and of its report
// folder (docs/python.md).
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "robomach/audit/model_audit.h"
#include "robomach/io/robot_config.h"
#include "robomach/report/audit_report.h"
#include "robomach/report/json.h"
#include "robomach/workflows/model_audit.h"

namespace robomach::python {

namespace {

// A result as plain Python objects: numbers, strings, lists and dicts.
py::dict ResultDict(const audit::AuditResult& r) {
  auto number = [](double v) -> py::object { return std::isfinite(v) ? py::object(py::float_(v)) : py::none(); };
  py::dict d;
  d["grade"] = audit::ToString(r.grade);
  d["headline"] = r.headline;
  d["verdict"] = r.verdict;
  d["pattern"] = r.pattern;
  d["explained"] = r.explained;
  d["significant_failure"] = r.significant_failure;
  d["missing_effects"] = r.missing_effects;
  d["candidate"] = r.graded >= 0 ? py::object(py::str(r.candidates[r.graded].name())) : py::none();
  d["error_before"] = r.errors_before.total_rms_log_mag;
  // As summary.json's error_after: with the accepted candidate, else before.
  const audit::CandidateResult* accepted = audit::AcceptedCandidate(r);
  d["error_after"] = accepted ? accepted->errors.total_rms_log_mag : r.errors_before.total_rms_log_mag;
  d["noise_floor"] = r.noise_floor;
  d["error_before_noise_units"] = number(r.error_before_noise_units);
  d["remainder_noise_units"] = number(r.remainder_noise_units);
  d["fraction_removed"] = number(r.fraction_removed);
  d["bic_gap"] = number(r.bic_gap);
  d["runner_up"] = r.runner_up;
  d["reasons"] = r.reasons;
  d["next_steps"] = r.next_steps;
  d["warnings"] = r.warnings;
  py::list changes;
  for (const auto& pc : r.parameter_changes) {
    py::dict c;
    c["name"] = pc.name;
    c["unit"] = pc.unit;
    c["configured"] = pc.configured;
    c["fitted"] = number(pc.fitted);
    c["std"] = number(pc.std_dev);
    c["ratio"] = number(pc.ratio());
    changes.append(c);
  }
  d["parameter_changes"] = changes;
  d["description"] = r.graded >= 0 ? py::object(py::str(audit::DescribeCandidate(r.candidates[r.graded], r.configured)))
                                   : py::none();
  py::list on_bound;
  for (const auto& f : r.baseline_on_bound) on_bound.append(f.message);
  d["baseline_on_bound"] = on_bound;
  d["error_configured"] = r.errors_configured.total_rms_log_mag;
  py::list screen;
  for (const auto& s : r.virtual_joint_screen) {
    py::dict sd;
    sd["effect"] = s.effect;
    sd["stiffness"] = number(s.stiffness);
    sd["predicted_error"] = number(s.predicted_error);
    sd["fitted"] = s.fitted;
    screen.append(sd);
  }
  d["virtual_joint_screen"] = screen;
  if (r.uncertainty) {
    // Issue #37 §4: what the parameters' own uncertainty allows.
    const audit::UncertaintyAllowance& u = *r.uncertainty;
    py::dict ud, values;
    for (const auto& n : u.parameters) values[py::str(n)] = u.at.Get(n);
    ud["parameters"] = u.parameters;
    ud["left_out"] = u.left_out;
    ud["confidence"] = u.confidence;
    ud["rank"] = u.rank;
    ud["chi2"] = u.chi2;
    ud["distance"] = number(u.distance);
    ud["radius"] = number(u.radius);
    ud["values_at_most_favourable_point"] = values;
    ud["error_noise_units"] = number(u.error_noise_units);
    ud["fraction_removed"] = number(u.fraction_removed);
    ud["covers_failure"] = u.covers_failure;
    ud["sentence"] = u.sentence;
    d["parameter_uncertainty"] = ud;
  } else {
    d["parameter_uncertainty"] = py::none();
  }
  const RunFindings verdict = audit::JudgeAudit(r);
  d["status"] = robomach::ToString(verdict.status());
  d["findings"] = FindingMessages(verdict);
  py::list cands;
  for (const auto& c : r.candidates) {
    py::dict cd;
    cd["name"] = c.name();
    cd["effects"] = c.effects;
    cd["freed_parameters"] = c.parameters;
    cd["bic_change"] = c.bic_change;
    cd["error_after"] = c.errors.total_rms_log_mag;
    cd["plausible"] = c.plausible;
    cd["note"] = c.note;
    py::dict params;
    for (const auto& e : c.fit.estimates) params[py::str(e.name)] = py::make_tuple(e.value, e.std_dev);
    cd["parameters"] = params;
    cands.append(cd);
  }
  d["candidates"] = cands;
  const audit::CandidateResult* best = audit::AcceptedCandidate(r);
  d["effects_yaml"] = best ? audit::EffectYaml(*best) : std::string();
  return d;
}

}  // namespace

void BindAudit(py::module_& m) {
  m.def("audit", [](const io::RobotConfig& config, const std::map<std::string, Eigen::VectorXd>& postures,
                    const dynamics::FrfSet& measured, const std::map<KeyTuple, calibration::FrfNoise>& noise,
                    const std::optional<std::string>& report_dir, const std::vector<std::string>& candidates,
                    const std::vector<std::string>& calibration_parameters, double fmin_hz, double fmax_hz,
                    int max_iterations, const std::optional<dynamics::FrfSet>& measured_all,
                    const std::optional<dynamics::ParameterUncertainty>& uncertainty, double confidence) {
    audit::AuditOptions o;
    io::RobotConfig cfg = config;
    if (uncertainty) {
      // As model-audit: the file's estimates are the audited values.
      o.parameter_uncertainty = *uncertainty;
      dynamics::UseEstimates(*uncertainty, &cfg.parameters);
    }
    o.uncertainty_confidence = confidence;
    o.candidates = candidates;
    o.calibration_parameters = calibration_parameters;
    o.fmin_hz = fmin_hz;
    o.fmax_hz = fmax_hz;
    o.max_iterations = max_iterations;
    calibration::NoiseModels n;
    for (const auto& [k, v] : noise) n.emplace(ToKey(k), v);
    const calibration::PostureMap q(postures.begin(), postures.end());
    for (const auto& [key, frf] : measured) {
      if (!q.count(key.pose_id)) throw std::invalid_argument("posture " + key.pose_id + " of a measured FRF is not in postures");
    }
    audit::AuditResult r;
    report::AuditReport rep;
    {
      py::gil_scoped_release release;
      r = audit::RunAudit(cfg.description, cfg.parameters, q, measured, o);
      if (report_dir) {
        report::AuditReportOptions ro;
        ro.robot_path = config.path;
        ro.noise_model = n.empty() ? "none" : "given";
        ro.min_snr = calibration::NoiseOptions{}.min_snr;
        ro.fmin_hz = fmin_hz;
        ro.fmax_hz = fmax_hz;
        ro.mostly_explained_fraction = o.mostly_explained_fraction;
        ro.clear_bic_gap = o.clear_bic_gap;
        rep = report::WriteAuditReport(*report_dir, r, config.description, q, measured,
                                       measured_all ? *measured_all : measured, n, ro);
      }
    }
    py::dict d = ResultDict(r);
    if (report_dir) {
      d["report"] = *report_dir;
      d["summary"] = py::module_::import("json").attr("loads")(report::DumpJson(rep.summary));
    }
    return d;
  }, py::arg("config"), py::arg("postures"), py::arg("measured"),
     py::arg("noise") = std::map<KeyTuple, calibration::FrfNoise>{}, py::arg("report_dir") = py::none(),
     py::arg("candidates") = std::vector<std::string>{},
     py::arg("calibration_parameters") = audit::AuditOptions{}.calibration_parameters, py::arg("fmin_hz") = 0.0,
     py::arg("fmax_hz") = std::numeric_limits<double>::infinity(), py::arg("max_iterations") = 100,
     py::arg("measured_all") = py::none(), py::arg("uncertainty") = py::none(), py::arg("confidence") = 0.95,
     "model-audit's call: calibrates `config` (RobotConfig) against `measured` (FrfSet, receptance "
     "[m/N]; usable_data(...) of it, as the tool fits) at `postures` ({pose_id: q [rad]}), tries each "
     "library effect not in the model (or `candidates`) and grades the best. Returns a dict of plain "
     "Python objects: grade, headline, verdict, explained, missing_effects, candidate, errors "
     "(rms of ln|H| differences; in units of the noise when the FRFs carry sigma), candidates (name, "
     "bic_change, error_after, plausible, note, parameters {name: (value, std)}), effects_yaml, and status ('ok' "
     "or 'flagged': model-audit's exit 3 but for the unit checks of its reader) with its findings. "
     "With report_dir it also writes model-audit's report folder there (noise: the noise models of "
     "estimate_noise; measured_all: every measured line for the overlays) and adds 'report' and "
     "'summary' (summary.json as a dict). uncertainty (ParameterUncertainty, e.g. read_parameter_uncertainty of "
     "kq-identify's file; its estimates replace the config's values) adds 'parameter_uncertainty': which part of "
     "the misfit those parameters could explain within their `confidence` region (model-audit --uncertainty; None "
     "without one or without a significant failure). Releases the GIL (seconds to minutes).");

  const workflows::ModelAuditOptions kAudit;  // model-audit's defaults
  m.def("run_model_audit",
        [](const std::string& robot, const std::string& postures, const std::vector<std::string>& measured,
           const std::vector<std::string>& pose, const std::vector<std::string>& adds,
           const std::vector<std::string>& uncertainty, double confidence, const std::vector<std::string>& candidates,
           bool no_parameter_hypotheses, int virtual_joints, double fmin_hz, double fmax_hz, int max_iterations,
           double robust_loss_sigma, const std::string& noise_model, double min_snr, int averages, bool drift_floor,
           const std::optional<std::string>& write_config, const std::optional<std::string>& report_dir) {
          workflows::ModelAuditOptions o;
          o.robot_path = robot;
          o.postures_path = postures;
          o.measured_files = measured;
          o.pose_files = pose;
          o.pose_files_name = "pose";
          o.adds = adds;
          o.uncertainty_paths = uncertainty;
          o.confidence = confidence;
          o.candidates = candidates;
          o.no_parameter_hypotheses = no_parameter_hypotheses;
          o.virtual_joints = virtual_joints;
          o.fmin_hz = fmin_hz;
          o.fmax_hz = fmax_hz;
          o.max_iterations = max_iterations;
          o.robust_loss_sigma = robust_loss_sigma;
          o.noise = {noise_model, min_snr, averages, drift_floor};
          o.write_config = write_config.value_or("");
          o.Validate();
          RequireReadableFile(robot);
          RequireReadableFile(postures);
          for (const std::string& f : measured) RequireReadableFile(f);
          for (const std::string& f : pose) {
            if (f.find('=') != std::string::npos) RequireReadableFile(f.substr(f.find('=') + 1));
          }
          for (const std::string& f : uncertainty) RequireReadableFile(f);
          CollectedMessages said;
          workflows::ModelAuditRun run;
          report::AuditReport rep;
          {
            py::gil_scoped_release release;
            run = workflows::RunModelAudit(o, said.Sink());
            if (report_dir) {
              // model-audit's report folder with the options the tool gives it.
              report::AuditReportOptions ro;
              ro.robot_path = o.robot_path;
              ro.added_effects = o.adds;
              ro.noise_model = o.noise.noise_model;
              ro.min_snr = o.noise.min_snr;
              ro.fmin_hz = o.fmin_hz;
              ro.fmax_hz = o.fmax_hz;
              ro.mostly_explained_fraction = run.audit_options.mostly_explained_fraction;
              ro.clear_bic_gap = run.audit_options.clear_bic_gap;
              if (!o.write_config.empty() && run.change) ro.written_config = o.write_config;
              for (const Message& msg : said.messages) {
                if (msg.kind == Message::Kind::kWarning) ro.input_warnings.push_back(msg.text);
              }
              rep = report::WriteAuditReport(*report_dir, run.audit, run.config.description, run.postures,
                                             run.measured, run.measured_read.frfs, run.noise, ro);
            }
          }
          for (const std::string& f : run.config.implausible) WarnUnit(f);
          for (const std::string& f : run.measured_read.unit_findings) WarnUnit(f);
          py::dict d = ResultDict(run.audit);
          d["change_description"] = run.change_description;
          d["config_text"] = run.config_text;
          d["messages"] = said.List();
          d["unit_findings"] = run.measured_read.unit_findings;
          d["status"] = robomach::ToString(run.status());
          d["findings"] = FindingMessages(run.verdict);
          d["flagged"] = run.flagged();
          if (report_dir) {
            d["report"] = *report_dir;
            d["effects_yaml"] = rep.effects_yaml;
            d["summary"] = py::module_::import("json").attr("loads")(rep.summary.dump());
          }
          return d;
        },
        py::arg("robot"), py::arg("postures"), py::arg("measured") = std::vector<std::string>{},
        py::arg("pose") = std::vector<std::string>{}, py::arg("adds") = std::vector<std::string>{},
        py::arg("uncertainty") = std::vector<std::string>{}, py::arg("confidence") = kAudit.confidence,
        py::arg("candidates") = std::vector<std::string>{},
        py::arg("no_parameter_hypotheses") = kAudit.no_parameter_hypotheses,
        py::arg("virtual_joints") = kAudit.virtual_joints, py::arg("fmin_hz") = kAudit.fmin_hz,
        py::arg("fmax_hz") = kAudit.fmax_hz, py::arg("max_iterations") = kAudit.max_iterations,
        py::arg("robust_loss_sigma") = kAudit.robust_loss_sigma, py::arg("noise_model") = kAudit.noise.noise_model,
        py::arg("min_snr") = kAudit.noise.min_snr, py::arg("averages") = kAudit.noise.averages,
        py::arg("drift_floor") = kAudit.noise.drift_floor, py::arg("write_config") = py::none(),
        py::arg("report") = py::none(),
        "model-audit as one call (workflows::RunModelAudit): a robot config, a posture file and measured FRF files "
        "(measured: CSV or UFF58; pose: 'ID=file.uff' of one posture), the tool's options under their names without "
        "dashes (adds: --add; uncertainty: --uncertainty files, none: the config's). Returns audit()'s dict of the "
        "result plus change_description, config_text (the config with the named change, with write_config: its "
        "relative urdf path made valid from there; not written), messages ({kind, text}), unit_findings (the measured "
        "receptances'; with the config's, also as UnitWarning), status/findings/flagged (the tool's exit 3 but for "
        "--uncertainty-out); with report (a folder) it writes model-audit's report there and adds report, "
        "effects_yaml and summary (summary.json as a dict, as the tool writes it). ValueError naming the option; "
        "FileNotFoundError, InputError for files. Releases the GIL (seconds to minutes).");
}

}  // namespace robomach::python
