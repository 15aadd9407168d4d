// The model audit on virtual hammer tests with known truth (issue #5
// acceptance, first part): a hidden effect is flagged, ranked first and,
// once added, brings the error down to that of the true model; data without
// a hidden effect raise no alarm.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "robomach/audit/model_audit.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::audit {
namespace {

using calibration::NamedPosture;
using robomach::testing::SourcePath;

constexpr double kRelativeNoise = 0.02;  // 2 % rms, as issue #5 asks

struct Campaign {
  io::RobotConfig cfg;
  std::vector<NamedPosture> poses;
  calibration::PostureMap postures;
};

Campaign MakeCampaign() {
  Campaign c{io::LoadRobotConfig(SourcePath("config/kr210.yaml")), {}, {}};
  for (const io::Posture& p : io::ReadPostureFile(SourcePath("config/postures_demo.csv"), 6)) {
    c.poses.push_back({p.id, p.q});
    c.postures[p.id] = p.q;
  }
  return c;
}

// Truth: calibration parameters off the config's start values by +10 %,
// −8 %, +20 %, −15 % (the audit must recalibrate them), plus an optional
// hidden effect with given values.
std::pair<dynamics::RobotDescription, dynamics::ParameterSet> Truth(
    const Campaign& c, const std::string& hidden, const std::map<std::string, double>& values) {
  dynamics::RobotDescription d = c.cfg.description;
  dynamics::ParameterSet p = c.cfg.parameters;
  if (!hidden.empty()) std::tie(d, p) = WithEffect(d, p, hidden);
  p.Set("m6_kg", 1.10 * c.cfg.parameters.Get("m6_kg"));
  p.Set("d6_m", 0.92 * c.cfg.parameters.Get("d6_m"));
  p.Set("alpha_s", 1.20 * c.cfg.parameters.Get("alpha_s"));
  p.Set("beta_per_s", 0.85 * c.cfg.parameters.Get("beta_per_s"));
  for (const auto& [k, v] : values) p.Set(k, v);
  return {d, p};
}

dynamics::FrfSet Synthesize(const Campaign& c, const dynamics::RobotDescription& d, const dynamics::ParameterSet& p,
                            unsigned seed) {
  calibration::VirtualHammerOptions o;  // 0.25..500 Hz, Δf = 0.25 Hz, xx and yy
  o.relative_noise = kRelativeNoise;
  o.seed = seed;
  return calibration::SynthesizeHammerTest(dynamics::RobotModel::Build(d, p), c.poses, o);
}

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The noise floor and the error of the true model against the independent
// reference: the noise the synthesis put in. H(1 + σ n), n complex standard
// normal, gives ln|H| an error Re(σ n) + O(σ²) of standard deviation σ/√2
// = 0.01414. Tolerances: the rms over 20 000 lines scatters by 1/√(2·20000)
// = 0.5 %; the median estimator of the noise floor by 1.25/√(20000) ≈ 0.9 %
// plus the bias of lines near lightly damped peaks where ln|H| is not
// straight over 2Δf; 5 % and 10 % cover these with margin.
TEST(ModelAudit, NoiseFloorAndTrueModelErrorMatchTheSynthesisNoise) {
  const Campaign c = MakeCampaign();
  const auto [d, p] = Truth(c, "", {});
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

void ExpectHiddenEffectFound(const std::string& hidden, const std::map<std::string, double>& values, unsigned seed) {
  const Campaign c = MakeCampaign();
  const auto [d, p] = Truth(c, hidden, values);
  const dynamics::FrfSet measured = Synthesize(c, d, p, seed);
  const auto t0 = std::chrono::steady_clock::now();
  // Run time: the full library (7 candidates) takes ~4 min on 2 cores, far
  // beyond the test budget: spindle_interface, tool_flexibility,
  // base_compliance and joint_damping take 0.5-2 min each (many extra DOFs,
  // complex modes). This test ranks the hidden effect against the cheap
  // one-parameter effects only; the full ranking is still to be tested
  // (README, model-audit status). Fit stride 2 (the default): stride 4 was
  // tried and leaves the flange fit at twice the true model's error, since
  // 1 Hz lines undersample the 10.5 Hz mode's 0.84 Hz half-power band.
  AuditOptions o;
  o.candidates = {"flange_compliance", "gravity_stiffness", "tip_mass"};
  o.progress = [](const std::string& m) { std::cout << m << std::endl; };
  const AuditResult r = RunAudit(c.cfg.description, c.cfg.parameters, c.postures, measured, o);
  const double seconds = Seconds(t0);
  const double true_error =
      ComputeErrors(dynamics::RobotModel::Build(d, p), c.postures, measured, 0.0, 1e9, 8).total_rms_log_mag;
  // (i) significant failure: beyond 1.3 × noise floor (see AuditOptions).
  EXPECT_TRUE(r.significant_failure) << hidden << ": error " << r.errors_before.total_rms_log_mag << ", floor "
                                     << r.noise_floor;
  // (ii) ranked first, with a lower BIC than the current model.
  ASSERT_FALSE(r.candidates.empty());
  EXPECT_EQ(r.candidates[0].name(), hidden);
  EXPECT_LT(r.candidates[0].bic_change, 0.0);
  EXPECT_EQ(r.missing_effects, std::vector<std::string>{hidden}) << r.verdict;
  EXPECT_TRUE(r.explained) << r.verdict;
  // (iii) the error after adding it is within 1.5 × that of the true model
  // on the same noisy data (issue #5's bound).
  EXPECT_LT(r.candidates[0].errors.total_rms_log_mag, 1.5 * true_error);
  std::cout << hidden << ": error before " << r.errors_before.total_rms_log_mag << ", after "
            << r.candidates[0].errors.total_rms_log_mag << ", true model " << true_error << ", floor "
            << r.noise_floor << "; " << r.candidates.size() << " candidates in " << seconds << " s\n";
  for (const CandidateResult& cand : r.candidates) {
    std::cout << "  " << cand.name() << " dBIC " << cand.bic_change << " error " << cand.errors.total_rms_log_mag
              << (cand.plausible ? "" : " implausible: " + cand.note) << "\n";
  }
}

TEST(ModelAudit, HiddenFlangeComplianceIsFlaggedRankedFirstAndExplainsTheError) {
  // Bending stiffness at half the library default (2e6 → 1e6 N·m/rad): a
  // soft quick-change flange; it lowers the end-effector modes visibly.
  ExpectHiddenEffectFound("flange_compliance", {{"flange_compliance.bending_stiffness_Nm_per_rad", 1e6}}, 41);
}

TEST(ModelAudit, NoHiddenEffectRaisesNoFalseAlarm) {
  const Campaign c = MakeCampaign();
  const auto [d, p] = Truth(c, "", {});
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
