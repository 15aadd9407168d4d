#include "robomach/workflows/frf_calibrate.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/option_validate.h"
#include "robomach/io/posture_file.h"
#include "robomach/workflows/frf_predict.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::workflows {
MeasuredFrfOptions MeasuredFilesRoute(const std::vector<std::string>& files,
                                      const std::vector<std::string>& pose_files, const std::string& pose_field,
                                      const std::string& pose_name, const std::string& what) {
  MeasuredFrfOptions o;
  o.files = files;
  for (const std::string& a : pose_files) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == a.size()) {
      throw OptionError(pose_field,
                        pose_field + " '" + a + "': expected ID=file.uff, e.g. " + pose_field + " P1=p1.uff");
    }
    o.posed_files.push_back({a.substr(0, eq), a.substr(eq + 1)});
  }
  o.what = what;
  o.pose_option = pose_name;
  return o;
}

void FrfNoiseOptions::Validate() const {
  CheckOptionRange("min_snr", min_snr, 1e-3, 1e6);
  CheckOptionRange("averages", averages, 0, 1e6);
  ParseNoiseModelChoice(noise_model);  // OptionError("noise_model", ...) naming the four
}

calibration::NoiseModels EstimateNoise(const MeasuredFrfs& data, const FrfNoiseOptions& noise,
                                       const MessageSink& tell) {
  noise.Validate();
  MeasuredFrfOptions w;
  w.noise_model = ParseNoiseModelChoice(noise.noise_model);
  w.min_snr = noise.min_snr;
  w.averages = noise.averages;
  w.drift_floor = noise.drift_floor;
  return EstimateNoiseModels(data, w, tell);
}

void FrfCalibrateOptions::Validate() const {
  if (robot_path.empty()) throw OptionError("robot_path", "robot_path: a robot config is required");
  if (postures_path.empty()) throw OptionError("postures_path", "postures_path: a posture file is required");
  CheckOptionRange("max_iterations", max_iterations, 1, 100000);
  CheckOptionRange("robust_loss_sigma", robust_loss_sigma, 0.0, 1e6);
  // The band before the files are read: 0 <= fmin_hz < fmax_hz (fmax_hz may
  // be +inf, all lines), naming both values.
  CheckOptionBand("fmin_hz", fmin_hz, "fmax_hz", fmax_hz);
  if (measured_files.empty() && pose_files.empty()) {
    throw OptionError("measured_files", "no measured FRFs: give measured_files FILE or pose_files ID=file.uff");
  }
  try {
    calibration::ParseObjective(objective);
  } catch (const std::invalid_argument& e) {
    throw OptionError("objective", std::string("objective: ") + e.what());
  }
  if (only_free && frees.empty()) throw OptionError("only_free", "no free parameters (only_free without frees)");
  // The noise fields are the tools' own options (--min-snr ...): their
  // fields stay unprefixed, as the tools map them.
  noise.Validate();
}

calibration::CalibrationOptions FrfCalibrateOptions::Calibration() const {
  calibration::CalibrationOptions c;
  c.objective = calibration::ParseObjective(objective);
  if (only_free) c.free_parameters.clear();
  for (const std::string& f : frees) {
    if (std::find(c.free_parameters.begin(), c.free_parameters.end(), f) == c.free_parameters.end()) {
      c.free_parameters.push_back(f);
    }
  }
  c.fmin_hz = c.modal_fit.fmin_hz = fmin_hz;
  c.fmax_hz = c.modal_fit.fmax_hz = fmax_hz;
  c.max_iterations = max_iterations;
  c.robust_scale = robust_loss_sigma;
  return c;
}

nlohmann::json FrfCalibrateRun::Misfit() const {
  return {{"start", result.misfit_start},
          {"calibrated", result.misfit_final},
          {"rms_per_residual_in_noise_units", verdict.rms_per_residual_in_noise_units},
          {"starts_tried", result.starts_tried},
          {"start_used", result.start_used},
          {"flags", flags}};
}

std::vector<std::string> FrfCalibrateRun::ResultLines() const {
  std::vector<std::string> lines;
  auto matching = [&](const std::string& label, const calibration::Comparison& before,
                      const calibration::Comparison& after) {
    std::ostringstream m;
    m.precision(3);
    m << label << ": " << after.matches.size() << " matched modes; largest error after calibration: frequency "
      << 100 * after.max_abs_freq_error << " %, peak amplitude " << 100 * after.max_abs_peak_error << " % (before: "
      << 100 * before.max_abs_freq_error << " %, " << 100 * before.max_abs_peak_error << " %)";
    lines.push_back(m.str());
  };
  matching("fit", fit_before, fit_after);
  if (!holdout.empty()) matching("holdout", holdout_before, holdout_after);
  for (const auto& e : result.estimates) {
    std::ostringstream m;
    m.precision(6);
    m << e.name << " = " << e.value << " ± " << e.std_dev << " " << e.unit << " (start " << e.initial << ")"
      << (e.weakly_identified ? " WEAKLY IDENTIFIED" : "") << (e.at_bound ? " AT BOUND" : "");
    lines.push_back(m.str());
  }
  std::ostringstream m;
  m.precision(4);
  m << "whole-curve misfit (chi^2";
  if (!noise.empty()) m << ", in units of the noise";
  m << ") " << result.misfit_start << " at the start, " << result.misfit_final << " calibrated ("
    << result.starts_tried << " start" << (result.starts_tried > 1 ? "s" : "") << ", result from: "
    << result.start_used << ")";
  lines.push_back(m.str());
  return lines;
}

FrfCalibrateRun RunFrfCalibrate(const FrfCalibrateOptions& o, const MessageSink& tell) {
  o.Validate();
  FrfCalibrateRun r;
  r.options = o.Calibration();
  r.config = workflows::LoadRobotConfigChecked(o.robot_path);
  for (const std::string& w : r.config.implausible) Tell(tell, Message::Kind::kWarning, w);
  ApplyAddsAndSets(o.adds, o.sets, &r.config);
  for (const std::string& name : r.options.free_parameters) {
    if (!r.config.parameters.Has(name)) {
      throw OptionError("frees", "frees " + name + ": unknown parameter; known: " + r.config.parameters.NameList());
    }
  }
  r.model_before = r.config.Build();
  std::vector<std::string> posture_units;  // radians under _deg headers, ...
  for (const io::Posture& p : io::ReadPostureFile(o.postures_path, r.model_before->num_joints(), &posture_units)) {
    r.postures[p.id] = p.q;
  }
  r.measured_read = ReadMeasuredFrfFiles(
      MeasuredFilesRoute(o.measured_files, o.pose_files, "pose_files", o.pose_files_name, "measured FRF file"), tell);
  r.holdout_read = ReadMeasuredFrfFiles(MeasuredFilesRoute(o.validate_files, o.validate_pose_files,
                                                           "validate_pose_files", o.validate_pose_files_name,
                                                           "validation FRF file"),
                                        tell);
  for (const auto* set : {&r.measured_read.frfs, &r.holdout_read.frfs}) {
    for (const std::string& id : set->pose_ids()) {
      if (!r.postures.count(id)) {
        std::string known;
        for (const auto& [k, q] : r.postures) known += (known.empty() ? "" : ", ") + k;
        throw InputError({o.postures_path, 0, 0}, "posture " + id + " of the " +
                                                      (set == &r.measured_read.frfs ? "measured" : "validation") +
                                                      " FRFs is not in this posture file (it has " + known + ")");
      }
    }
  }
  // The noise of every FRF, and the lines every fit uses (issue #10).
  r.noise = EstimateNoise(r.measured_read, o.noise, tell);
  r.measured = FitData(r.measured_read, r.noise);
  if (!r.holdout_read.frfs.empty()) {
    r.holdout_noise = EstimateNoise(r.holdout_read, o.noise, tell);
    r.holdout = FitData(r.holdout_read, r.holdout_noise);
  }
  // Overlays show every measured line with the noise model, not only the usable ones.
  r.all_measured = r.measured_read.frfs;
  r.all_noise = r.noise;
  for (const auto& [k, f] : r.holdout_read.frfs) {
    if (!r.all_measured.contains(k)) r.all_measured.Insert(k, f);
  }
  for (const auto& [k, n] : r.holdout_noise) r.all_noise.emplace(k, n);

  const calibration::CalibrationOptions& opt = r.options;
  Tell(tell, Message::Kind::kInfo, "modal fit of " + std::to_string(r.measured.size()) + " measured FRFs");
  r.features = calibration::ExtractFeatures(r.measured, opt.modal_fit);
  for (const auto& [key, fit] : r.features.fits) {
    if (fit.status != SolverStatus::kConverged) {
      Tell(tell, Message::Kind::kWarning, "modal fit of " + key.ToString() + ": " + fit.message);
    }
  }
  std::string line = "calibrating (" + calibration::ToString(opt.objective) + ") ";
  for (const auto& n : opt.free_parameters) line += n + ' ';
  Tell(tell, Message::Kind::kInfo, line);
  r.result = calibration::Calibrate(r.config.description, r.config.parameters, r.postures, r.measured, r.features, opt);
  r.model_after = dynamics::RobotModel::Build(r.config.description, r.result.parameters);
  auto compare = [&](const std::shared_ptr<const dynamics::RobotModel>& model, const dynamics::FrfSet& data,
                     const calibration::MeasuredFeatures& features) {
    return calibration::CompareWithMeasurement(model, r.postures, data, features, opt.matching, opt.fmin_hz,
                                               opt.fmax_hz);
  };
  r.fit_before = compare(r.model_before, r.measured, r.features);
  r.fit_after = compare(r.model_after, r.measured, r.features);
  if (!r.holdout.empty()) {
    r.holdout_features = calibration::ExtractFeatures(r.holdout, opt.modal_fit);
    r.holdout_before = compare(r.model_before, r.holdout, r.holdout_features);
    r.holdout_after = compare(r.model_after, r.holdout, r.holdout_features);
  }

  bool effects_left_out = false;
  r.config_text = io::CalibratedConfigText(
      o.robot_path, o.out_path,
      io::ParametersYaml(r.result.parameters, dynamics::DefaultParameters(r.config.description)), o.adds,
      &effects_left_out);
  if (effects_left_out) {
    Tell(tell, Message::Kind::kWarning,
         "the config already has an `effects:` list; add the effects given with --add to " + o.out_path +
             " by hand");
  }
  r.verdict = calibration::JudgeCalibration(r.result, r.measured, opt);
  r.flags = r.measured_read.unit_findings;  // implausible units, warned when read
  r.flags.insert(r.flags.end(), r.holdout_read.unit_findings.begin(), r.holdout_read.unit_findings.end());
  r.flags.insert(r.flags.end(), r.config.implausible.begin(), r.config.implausible.end());  // warned when read
  for (const std::string& w : posture_units) {
    Tell(tell, Message::Kind::kWarning, w);
    r.flags.push_back(w);
  }
  for (const Finding& f : r.verdict.verdict.findings) {
    Tell(tell, Message::Kind::kWarning, f.message);
    r.flags.push_back(f.message);
  }
  return r;
}

}  // namespace robomach::workflows
