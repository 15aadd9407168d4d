// Example: the model-audit loop on data with a known answer.
//
// A model is only as good as its agreement with measurements. The audit
// compares a robot model's tool-tip FRFs with hammer-test FRFs, says whether
// it fails beyond the measurement noise and which physical effect of the
// library, added and fitted, explains the failure. Here the "measurement" is
// made by a virtual hammer test of the same robot with a hidden effect (a
// 0.5 kg mass at the tool tip), so we know the right answer:
//   1. make the measured FRFs (SynthesizeHammerTest, 2 % noise);
//   2. give them a noise model, so errors are in units of the noise;
//   3. audit the configured model: verdict and ranked candidates;
//   4. add the named effect, refit, and compare the error before and after.
//
// Usage: audit_loop [robot.yaml [postures.csv]]
// (defaults: config/kr210.yaml and config/postures_demo.csv of the source
// tree). The model-audit tool runs this loop on measured files
// (docs/model-audit.md); scripts/demo.sh runs it on the shipped demo data.
// Ceres may log a line about a rank-deficient covariance on stderr (through
// glog; the tools and the Python module silence it): the fits report their
// own status.
#include <cstdio>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include "robomach/audit/model_audit.h"
#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"

namespace rm = robomach;

int main(int argc, char** argv) try {
  const std::string robot_path = argc > 1 ? argv[1] : ROBOMACH_SOURCE_DIR "/config/kr210.yaml";
  const std::string postures_path = argc > 2 ? argv[2] : ROBOMACH_SOURCE_DIR "/config/postures_demo.csv";

  // The model as configured, and the postures of the test (q in radians).
  const rm::io::RobotConfig config = rm::io::LoadRobotConfig(robot_path);
  std::vector<rm::calibration::NamedPosture> poses;
  rm::calibration::PostureMap postures;  // pose_id -> q, what fits and audits take
  for (const rm::io::Posture& p : rm::io::ReadPostureFile(postures_path, config.description.arm.num_joints())) {
    poses.push_back({p.id, p.q});
    postures[p.id] = p.q;
  }

  // 1. The truth: the configured robot with an effect switched on. WithEffect
  // returns a new description and parameter set (the model is immutable);
  // effect parameters are named "<effect>.<parameter>".
  auto [truth_description, truth_parameters] =
      rm::dynamics::WithEffect(config.description, config.parameters, "tip_mass");
  truth_parameters.Set("tip_mass.mass_kg", 0.5);
  rm::calibration::VirtualHammerOptions hammer;  // 0.25..500 Hz every 0.25 Hz, Hxx and Hyy
  hammer.relative_noise = 0.02;                  // 2 % rms on every line
  hammer.seed = 7;                               // deterministic
  const rm::dynamics::FrfSet synthesized = rm::calibration::SynthesizeHammerTest(
      rm::dynamics::RobotModel::Build(truth_description, truth_parameters), poses, hammer);

  // 2. The noise model of each FRF (from the scatter between lines, or the
  // coherence when a file has one) and the lines above the noise floor.
  // Every error below is then in units of the noise: 1 is a model that is
  // right.
  const rm::dynamics::FrfSet measured =
      rm::calibration::UsableData(synthesized, rm::calibration::EstimateNoise(synthesized));
  std::printf("measured: %d FRFs at %zu postures\n", measured.size(), poses.size());

  // 3. The audit. It first calibrates the configured model (m6, d6 and the
  // Rayleigh damping are always free), then adds each candidate, fits it
  // with the calibration parameters and ranks the candidates by BIC. By
  // default every library effect, the joint stiffnesses and compliance
  // anywhere along the arm are tried; this example names a short list of
  // effects to stay fast (each candidate fit takes seconds).
  rm::audit::AuditOptions options;
  options.candidates = {"tip_mass", "flange_compliance", "tool_flexibility"};
  const rm::audit::AuditResult audit =
      rm::audit::RunAudit(config.description, config.parameters, postures, measured, options);
  std::printf("verdict: %s (%s)\n", rm::audit::ToString(audit.grade).c_str(), audit.headline.c_str());
  std::printf("  rank  candidate            BIC change  error [noise units]\n");
  for (std::size_t i = 0; i < audit.candidates.size(); ++i) {
    const rm::audit::CandidateResult& c = audit.candidates[i];
    std::printf("  %4zu  %-20s %10.1f  %.2f%s\n", i + 1, c.name().c_str(), c.bic_change,
                c.errors.total_rms_log_mag / audit.noise_floor, c.plausible ? "" : "  (not plausible)");
  }
  if (audit.missing_effects.empty()) {
    std::printf("nothing to add\n");
    return 0;
  }

  // 4. Add the named effect to the model and refit. The audit has done this
  // fit already (audit::CandidateModel(config.description,
  // audit.candidates[audit.best]) is that model in one call); doing it by
  // hand shows the calls a user makes with the next measurement campaign:
  // switch the effect on, free its fittable parameters with the calibration
  // ones, and fit the whole curve (log magnitude and phase, weighted by the
  // noise). The fit starts from the calibrated model, whose m6 has taken up
  // part of the missing tip mass; it gives it back. The measured modes
  // (audit.features, a modal fit of every FRF) are what a modal objective
  // would match; the audit has them already.
  const std::string effect = audit.missing_effects.front();
  auto [description, start] =
      rm::dynamics::WithEffect(config.description, audit.baseline_fit.parameters, effect);
  rm::calibration::CalibrationOptions fit;
  fit.objective = rm::calibration::Objective::kWholeCurve;
  fit.free_parameters = options.calibration_parameters;
  for (const rm::dynamics::ParameterSpec& s : start.specs()) {
    if (s.fittable && s.name.rfind(effect + ".", 0) == 0) fit.free_parameters.push_back(s.name);
  }
  const rm::calibration::CalibrationResult refit = rm::calibration::Calibrate(
      description, start, postures, measured, audit.features, fit);
  std::printf("refit with %s: %s\n", effect.c_str(), rm::ToString(refit.status));
  for (const rm::calibration::ParameterEstimate& e : refit.estimates) {
    std::printf("  %-22s %.4g %s (start %.4g)\n", e.name.c_str(), e.value, e.unit.c_str(), e.initial);
  }

  // The rms log-magnitude errors over all lines of all FRFs (and per FRF
  // in `curves`, per band in their `bands`), before (the configured model,
  // calibrated) and after (with the effect), in units of the noise.
  const double inf = std::numeric_limits<double>::infinity();
  const rm::audit::ModelErrors before = rm::audit::ComputeErrors(
      rm::dynamics::RobotModel::Build(config.description, audit.baseline_fit.parameters), postures, measured, 0.0,
      inf, 8);
  const rm::audit::ModelErrors after = rm::audit::ComputeErrors(
      rm::dynamics::RobotModel::Build(description, refit.parameters), postures, measured, 0.0, inf, 8);
  std::printf("error before: %.2f x the noise\n", before.total_rms_log_mag / audit.noise_floor);
  std::printf("error after:  %.2f x the noise (with %s)\n", after.total_rms_log_mag / audit.noise_floor,
              effect.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "audit_loop: %s\n", e.what());
  return 1;
}
