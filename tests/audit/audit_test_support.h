#pragma once

// Virtual hammer-test campaigns with known truth for the model-audit tests
// (issue #5 acceptance): the default robot of config/kr210.yaml at the five
// demonstration postures, calibration parameters off their start values,
// optionally hidden effects, 2 % noise.

#include <cmath>
#include <complex>
#include <gtest/gtest.h>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "robomach/audit/model_audit.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::audit::testing {

constexpr double kRelativeNoise = 0.02;  // 2 % rms, as issue #5 asks

struct Campaign {
  io::RobotConfig cfg;
  std::vector<calibration::NamedPosture> poses;
  calibration::PostureMap postures;
};

inline Campaign MakeCampaign() {
  Campaign c{io::LoadRobotConfig(robomach::testing::SourcePath("config/kr210.yaml")), {}, {}};
  for (const io::Posture& p : io::ReadPostureFile(robomach::testing::SourcePath("config/postures_demo.csv"), 6)) {
    c.poses.push_back({p.id, p.q});
    c.postures[p.id] = p.q;
  }
  return c;
}

/// One hidden effect with the values of the parameters that differ from
/// the library defaults.
struct Hidden {
  std::string effect;
  std::map<std::string, double> values;  // prefixed names
};

/// Truth: calibration parameters off the config's start values by +10 %,
/// −8 %, +20 %, −15 % (the audit must recalibrate them), plus hidden effects.
inline std::pair<dynamics::RobotDescription, dynamics::ParameterSet> Truth(const Campaign& c,
                                                                           const std::vector<Hidden>& hidden) {
  dynamics::RobotDescription d = c.cfg.description;
  dynamics::ParameterSet p = c.cfg.parameters;
  for (const Hidden& h : hidden) std::tie(d, p) = WithEffect(d, p, h.effect);
  p.Set("m6_kg", 1.10 * c.cfg.parameters.Get("m6_kg"));
  p.Set("d6_m", 0.92 * c.cfg.parameters.Get("d6_m"));
  p.Set("alpha_s", 1.20 * c.cfg.parameters.Get("alpha_s"));
  p.Set("beta_per_s", 0.85 * c.cfg.parameters.Get("beta_per_s"));
  for (const Hidden& h : hidden) {
    for (const auto& [k, v] : h.values) p.Set(k, v);
  }
  return {d, p};
}

inline dynamics::FrfSet Synthesize(const Campaign& c, const dynamics::RobotDescription& d,
                                   const dynamics::ParameterSet& p, unsigned seed) {
  calibration::VirtualHammerOptions o;  // 0.25..500 Hz, Δf = 0.25 Hz, xx and yy
  o.relative_noise = kRelativeNoise;
  o.seed = seed;
  return calibration::SynthesizeHammerTest(dynamics::RobotModel::Build(d, p), c.poses, o);
}

/// Two hidden effects at both ends of the robot: a soft quick-change flange
/// (bending 1e6 N·m/rad) on a soft foundation (lateral 3e8 N/m, rocking
/// 2e7 N·m/rad).
inline std::vector<Hidden> SoftFlangeOnSoftFoundation() {
  return {{"flange_compliance", {{"flange_compliance.bending_stiffness_Nm_per_rad", 1e6}}},
          {"base_compliance",
           {{"base_compliance.lateral_stiffness_N_per_m", 3e8}, {"base_compliance.rocking_stiffness_Nm_per_rad", 2e7}}}};
}

/// Outside the library: a resonance of the measurement chain (an
/// accelerometer's mounting, 320 Hz, 4 % damping) multiplies every measured
/// FRF by 1 / (1 − r² + 2iζr), r = f / 320 Hz, at every posture alike.
inline void ApplyMountingResonance(dynamics::FrfSet* m) {
  dynamics::FrfSet out;
  for (const auto& [key, frf] : *m) {
    Eigen::VectorXcd h = frf.receptance();
    for (int i = 0; i < frf.size(); ++i) {
      const double r = frf.freq_hz()(i) / 320.0;
      h(i) /= std::complex<double>(1.0 - r * r, 2.0 * 0.04 * r);
    }
    out.Insert(key, dynamics::Frf::FromSamples(frf.freq_hz(), h));
  }
  *m = out;
}

// The cases of tests/audit/audit_realistic_test.cc, also benchmarked by
// bench_audit's BM_AuditRealisticCase (issue #23: the slowest under 30 s):
// one hidden library effect each (seeds 301-306, not used in tuning), then
// nothing missing (307), two effects (308) and an effect outside the library
// (309, the accelerometer's mounting resonance).
struct RealisticCase {
  std::string name;
  std::vector<Hidden> hidden;
  unsigned seed;
  void (*alter)(dynamics::FrfSet*) = nullptr;
};
inline std::vector<RealisticCase> RealisticSingleEffectCases() {
  return {
      {"tip_mass", {{"tip_mass", {{"tip_mass.mass_kg", 0.5}}}}, 301},
      {"flange_compliance", {{"flange_compliance", {{"flange_compliance.bending_stiffness_Nm_per_rad", 1e6}}}}, 302},
      {"joint_damping",
       {{"joint_damping",
         {{"joint_damping.c1_Nms_per_rad", 2550.0}, {"joint_damping.c2_Nms_per_rad", 4200.0},
          {"joint_damping.c3_Nms_per_rad", 1950.0}, {"joint_damping.c4_Nms_per_rad", 60.0},
          {"joint_damping.c5_Nms_per_rad", 120.0}, {"joint_damping.c6_Nms_per_rad", 10.5}}}},
       303},
      {"base_compliance",
       {{"base_compliance",
         {{"base_compliance.lateral_stiffness_N_per_m", 3e8}, {"base_compliance.rocking_stiffness_Nm_per_rad", 2e7}}}},
       304},
      {"tool_flexibility",
       {{"tool_flexibility", {{"tool_flexibility.diameter_m", 0.012}, {"tool_flexibility.stick_out_m", 0.06}}}},
       305},
      {"spindle_interface",
       {{"spindle_interface",
         {{"spindle_interface.translational_scale", 1.5}, {"spindle_interface.tilting_scale", 10.0}}}},
       306}};
}
inline std::vector<RealisticCase> RealisticCases() {
  std::vector<RealisticCase> all = RealisticSingleEffectCases();
  all.push_back({"none", {}, 307});
  all.push_back({"two", SoftFlangeOnSoftFoundation(), 308});
  all.push_back({"outside", {}, 309, ApplyMountingResonance});
  return all;
}
inline RealisticCase RealisticCaseNamed(const std::string& name) {
  for (const RealisticCase& c : RealisticCases()) {
    if (c.name == name) return c;
  }
  throw std::invalid_argument("no realistic case " + name);
}

/// Prints the audit's verdict and every candidate row (for the test log).
inline void PrintAudit(const AuditResult& r, double seconds) {
  std::cout << "audit in " << seconds << " s: " << r.verdict << "\n";
  for (const CandidateResult& cand : r.candidates) {
    std::cout << "  " << cand.name() << ": dBIC " << cand.bic_change << ", error " << cand.errors.total_rms_log_mag
              << (cand.plausible ? ", plausible" : ", implausible") << " (" << cand.start << ") " << cand.note << "\n";
  }
}

/// The value a fitted parameter is compared with. Joint damping and the
/// stiffness-proportional Rayleigh term are the same matrix (alpha K_q is
/// the diagonal joint damping alpha k_qi), so only c_i + alpha k_qi is
/// determined (the audit holds alpha_s, at 0): given the fitted alpha, the
/// truth of c_i is c_i,true + (alpha_true − alpha_fit) k_qi.
inline double ExpectedValue(const dynamics::ParameterSet& truth, const dynamics::ParameterSet& fitted,
                            const std::string& name) {
  double v = truth.Get(name);
  const std::string prefix = "joint_damping.c";
  if (name.rfind(prefix, 0) == 0) {
    const std::string joint = name.substr(prefix.size(), 1);
    v += (truth.Get("alpha_s") - fitted.Get("alpha_s")) * truth.Get("kq" + joint + "_Nm_per_rad");
  }
  return v;
}

/// Expects each fitted parameter of `effect` within 10 % of the truth or
/// within its 95 % interval; returns how many were checked.
inline int ExpectParametersNearTruth(const dynamics::ParameterSet& truth, const std::string& effect,
                                     const std::vector<calibration::ParameterEstimate>& estimates,
                                     const dynamics::ParameterSet& fitted, const std::string& label) {
  int checked = 0;
  for (const auto& e : estimates) {
    if (e.name.rfind(effect + ".", 0) != 0) continue;
    const double value = ExpectedValue(truth, fitted, e.name);
    const bool within_10 = std::abs(e.value / value - 1.0) <= 0.10;
    const bool within_ci = std::abs(e.value - value) <= 1.96 * e.std_dev;
    EXPECT_TRUE(within_10 || within_ci) << label << ": " << e.name << " = " << e.value << " ± " << e.std_dev
                                        << ", truth " << value;
    std::cout << "  " << label << ": " << e.name << " = " << e.value << " ± " << e.std_dev << " (truth " << value
              << ")\n";
    ++checked;
  }
  return checked;
}

}  // namespace robomach::audit::testing
