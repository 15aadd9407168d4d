#include "robomach/workflows/model_audit.h"

#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/dynamics/effect.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::workflows {
namespace {

// The tools' range message ("fmin_hz: expected a value in [0, 1e+09], got
// -1"), which the tool words with its option.
void CheckRange(const std::string& field, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi)) {
    std::ostringstream s;
    s << field << ": expected a value in [" << lo << ", " << hi << "], got " << value;
    throw OptionError(field, s.str());
  }
}

}  // namespace

void ModelAuditOptions::Validate() const {
  if (robot_path.empty()) throw OptionError("robot_path", "robot_path: a robot config is required");
  if (postures_path.empty()) throw OptionError("postures_path", "postures_path: a posture file is required");
  CheckRange("fmin_hz", fmin_hz, 0.0, 1e9);
  if (!(fmax_hz > fmin_hz)) {
    throw OptionError("fmax_hz", "fmax_hz must be above fmin_hz (" + FormatNumber(fmin_hz) + " Hz), got " +
                                     FormatNumber(fmax_hz));
  }
  CheckRange("max_iterations", max_iterations, 1, 100000);
  CheckRange("virtual_joints", virtual_joints, 0, 50);
  CheckRange("robust_loss_sigma", robust_loss_sigma, 0.0, 1e6);
  if (!(confidence > 0.0 && confidence < 1.0)) {
    throw OptionError("confidence", "confidence: expected a level between 0 and 1 (0.95 for 95 %), got " +
                                        FormatNumber(confidence));
  }
  std::set<std::string> seen;
  for (const std::string& a : adds) {
    if (!seen.insert(a).second) throw OptionError("adds", "adds " + a + " is given twice");
  }
  if (measured_files.empty() && pose_files.empty()) {
    throw OptionError("measured_files", "no measured FRFs: give measured_files FILE or pose_files ID=file.uff");
  }
  for (const std::string& n : candidates) {
    const bool is_parameter = n.rfind("kq", 0) == 0 && n.find('.') == std::string::npos;
    if (is_parameter || n.empty()) continue;
    try {
      dynamics::EffectRegistry::Instance().Create(n);
    } catch (const std::invalid_argument& e) {
      throw OptionError("candidates", std::string("candidates: ") + e.what());
    }
  }
  noise.Validate();  // the tool's own --min-snr ...: unprefixed fields, as the tool maps them
}

ModelAuditRun RunModelAudit(const ModelAuditOptions& o, const MessageSink& tell,
                            const std::function<void(const std::string&)>& progress) {
  o.Validate();
  ModelAuditRun r;
  audit::AuditOptions& opt = r.audit_options;
  opt.candidates = o.candidates;
  opt.fmin_hz = o.fmin_hz;
  opt.fmax_hz = o.fmax_hz;
  opt.max_iterations = o.max_iterations;
  opt.robust_scale = o.robust_loss_sigma;
  opt.virtual_joints_fitted = o.virtual_joints;
  opt.try_parameters = !o.no_parameter_hypotheses;
  opt.uncertainty_confidence = o.confidence;
  opt.progress = progress;

  r.config = workflows::LoadRobotConfigChecked(o.robot_path);
  for (const std::string& w : r.config.implausible) Tell(tell, Message::Kind::kWarning, w);
  io::RobotConfig& cfg = r.config;
  for (const std::string& name : o.adds) {
    try {
      std::tie(cfg.description, cfg.parameters) = audit::WithEffect(cfg.description, cfg.parameters, name);
    } catch (const std::invalid_argument& e) {
      throw OptionError("adds", "adds " + name + ": " + e.what());
    }
    // An effect switched on here starts at its defaults, so its fittable
    // parameters are calibrated with the others.
    for (const auto& spec : cfg.parameters.specs()) {
      if (spec.fittable && spec.name.rfind(name + ".", 0) == 0) opt.calibration_parameters.push_back(spec.name);
    }
  }
  {
    // The parameters' uncertainty (issue #37 §4), its estimates the audited values.
    const std::vector<std::string>& paths = o.uncertainty_paths.empty() ? cfg.uncertainty_files : o.uncertainty_paths;
    if (!paths.empty()) {
      opt.parameter_uncertainty = io::ReadParameterUncertainties(paths);
      std::string changed;
      try {
        changed = dynamics::UseEstimates(opt.parameter_uncertainty, &cfg.parameters);
      } catch (const std::invalid_argument& e) {
        throw OptionError("uncertainty_paths", std::string("uncertainty_paths: ") + e.what());
      }
      if (!changed.empty()) Tell(tell, Message::Kind::kNote, changed);
    }
  }
  for (const io::Posture& p : io::ReadPostureFile(o.postures_path, cfg.description.arm.num_joints())) {
    r.postures[p.id] = p.q;
  }
  r.measured_read = ReadMeasuredFrfFiles(
      MeasuredFilesRoute(o.measured_files, o.pose_files, "pose_files", o.pose_files_name, "measured FRF file"), tell);
  for (const auto& [key, frf] : r.measured_read.frfs) {
    if (!r.postures.count(key.pose_id)) {
      throw InputError({o.postures_path, 0, 0}, "posture " + key.pose_id + " of " + r.measured_read.file.at(key) +
                                                    " is not in this posture file");
    }
  }
  // The noise of every FRF and the lines every fit and error uses (issue #10).
  r.noise = EstimateNoise(r.measured_read, o.noise, tell);
  r.measured = FitData(r.measured_read, r.noise);  // throws when no FRF has a usable line
  {
    int lines = 0;
    for (const auto& [key, frf] : r.measured) lines += frf.Band(o.fmin_hz, o.fmax_hz).size();
    if (lines < 3) {
      throw InputError({r.measured_read.file.begin()->second, 0, 0},
                       "the measured FRFs have " + std::to_string(lines) + " lines in the band " +
                           FormatNumber(o.fmin_hz) + ".." + FormatNumber(o.fmax_hz) +
                           " Hz (--fmin-hz, --fmax-hz); need at least 3");
    }
  }

  r.audit = audit::RunAudit(cfg.description, cfg.parameters, r.postures, r.measured, opt);
  const audit::AuditResult& a = r.audit;
  if (a.baseline_fit.status != SolverStatus::kConverged) {
    Tell(tell, Message::Kind::kWarning,
         "the calibration of the current model did not converge (" + a.baseline_fit.message +
             "); its errors are those of the last iterate");
  }
  // The change the audit names (the tool's --write-config and
  // --uncertainty-out): the named candidate, or with no failure the
  // calibrated current model.
  const audit::CandidateResult* named =
      a.grade == audit::AuditGrade::kExplained || a.grade == audit::AuditGrade::kMostlyExplained
          ? audit::AcceptedCandidate(a)
          : nullptr;
  if (named) {
    r.change = *named;
    r.change_description = audit::DescribeCandidate(*named, a.configured);
  } else if (a.grade == audit::AuditGrade::kNoFailure) {
    r.change.emplace();
    r.change->fit = a.baseline_fit;
    r.change_description = "the calibrated current model";
  }
  if (!o.write_config.empty() && r.change) {
    // The config with the named change (issue #33 §6): built and checked
    // (loaded back) before anything is written.
    const auto [desc, params] = audit::CandidateModel(cfg.description, *r.change);
    std::vector<std::string> effects = o.adds;
    for (const std::string& e : r.change->effects) effects.push_back(e);
    bool left_out = false;
    r.config_text = io::CalibratedConfigText(
        o.robot_path, o.write_config, io::ParametersYaml(params, dynamics::DefaultParameters(desc)), effects,
        &left_out,
        "Written by robomach model-audit --write-config: " + r.change_description +
            ", with the calibration values fitted with it.");
    if (left_out) {
      std::string l;
      for (const auto& e : effects) l += (l.empty() ? "" : ", ") + e;
      Tell(tell, Message::Kind::kWarning,
           "the config's `effects:` list is a flow list; add " + l + " to " + o.write_config + " by hand");
    }
  }
  r.verdict = audit::JudgeAudit(a);
  return r;
}

}  // namespace robomach::workflows
