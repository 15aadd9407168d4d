// The model audit's measures on virtual hammer tests with known truth: the
// noise floor and error against the synthesis noise, no false alarm without
// a hidden effect, bad options. The hidden-effect acceptance is in
// audit_acceptance_test.cc.
#include <gtest/gtest.h>

#include <cmath>

#include "audit_test_support.h"

namespace robomach::audit {
namespace {

using testing::Campaign;
using testing::kRelativeNoise;
using testing::MakeCampaign;
using testing::Synthesize;
using testing::Truth;

// The noise floor and the error of the true model against the independent
// reference: the noise the synthesis put in. H(1 + σ n), n complex standard
// normal, gives ln|H| an error Re(σ n) + O(σ²) of standard deviation σ/√2
// = 0.01414. Tolerances: the rms over 20 000 lines scatters by 1/√(2·20000)
// = 0.5 %; the median estimator of the noise floor by 1.25/√(20000) ≈ 0.9 %
// plus the bias of lines near lightly damped peaks where ln|H| is not
// straight over 2Δf; 5 % and 10 % cover these with margin.
TEST(ModelAudit, NoiseFloorAndTrueModelErrorMatchTheSynthesisNoise) {
  const Campaign c = MakeCampaign();
  const auto [d, p] = Truth(c, {});
  const dynamics::FrfSet measured = Synthesize(c, d, p, 7);
  const double s = kRelativeNoise / std::sqrt(2.0);
  EXPECT_NEAR(EstimateNoiseFloor(measured, 0.0, 1e9) / s, 1.0, 0.10);
  const ModelErrors e = ComputeErrors(dynamics::RobotModel::Build(d, p), c.postures, measured, 0.0, 1e9, 8);
  EXPECT_NEAR(e.total_rms_log_mag / s, 1.0, 0.05);
  EXPECT_EQ(e.curves.size(), 10u);
  for (const CurveError& ce : e.curves) {
    EXPECT_EQ(ce.lines, 2000);
    ASSERT_FALSE(ce.bands.empty());
    for (size_t b = 1; b < ce.bands.size(); ++b) EXPECT_GE(ce.bands[b - 1].rms_log_mag, ce.bands[b].rms_log_mag);
  }
  // BIC by hand: n ln(RSS/n) + k ln n.
  EXPECT_DOUBLE_EQ(Bic(2.0, 4, 1), 4 * std::log(0.5) + std::log(4.0));
}

TEST(ModelAudit, NoHiddenEffectRaisesNoFalseAlarm) {
  const Campaign c = MakeCampaign();
  const auto [d, p] = Truth(c, {});
  const dynamics::FrfSet measured = Synthesize(c, d, p, 43);
  const AuditResult r = RunAudit(c.cfg.description, c.cfg.parameters, c.postures, measured);
  EXPECT_FALSE(r.significant_failure) << r.errors_before.total_rms_log_mag << " vs floor " << r.noise_floor;
  EXPECT_TRUE(r.explained);
  EXPECT_TRUE(r.missing_effects.empty());
}

TEST(ModelAudit, RejectsBadOptionsAndUnknownCandidates) {
  const Campaign c = MakeCampaign();
  AuditOptions o;
  o.fmax_hz = -1.0;
  EXPECT_THROW(CheckValid(o), std::invalid_argument);
  AuditOptions u;
  u.candidates = {"warp_drive"};
  EXPECT_THROW(RunAudit(c.cfg.description, c.cfg.parameters, c.postures, dynamics::FrfSet{}, u),
               std::invalid_argument);
}

}  // namespace
}  // namespace robomach::audit
