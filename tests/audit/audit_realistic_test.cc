// Issue #10 acceptance: the issue #5 table again, on hammer data as they
// really come. Accelerance files of a 5120 Hz test (0.625..2560 Hz, 4096
// lines per FRF, through a CSV file and back) at six postures, xx and yy,
// 2 % relative noise plus an additive floor (flat in acceleration, flat in
// receptance, raised above the hammer's 1 kHz cutoff): the signal-to-noise
// ratio falls below 1 a few hundred hertz up and at the lowest lines. The
// audit runs as model-audit does with its defaults: a noise model per FRF
// from the scatter of the data (no coherence), the usable lines with their
// σ, every library effect a candidate. Its errors are in noise units, so
// the true model's error is about 1 and "explained" means within 1.3 × the
// noise (AuditOptions::explained_factor).
//
// The calibration parameters of the truth are off the config (audit test
// support: +10 %, −8 %, +20 %, −15 %); each case hides one effect (the same
// realistic values as audit_acceptance_test.cc), none, two, or one outside
// the library. The seeds here were not used while tuning the audit (the
// runs behind the README's table used others).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <iostream>
#include <set>

#include "audit_test_support.h"
#include "realistic_hammer_test.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/common/units.h"
#include "robomach/io/frf_files.h"

namespace robomach::audit {
namespace {

using testing::Campaign;
using testing::Hidden;
using testing::Truth;

// The five demonstration postures and a sixth far from them, as in the
// issue's data set.
Campaign MakeSixPostureCampaign() {
  Campaign c = testing::MakeCampaign();
  const auto [id, deg] = robomach::testing::SixthPostureDeg();
  Eigen::VectorXd q(6);
  for (int j = 0; j < 6; ++j) q(j) = DegToRad(deg[j]);
  c.poses.push_back({id, q});
  c.postures[id] = q;
  return c;
}

struct Outcome {
  AuditResult result;
  dynamics::ParameterSet truth;
  double true_error{0.0};  // the true model's error on the same data, noise units
};

// Synthesis, the accelerance file and back, the noise model, the audit.
Outcome Audit(const std::string& name, const std::vector<Hidden>& hidden, unsigned seed,
              const std::function<void(dynamics::FrfSet*)>& alter = {}) {
  const Campaign c = MakeSixPostureCampaign();
  const auto [d, p] = Truth(c, hidden);
  dynamics::FrfSet synth =
      calibration::SynthesizeHammerTest(dynamics::RobotModel::Build(d, p), c.poses,
                                        robomach::testing::RealisticHammerTest(seed));
  if (alter) alter(&synth);
  const std::string path = robomach::testing::TempDir("audit_realistic_" + name) + "/hammer.csv";
  io::WriteFrfCsv(path, synth, io::FrfQuantity::kAccelerance, 0);
  const dynamics::FrfSet read = io::ReadFrfCsv(path).frfs;
  const dynamics::FrfSet measured = calibration::UsableData(read, calibration::EstimateNoise(read, {}));
  AuditOptions o;  // every library effect is a candidate
  o.progress = [](const std::string& m) { std::cout << "  " << m << std::endl; };
  const auto t0 = std::chrono::steady_clock::now();
  Outcome out{RunAudit(c.cfg.description, c.cfg.parameters, c.postures, measured, o), p, 0.0};
  testing::PrintAudit(out.result, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  out.true_error =
      ComputeErrors(dynamics::RobotModel::Build(d, p), c.postures, measured, 0.0, 1e9, 8).total_rms_log_mag;
  return out;
}

using Case = testing::RealisticCase;
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class HiddenEffectOnRealisticData : public ::testing::TestWithParam<Case> {};

TEST_P(HiddenEffectOnRealisticData, IsFlaggedRankedFirstAndExplained) {
  const Case& k = GetParam();
  const Outcome o = Audit(k.name, k.hidden, k.seed);
  const AuditResult& r = o.result;
  EXPECT_TRUE(r.significant_failure) << r.errors_before.total_rms_log_mag;
  ASSERT_FALSE(r.candidates.empty());
  const CandidateResult& top = r.candidates.front();
  EXPECT_EQ(top.name(), k.name);
  EXPECT_LT(top.bic_change, 0.0);
  EXPECT_TRUE(top.plausible) << top.note;
  EXPECT_EQ(r.missing_effects, std::vector<std::string>{k.name}) << r.verdict;
  EXPECT_TRUE(r.explained) << r.verdict;
  // Errors in noise units: the winner's within the audit's own "explained"
  // factor of the noise, and as close to the data as the true model's (the
  // #5 criterion). The true model's own error is printed, not asserted: it
  // is 0.99 for most cases but 0.84 with the long-reach tool, whose mode
  // makes the usable band reach 2.5 kHz, where the scatter estimate of the
  // noise comes out high (README, status of issue #10).
  EXPECT_LT(top.errors.total_rms_log_mag, 1.3);
  EXPECT_LT(top.errors.total_rms_log_mag, 1.1 * o.true_error);
  std::cout << k.name << ": error before " << r.errors_before.total_rms_log_mag << ", after "
            << top.errors.total_rms_log_mag << ", true model " << o.true_error << "\n";
  EXPECT_GT(testing::ExpectParametersNearTruth(o.truth, k.name, top.fit.estimates, top.fit.parameters, "candidate"), 0);
}

// The values of audit_acceptance_test.cc (see there for the physical
// situations); seeds 301.. not used in tuning.
INSTANTIATE_TEST_SUITE_P(
    EveryDetectableLibraryEffect, HiddenEffectOnRealisticData,
    ::testing::ValuesIn(testing::RealisticSingleEffectCases()),
    [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

// Nothing missing: no alarm (the issue found "12 of 12 FRFs fail
// significantly" here before the noise model).
TEST(NothingMissingOnRealisticData, RaisesNoAlarm) {
  const Case k = testing::RealisticCaseNamed("none");
  const Outcome o = Audit(k.name, k.hidden, k.seed);
  EXPECT_FALSE(o.result.significant_failure) << o.result.verdict;
  EXPECT_TRUE(o.result.missing_effects.empty());
  EXPECT_LT(o.result.errors_before.total_rms_log_mag, 1.3);
}

TEST(TwoHiddenEffectsOnRealisticData, AreBothFound) {
  const Case k = testing::RealisticCaseNamed("two");
  const Outcome o = Audit(k.name, k.hidden, k.seed);
  const AuditResult& r = o.result;
  EXPECT_TRUE(r.significant_failure);
  ASSERT_GE(r.best, 0) << r.verdict;
  std::vector<std::string> found = r.missing_effects;
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, (std::vector<std::string>{"base_compliance", "flange_compliance"})) << r.verdict;
  EXPECT_TRUE(r.explained) << r.verdict;
  EXPECT_LT(r.candidates[r.best].errors.total_rms_log_mag, 1.3);
}

// Outside the library: the accelerometer's mounting resonance (320 Hz, 4 %
// damping) in every FRF alike, inside the usable band. Reported
// unexplained, with the pattern: the same band fails at every posture.
TEST(EffectOutsideTheLibraryOnRealisticData, IsReportedAsUnexplainedWithItsPattern) {
  const Case k = testing::RealisticCaseNamed("outside");
  const Outcome o = Audit(k.name, k.hidden, k.seed, k.alter);
  const AuditResult& r = o.result;
  EXPECT_TRUE(r.significant_failure);
  EXPECT_FALSE(r.explained) << r.verdict;
  EXPECT_TRUE(r.missing_effects.empty()) << r.verdict;
  EXPECT_NE(r.verdict.find("unexplained"), std::string::npos) << r.verdict;
  EXPECT_NE(r.pattern.find("at every posture"), std::string::npos) << r.pattern;
  // The band with 320 Hz is the worst at every posture, in at least one
  // direction (the error bands are common to all FRFs).
  std::set<std::string> poses;
  for (const CurveError& ce : r.errors_before.curves) {
    ASSERT_FALSE(ce.bands.empty());
    if (ce.bands[0].fmin_hz <= 320.0 && ce.bands[0].fmax_hz >= 320.0) poses.insert(ce.key.pose_id);
  }
  EXPECT_EQ(poses.size(), 6u);
}

}  // namespace
}  // namespace robomach::audit
