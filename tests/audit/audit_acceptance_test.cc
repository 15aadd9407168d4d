// Issue #5 acceptance on virtual hammer tests with known truth: for each
// library effect in turn, data from the default robot with the effect
// switched on (a realistic value), calibration parameters perturbed, 2 %
// noise, five postures; the full audit (every library effect a candidate)
// must (i) flag a significant failure, (ii) rank the effect first, (iii)
// bring the whole-curve error within 1.5 × that of the true model on the
// same data, with the effect's fitted parameters within 10 % of the truth
// or within their reported 95 % interval. Also: two hidden effects are both
// found; an effect outside the library is reported as unexplained.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <iostream>
#include <set>

#include "audit_test_support.h"
#include "robomach/common/units.h"

namespace robomach::audit {
namespace {

using testing::Campaign;
using testing::Hidden;
using testing::MakeCampaign;
using testing::Synthesize;
using testing::Truth;

struct Case {
  std::string name;
  std::vector<Hidden> hidden;
  unsigned seed;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }  // test names without byte dumps

// Realistic values, each a physical situation rather than a library default:
// - tip_mass 0.5 kg: an instrumentation block at the tool tip. Below about
//   0.4 kg a tip mass is absorbed by the calibration of m6 and d6 within 2 %
//   noise (measured: 0.5 kg gives 1.39 × the noise floor before the fix).
// - flange_compliance: a soft quick-change flange, bending stiffness
//   1e6 N·m/rad (half the default).
// - joint_damping: 1.5 × the library's joint damping.
// - base_compliance: a soft foundation, lateral 3e8 N/m, rocking 2e7 N·m/rad.
// - tool_flexibility: a long-reach tool, 12 mm × 60 mm stick-out.
// - spindle_interface: an HSK face contact, tilting 10 × and translational
//   1.5 × the taper-only contact.
const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {
      {"tip_mass", {{"tip_mass", {{"tip_mass.mass_kg", 0.5}}}}, 101},
      {"flange_compliance", {{"flange_compliance", {{"flange_compliance.bending_stiffness_Nm_per_rad", 1e6}}}}, 102},
      {"joint_damping",
       {{"joint_damping",
         {{"joint_damping.c1_Nms_per_rad", 2550.0}, {"joint_damping.c2_Nms_per_rad", 4200.0},
          {"joint_damping.c3_Nms_per_rad", 1950.0}, {"joint_damping.c4_Nms_per_rad", 60.0},
          {"joint_damping.c5_Nms_per_rad", 120.0}, {"joint_damping.c6_Nms_per_rad", 10.5}}}},
       103},
      {"base_compliance",
       {{"base_compliance",
         {{"base_compliance.lateral_stiffness_N_per_m", 3e8}, {"base_compliance.rocking_stiffness_Nm_per_rad", 2e7}}}},
       104},
      {"tool_flexibility",
       {{"tool_flexibility", {{"tool_flexibility.diameter_m", 0.012}, {"tool_flexibility.stick_out_m", 0.06}}}},
       105},
      {"spindle_interface",
       {{"spindle_interface",
         {{"spindle_interface.translational_scale", 1.5}, {"spindle_interface.tilting_scale", 10.0}}}},
       106},
  };
  return cases;
}

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Outcome {
  AuditResult result;
  double true_error{0.0};
  dynamics::ParameterSet truth;
  dynamics::FrfSet measured;
};

Outcome Audit(const Campaign& c, const std::vector<Hidden>& hidden, unsigned seed,
              const std::function<void(dynamics::FrfSet*)>& alter = {}) {
  const auto [d, p] = Truth(c, hidden);
  dynamics::FrfSet measured = Synthesize(c, d, p, seed);
  if (alter) alter(&measured);
  AuditOptions o;  // every library effect is a candidate
  o.progress = [](const std::string& m) { std::cout << "  " << m << std::endl; };
  const auto t0 = std::chrono::steady_clock::now();
  Outcome out{RunAudit(c.cfg.description, c.cfg.parameters, c.postures, measured, o), 0.0, p, measured};
  testing::PrintAudit(out.result, Seconds(t0));
  out.true_error =
      ComputeErrors(dynamics::RobotModel::Build(d, p), c.postures, measured, 0.0, 1e9, 8).total_rms_log_mag;
  return out;
}

// Fitted values within 10 % of the truth or within their 95 % interval.
int ExpectParametersNearTruth(const Outcome& o, const std::string& effect,
                              const std::vector<calibration::ParameterEstimate>& estimates,
                              const dynamics::ParameterSet& fitted, const std::string& label) {
  return testing::ExpectParametersNearTruth(o.truth, effect, estimates, fitted, label);
}

class HiddenEffect : public ::testing::TestWithParam<Case> {};

TEST_P(HiddenEffect, IsFlaggedRankedFirstAndExplainsTheError) {
  const Case& k = GetParam();
  const Campaign c = MakeCampaign();
  const Outcome o = Audit(c, k.hidden, k.seed);
  const AuditResult& r = o.result;
  // (i) A significant failure: beyond 1.3 × the noise floor (AuditOptions).
  EXPECT_TRUE(r.significant_failure) << r.errors_before.total_rms_log_mag << " vs floor " << r.noise_floor;
  ASSERT_FALSE(r.candidates.empty());
  // (ii) Ranked first, lowering the BIC, and named as the missing effect.
  const CandidateResult& top = r.candidates.front();
  EXPECT_EQ(top.name(), k.name);
  EXPECT_LT(top.bic_change, 0.0);
  EXPECT_TRUE(top.plausible) << top.note;
  EXPECT_EQ(r.missing_effects, std::vector<std::string>{k.name}) << r.verdict;
  EXPECT_TRUE(r.explained) << r.verdict;
  // (iii) Error within 1.5 × the true model's on the same noisy data.
  EXPECT_LT(top.errors.total_rms_log_mag, 1.5 * o.true_error);
  std::cout << k.name << ": error before " << r.errors_before.total_rms_log_mag << ", after "
            << top.errors.total_rms_log_mag << ", true model " << o.true_error << ", floor " << r.noise_floor << "\n";
  EXPECT_GT(ExpectParametersNearTruth(o, k.name, top.fit.estimates, top.fit.parameters, "candidate"), 0);
  for (const auto& n : top.not_identifiable) std::cout << "  not identifiable: " << n << "\n";

  // (iii) as the user does it: a second audit with the effect added (as
  // model-audit --add does: the effect at its defaults, its fittable
  // parameters calibrated with the core four) finds no significant failure
  // and an error within 1.5 × the true model's.
  const auto [d2, p2] = WithEffect(c.cfg.description, c.cfg.parameters, k.name);
  AuditOptions again;
  for (const auto& s : p2.specs()) {
    if (s.fittable && s.name.rfind(k.name + ".", 0) == 0) again.calibration_parameters.push_back(s.name);
  }
  const AuditResult r2 = RunAudit(d2, p2, c.postures, o.measured, again);
  EXPECT_FALSE(r2.significant_failure) << r2.verdict;
  EXPECT_LT(r2.errors_before.total_rms_log_mag, 1.5 * o.true_error);
  EXPECT_GT(ExpectParametersNearTruth(o, k.name, r2.baseline_fit.estimates, r2.baseline_fit.parameters, "--add"), 0);
  std::cout << "with --add " << k.name << ": error " << r2.errors_before.total_rms_log_mag << "\n";
}

INSTANTIATE_TEST_SUITE_P(EveryLibraryEffect, HiddenEffect, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

// gravity_stiffness switched on at its physical value (scale 1) moves the
// KR210's modes by less than 0.1 %: below what 2 % noise lets anyone see.
// The independent check is the true-model error itself: the model without
// the effect, calibrated, is within the noise, so the audit must not claim
// a failure (and cannot rank what it cannot see).
TEST(HiddenEffectBelowDetection, GravityStiffnessIsWithinTheNoiseAndRaisesNoAlarm) {
  const Campaign c = MakeCampaign();
  const Outcome o = Audit(c, {{"gravity_stiffness", {}}}, 107);
  EXPECT_FALSE(o.result.significant_failure) << o.result.errors_before.total_rms_log_mag;
  EXPECT_LT(o.result.errors_before.total_rms_log_mag, 1.05 * o.true_error);
  EXPECT_TRUE(o.result.missing_effects.empty());
  // No alarm: the verdict is not among model-audit's findings.
  for (const Finding& f : JudgeAudit(o.result).findings) EXPECT_NE(f.message, o.result.verdict);

}

// A soft quick-change flange on a soft foundation: flexibilities at both
// ends of the robot. (A soft flange with the long-reach tool was tried too:
// the greedy pair ends at 1.1 × the true model's error with a 3 × 9 mm tool
// whose damping sits on its bound. With its first bending mode near 3 kHz,
// far above the 500 Hz band, the tool shows mainly as a static compliance
// ∝ L³/d⁴, and diameter and stick-out trade off; noted in the README.)
TEST(TwoHiddenEffects, AreBothFound) {
  const Campaign c = MakeCampaign();
  const Outcome o = Audit(c,
                          testing::SoftFlangeOnSoftFoundation(),
                          108);
  const AuditResult& r = o.result;
  EXPECT_TRUE(r.significant_failure);
  ASSERT_GE(r.best, 0) << r.verdict;
  std::vector<std::string> found = r.missing_effects;
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, (std::vector<std::string>{"base_compliance", "flange_compliance"})) << r.verdict;
  EXPECT_TRUE(r.explained) << r.verdict;
  EXPECT_LT(r.candidates[r.best].errors.total_rms_log_mag, 1.5 * o.true_error);
}

// Outside the library: a resonance of the measurement chain (an
// accelerometer's mounting, 320 Hz, 4 % damping) multiplies every measured
// FRF by 1 / (1 − r² + 2iζr), r = f / 320 Hz, at every posture alike. No
// effect of the robot model makes a posture-independent resonance in every
// FRF, so the audit must not attribute it with confidence: the verdict is
// "unexplained" and describes the pattern (the failing band is the same at
// every posture).
TEST(EffectOutsideTheLibrary, IsReportedAsUnexplainedWithItsPattern) {
  const Campaign c = MakeCampaign();

  const Outcome o = Audit(c, {}, 109, testing::ApplyMountingResonance);
  const AuditResult& r = o.result;
  EXPECT_TRUE(r.significant_failure);
  EXPECT_FALSE(r.explained) << r.verdict;
  EXPECT_TRUE(r.missing_effects.empty()) << r.verdict;
  EXPECT_NE(r.verdict.find("unexplained"), std::string::npos) << r.verdict;
  // model-audit's exit 3: the verdict is the first finding.
  const RunFindings v = JudgeAudit(r);
  EXPECT_EQ(v.status(), RunStatus::kFlagged);
  ASSERT_FALSE(v.findings.empty());
  EXPECT_EQ(v.findings[0].message, r.verdict);
  // The pattern: the band with 320 Hz is the worst at every posture (in at
  // least one direction; the calibration may bend a robot mode elsewhere in
  // the other), and the verdict says so.
  EXPECT_NE(r.pattern.find("at every posture"), std::string::npos) << r.pattern;
  EXPECT_NE(r.verdict.find(r.pattern), std::string::npos) << r.verdict;
  std::set<std::string> poses;
  for (const CurveError& ce : r.errors_before.curves) {
    ASSERT_FALSE(ce.bands.empty());
    if (ce.bands[0].fmin_hz <= 320.0 && ce.bands[0].fmax_hz >= 320.0) poses.insert(ce.key.pose_id);
  }
  EXPECT_EQ(poses.size(), c.postures.size());
}

}  // namespace
}  // namespace robomach::audit
