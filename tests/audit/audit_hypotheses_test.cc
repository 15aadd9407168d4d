// Issue #33 acceptance: the audit when the cause is not one of the library's
// effects. Hammer data as they really come (issue #10's accelerance files at
// six postures, through a CSV file and back, with the noise model of the
// data's scatter); the truth's calibration parameters off the config as in
// every audit test (+10 %, −8 %, +20 %, −15 %).
//
// - Joint stiffness off on two joints (kq2 40 % lower, kq3 30 % higher than
//   configured; nothing missing): the audit must name the two parameters,
//   each factor within 10 %, and no effect.
// - An elastic hinge inside the arm, made by a second route that shares no
//   code with the virtual-joint effect: a URDF with a real revolute joint
//   inserted between joint 3 and link 3 (about link 3's x axis), whose
//   spring is that joint's stiffness in a 7-joint model. The audit must
//   localise it to link 3 and the x axis and remove at least 80 % of the
//   excess misfit.
//
// Seeds 331-333 were not used while tuning.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <cmath>
#include <fstream>
#include <iostream>
#include <regex>
#include <set>
#include <sstream>

#include "audit_test_support.h"
#include "realistic_hammer_test.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/common/units.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/urdf_loader.h"

namespace robomach::audit {
namespace {

using testing::Campaign;

Campaign MakeSixPostureCampaign() {
  Campaign c = testing::MakeCampaign();
  const auto [id, deg] = robomach::testing::SixthPostureDeg();
  Eigen::VectorXd q(6);
  for (int j = 0; j < 6; ++j) q(j) = DegToRad(deg[j]);
  c.poses.push_back({id, q});
  c.postures[id] = q;
  return c;
}

// The truth's calibration parameters off the config, as testing::Truth does.
void OffsetCalibration(const dynamics::ParameterSet& config, dynamics::ParameterSet* p) {
  p->Set("m6_kg", 1.10 * config.Get("m6_kg"));
  p->Set("d6_m", 0.92 * config.Get("d6_m"));
  p->Set("alpha_s", 1.20 * config.Get("alpha_s"));
  p->Set("beta_per_s", 0.85 * config.Get("beta_per_s"));
}

// Realistic hammer data of `model` at `poses`, as read from an accelerance
// CSV file, with their noise model's usable lines.
dynamics::FrfSet Measure(const std::shared_ptr<const dynamics::RobotModel>& model,
                         const std::vector<calibration::NamedPosture>& poses, unsigned seed, const std::string& name) {
  const dynamics::FrfSet synth =
      calibration::SynthesizeHammerTest(model, poses, robomach::testing::RealisticHammerTest(seed));
  const std::string path = robomach::testing::TempDir("audit_hypotheses_" + name) + "/hammer.csv";
  io::WriteFrfCsv(path, synth, io::FrfQuantity::kAccelerance, 0);
  const dynamics::FrfSet read = io::ReadFrfCsv(path).frfs;
  return calibration::UsableData(read, calibration::EstimateNoise(read, {}));
}

AuditResult RunCase(const Campaign& c, const dynamics::FrfSet& measured) {
  AuditOptions o;
  o.progress = [](const std::string& m) { std::cout << "  " << m << std::endl; };
  const auto t0 = std::chrono::steady_clock::now();
  AuditResult r = RunAudit(c.cfg.description, c.cfg.parameters, c.postures, measured, o);
  testing::PrintAudit(r, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  std::cout << "headline: " << r.headline << "\n";
  return r;
}

TEST(AuditHypotheses, JointStiffnessOffOnTwoJointsIsNamedAsParametersNotAsAnEffect) {
  const Campaign c = MakeSixPostureCampaign();
  dynamics::ParameterSet truth = c.cfg.parameters;
  OffsetCalibration(c.cfg.parameters, &truth);
  truth.Set("kq2_Nm_per_rad", 0.6 * c.cfg.parameters.Get("kq2_Nm_per_rad"));
  truth.Set("kq3_Nm_per_rad", 1.3 * c.cfg.parameters.Get("kq3_Nm_per_rad"));
  const dynamics::FrfSet measured =
      Measure(dynamics::RobotModel::Build(c.cfg.description, truth), c.poses, 331, "kq");
  const AuditResult r = RunCase(c, measured);
  EXPECT_TRUE(r.significant_failure);
  EXPECT_EQ(r.grade, AuditGrade::kExplained) << r.verdict;
  EXPECT_TRUE(r.missing_effects.empty()) << r.verdict;
  ASSERT_GE(r.graded, 0);
  EXPECT_TRUE(r.candidates[r.graded].is_parameter_hypothesis()) << r.candidates[r.graded].name();
  ASSERT_EQ(r.parameter_changes.size(), 2u) << r.verdict;
  for (const ParameterChange& pc : r.parameter_changes) {
    const double expected = pc.name == "kq2_Nm_per_rad" ? 0.6 : pc.name == "kq3_Nm_per_rad" ? 1.3 : NAN;
    ASSERT_TRUE(std::isfinite(expected)) << "named " << pc.name;
    EXPECT_NEAR(pc.ratio() / expected, 1.0, 0.10) << pc.name << " ratio " << pc.ratio();
  }
  // The words lead to the fix: the parameters, the direction and the tools.
  EXPECT_NE(r.headline.find("no effect is missing"), std::string::npos) << r.headline;
  EXPECT_NE(r.headline.find("kq2_Nm_per_rad"), std::string::npos) << r.headline;
  EXPECT_NE(r.headline.find("lower than configured"), std::string::npos) << r.headline;
  EXPECT_NE(r.headline.find("kq-identify"), std::string::npos) << r.headline;
  EXPECT_NE(r.headline.find("--free kq2_Nm_per_rad"), std::string::npos) << r.headline;
  // The model with them is right: within the noise.
  EXPECT_LE(r.remainder_noise_units, 1.3);
}

// Issue #37 §4: a misfit within what the joint stiffnesses' uncertainty
// allows is not evidence of a missing effect. kq2 15 % lower and kq3 10 %
// higher than configured; the configured kq1..kq6 carry a kq-identify-like
// uncertainty (compliances, σ a fixed fraction of each). With σ 10 % the
// truth lies inside the 95 % region (Mahalanobis distance² ≈ 3.9 against
// χ²₆(0.95) = 12.6): the allowance must cover the failure, bring the error
// within the noise and find kq2 near the truth. With σ 1 % the truth is
// 15 σ away: the most favourable point lies on the region's boundary and
// explains only part of the misfit. (With σ 3 %, 6 σ for kq2, the trade-off
// with kq3 and the calibration parameters still covers it: 1.2 x the noise.)
dynamics::ParameterUncertainty StiffnessUncertainty(const dynamics::ParameterSet& p, double rel) {
  dynamics::ParameterUncertainty u;
  for (int j = 1; j <= 6; ++j) {
    const std::string n = "kq" + std::to_string(j) + "_Nm_per_rad";
    u.parameters.push_back({n, p.Get(n), dynamics::UncertainScale::kInverse});
  }
  u.covariance = Eigen::MatrixXd::Zero(6, 6);
  for (int j = 0; j < 6; ++j) u.covariance(j, j) = std::pow(rel / u.parameters[j].value, 2);
  u.covariance(1, 2) = u.covariance(2, 1) = 0.3 * std::sqrt(u.covariance(1, 1) * u.covariance(2, 2));
  u.source = "test";
  return u;
}

AuditResult RunWithUncertainty(const Campaign& c, const dynamics::FrfSet& measured, double rel) {
  AuditOptions o;
  o.candidates = {"kq2_Nm_per_rad"};  // the allowance is under test, not the candidates
  o.parameter_uncertainty = StiffnessUncertainty(c.cfg.parameters, rel);
  o.progress = [](const std::string& m) { std::cout << "  " << m << std::endl; };
  AuditResult r = RunAudit(c.cfg.description, c.cfg.parameters, c.postures, measured, o);
  std::cout << "verdict: " << r.verdict << "\nheadline: " << r.headline << "\n";
  return r;
}

dynamics::FrfSet StiffnessOffMeasured(const Campaign& c, unsigned seed) {
  dynamics::ParameterSet truth = c.cfg.parameters;
  OffsetCalibration(c.cfg.parameters, &truth);
  truth.Set("kq2_Nm_per_rad", 0.85 * c.cfg.parameters.Get("kq2_Nm_per_rad"));
  truth.Set("kq3_Nm_per_rad", 1.10 * c.cfg.parameters.Get("kq3_Nm_per_rad"));
  return Measure(dynamics::RobotModel::Build(c.cfg.description, truth), c.poses, seed, "kq_unc");
}

TEST(AuditUncertainty, MisfitWithinTheStiffnessUncertaintyIsCoveredAndNotEvidence) {
  const Campaign c = MakeSixPostureCampaign();
  const AuditResult r = RunWithUncertainty(c, StiffnessOffMeasured(c, 417), 0.10);
  ASSERT_TRUE(r.significant_failure) << r.verdict;
  ASSERT_TRUE(r.uncertainty.has_value());
  const UncertaintyAllowance& u = *r.uncertainty;
  EXPECT_EQ(u.rank, 6);
  EXPECT_NEAR(u.chi2, 12.5916, 1e-3);
  EXPECT_TRUE(u.covers_failure) << u.sentence;
  EXPECT_LE(u.error_noise_units, 1.3) << u.sentence;
  EXPECT_LE(u.distance, u.radius * (1.0 + 1e-9));
  EXPECT_NEAR(u.at.Get("kq2_Nm_per_rad") / c.cfg.parameters.Get("kq2_Nm_per_rad"), 0.85, 0.05) << u.sentence;
  EXPECT_NE(r.verdict.find("not evidence of a missing effect"), std::string::npos) << r.verdict;
  EXPECT_NE(r.headline.find("uncertainty alone could explain"), std::string::npos) << r.headline;
  ASSERT_FALSE(r.next_steps.empty());
  EXPECT_NE(r.next_steps.front().find("kq-identify --plan"), std::string::npos) << r.next_steps.front();
}

TEST(AuditUncertainty, MisfitBeyondTheStiffnessUncertaintyIsPartlyExplainedOnTheBoundary) {
  const Campaign c = MakeSixPostureCampaign();
  const AuditResult r = RunWithUncertainty(c, StiffnessOffMeasured(c, 419), 0.01);
  ASSERT_TRUE(r.significant_failure) << r.verdict;
  ASSERT_TRUE(r.uncertainty.has_value());
  const UncertaintyAllowance& u = *r.uncertainty;
  EXPECT_FALSE(u.covers_failure) << u.sentence;
  // The best point within the region is on its boundary (the truth is
  // outside); which parameters spend the region's budget is the fit's
  // business (kq3 and the calibration parameters trade off with kq2).
  EXPECT_NEAR(u.distance / u.radius, 1.0, 0.02) << u.sentence;
  EXPECT_GT(u.fraction_removed, 0.0) << u.sentence;
  EXPECT_LT(u.fraction_removed, 0.9) << u.sentence;
  EXPECT_GT(u.error_noise_units, 1.3);
  EXPECT_NE(r.verdict.find("the rest is a model error"), std::string::npos) << r.verdict;
}

// The same two joints off, with data from a second model that shares no
// code with the library: tests/audit/numpy_robot_frf.py (NumPy on the URDF:
// forward kinematics, body Jacobians, M = Σ m JvᵀJv + JωᵀIJω, Rayleigh
// damping, the receptance by a direct solve), at the five demonstration
// postures, 0.25-500 Hz, 2 % noise. Its nominal FRFs agree with frf-predict's
// to 1.4 % rms over 0.25-500 Hz, the noise it adds. The audit must name
// kq2 and kq3 within 10 % and no effect.
TEST(AuditHypotheses, JointStiffnessOffInDataFromASecondModelInNumPy) {
  const std::string python = NUMPY_PYTHON;
  if (python.empty()) GTEST_SKIP() << "no python3 with numpy: the second model's case is skipped";
  const Campaign c = testing::MakeCampaign();
  const Eigen::VectorXd kq = c.cfg.description.joint_stiffness;
  const std::string out = robomach::testing::TempDir("audit_hypotheses_numpy") + "/hammer.csv";
  std::ostringstream cmd;
  cmd.precision(17);
  cmd << python << " " << robomach::testing::SourcePath("tests/audit/numpy_robot_frf.py") << " "
      << robomach::testing::SourcePath("config/kr210_r2700_2.urdf") << " "
      << robomach::testing::SourcePath("config/postures_demo.csv") << " " << out;
  for (int j = 0; j < 6; ++j) cmd << " " << kq(j) * (j == 1 ? 0.6 : j == 2 ? 1.3 : 1.0);
  cmd << " --seed 335";
  ASSERT_EQ(std::system(cmd.str().c_str()), 0) << cmd.str();
  const dynamics::FrfSet read = io::ReadFrfCsv(out).frfs;
  const dynamics::FrfSet measured = calibration::UsableData(read, calibration::EstimateNoise(read, {}));
  const AuditResult r = RunCase(c, measured);
  EXPECT_EQ(r.grade, AuditGrade::kExplained) << r.verdict;
  EXPECT_TRUE(r.missing_effects.empty()) << r.verdict;
  ASSERT_EQ(r.parameter_changes.size(), 2u) << r.verdict;
  for (const ParameterChange& pc : r.parameter_changes) {
    const double expected = pc.name == "kq2_Nm_per_rad" ? 0.6 : pc.name == "kq3_Nm_per_rad" ? 1.3 : NAN;
    ASSERT_TRUE(std::isfinite(expected)) << "named " << pc.name;
    EXPECT_NEAR(pc.ratio() / expected, 1.0, 0.10) << pc.name << " ratio " << pc.ratio();
  }
}

// A posture-dependent joint stiffness (issue #33 §3): kq2 20 % lower than
// configured and stiffening by 30 % per kN·m of the gravity torque on
// joint 2 (a counterbalance, a preloaded gear). The audit must name the
// load-dependent form of joint 2 with both values within 10 %.
TEST(AuditHypotheses, JointStiffnessVaryingWithTheGravityTorqueIsNamed) {
  const Campaign c = MakeSixPostureCampaign();
  auto [d, p] = dynamics::WithEffect(c.cfg.description, c.cfg.parameters, "load_stiffness_j2");
  OffsetCalibration(c.cfg.parameters, &p);
  p.Set("kq2_Nm_per_rad", 0.8 * c.cfg.parameters.Get("kq2_Nm_per_rad"));
  p.Set("load_stiffness_j2.stiffening_per_kNm", 0.3);
  const dynamics::FrfSet measured = Measure(dynamics::RobotModel::Build(d, p), c.poses, 334, "load");
  const AuditResult r = RunCase(c, measured);
  EXPECT_TRUE(r.significant_failure);
  ASSERT_GE(r.graded, 0) << r.verdict;
  const CandidateResult& g = r.candidates[r.graded];
  EXPECT_EQ(r.grade, AuditGrade::kExplained) << r.verdict;
  EXPECT_EQ(g.name(), "load_stiffness_j2") << r.verdict;
  EXPECT_NEAR(g.fit.parameters.Get("kq2_Nm_per_rad") / p.Get("kq2_Nm_per_rad"), 1.0, 0.10);
  EXPECT_NEAR(g.fit.parameters.Get("load_stiffness_j2.stiffening_per_kNm") / 0.3, 1.0, 0.10);
  EXPECT_NE(r.headline.find("varies with the gravity torque"), std::string::npos) << r.headline;
}

// The KR210's URDF with a revolute joint "hinge_3x" inserted between joint_3
// and link_3, at link 3's frame, about its x axis: link 3 and everything
// beyond turn about it.
std::string HingedUrdf() {
  std::ifstream in(robomach::testing::SourcePath("config/kr210_r2700_2.urdf"));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string urdf = ss.str();
  const std::string joint3 = "<joint name=\"joint_3\" type=\"revolute\">";
  const size_t at = urdf.find(joint3);
  const size_t child = urdf.find("<child link=\"link_3\"/>", at);
  EXPECT_NE(child, std::string::npos);
  urdf.replace(child, std::string("<child link=\"link_3\"/>").size(), "<child link=\"link_3_hinge\"/>");
  const size_t end = urdf.find("</joint>", at) + std::string("</joint>").size();
  urdf.insert(end,
              "\n  <link name=\"link_3_hinge\"/>\n"
              "  <joint name=\"hinge_3x\" type=\"revolute\">\n"
              "    <parent link=\"link_3_hinge\"/>\n    <child link=\"link_3\"/>\n"
              "    <origin rpy=\"0 0 0\" xyz=\"0 0 0\"/>\n    <axis xyz=\"1 0 0\"/>\n"
              "    <limit effort=\"1\" lower=\"-0.1\" upper=\"0.1\" velocity=\"1\"/>\n  </joint>");
  return urdf;
}

TEST(AuditHypotheses, ElasticHingeInTheArmIsLocalisedToItsLinkAndAxis) {
  const Campaign c = MakeSixPostureCampaign();
  const std::string path = robomach::testing::TempDir("audit_hypotheses_hinge") + "/kr210_hinged.urdf";
  std::ofstream(path) << HingedUrdf();
  // The 7-joint truth: the hinge's spring is its joint stiffness.
  dynamics::RobotDescription d7 = c.cfg.description;
  d7.arm = io::LoadUrdfChain(path, "base_link", "tool0");
  ASSERT_EQ(d7.arm.num_joints(), 7);
  constexpr double kHinge = 4e6;  // N·m/rad
  const Eigen::VectorXd& kq = c.cfg.description.joint_stiffness;
  d7.joint_stiffness.resize(7);
  d7.joint_stiffness << kq(0), kq(1), kq(2), kHinge, kq(3), kq(4), kq(5);
  dynamics::ParameterSet p7 = dynamics::DefaultParameters(d7);
  for (const auto& s : p7.specs()) {
    if (s.name.rfind("kq", 0) != 0 && c.cfg.parameters.Has(s.name)) p7.Set(s.name, c.cfg.parameters.Get(s.name));
  }
  OffsetCalibration(c.cfg.parameters, &p7);
  std::vector<calibration::NamedPosture> poses7;
  for (const auto& [id, q] : c.poses) {
    Eigen::VectorXd q7(7);
    q7 << q(0), q(1), q(2), 0.0, q(3), q(4), q(5);
    poses7.push_back({id, q7});
  }
  const dynamics::FrfSet measured = Measure(dynamics::RobotModel::Build(d7, p7), poses7, 332, "hinge");
  const AuditResult r = RunCase(c, measured);
  EXPECT_TRUE(r.significant_failure);
  ASSERT_GE(r.graded, 0) << r.verdict;
  const CandidateResult& g = r.candidates[r.graded];
  EXPECT_TRUE(r.grade == AuditGrade::kExplained || r.grade == AuditGrade::kMostlyExplained) << r.verdict;
  EXPECT_EQ(g.name(), "virtual_joint_link3_rx") << r.verdict;
  EXPECT_GE(r.fraction_removed, 0.8) << r.verdict;
  // Its stiffness is the hinge's (the model is the same system, so within
  // the fit's scatter: 10 %).
  EXPECT_NEAR(g.fit.parameters.Get("virtual_joint_link3_rx.stiffness_Nm_per_rad") / kHinge, 1.0, 0.10);
  EXPECT_NE(r.headline.find("link 3's x axis"), std::string::npos) << r.headline;
  // The screen put it among the few fitted.
  bool screened = false;
  for (const auto& s : r.virtual_joint_screen) screened |= s.effect == "virtual_joint_link3_rx" && s.fitted;
  EXPECT_TRUE(screened);
}

// Data as they come (issue #33 §4): a base rocking on its foundation (a
// library effect) measured with an accelerometer and a hammer whose band
// ends near 1.2 kHz, at only four postures with y measured at two of them,
// and mains hum at 50, 100 and 150 Hz in every record (25 times the noise
// at its line: far outside it, and inside the usable band). The noise model must name the hum lines and leave them out
// of every fit; the audit must still name the base.
TEST(AuditHypotheses, LibraryEffectMeasuredWithHumBandLimitedAndFewPosturesIsNamedAndTheHumLeftOut) {
  Campaign all = MakeSixPostureCampaign();
  Campaign c = all;
  c.poses.resize(4);
  c.postures.clear();
  for (const auto& [id, q] : c.poses) c.postures[id] = q;
  const auto [d, p] = testing::Truth(c, {{"base_compliance",
                                          {{"base_compliance.lateral_stiffness_N_per_m", 3e8},
                                           {"base_compliance.rocking_stiffness_Nm_per_rad", 2e7}}}});
  calibration::VirtualHammerOptions ho = robomach::testing::RealisticHammerTest(333);
  ho.hammer_cutoff_hz = 1200.0;
  const dynamics::FrfSet synth = calibration::SynthesizeHammerTest(dynamics::RobotModel::Build(d, p), c.poses, ho);
  dynamics::FrfSet hummed;
  const std::vector<std::string> ids = synth.pose_ids();
  for (const auto& [key, frf] : synth) {
    // y measured at the first two postures only.
    if (key.response == Axis::kY && key.pose_id != ids[0] && key.pose_id != ids[1]) continue;
    Eigen::VectorXcd h = frf.receptance();
    for (int i = 0; i < frf.size(); ++i) {
      const double f = frf.freq_hz()(i);
      for (double mains : {50.0, 100.0, 150.0}) {
        // Hum is an additive voltage in the sensor's channel: its size is
        // set against the synthesis's own noise at the line (2 % of |H|,
        // the accelerometer's floor 1.5e-4 m/s²/N and 4e-9 m/N, as
        // realistic_hammer_test.h), 25 times that.
        const double w2 = std::pow(2.0 * kPi * f, 2);
        const double sigma = std::sqrt(std::pow(0.02 * std::abs(h(i)), 2) + std::pow(1.5e-4 / w2, 2) + std::pow(4e-9, 2));
        if (std::abs(f - mains) < 1e-6) h(i) += 25.0 * sigma * std::polar(1.0, 0.7 * mains);
      }
    }
    hummed.Insert(key, dynamics::Frf::FromSamples(frf.freq_hz(), h));
  }
  const std::string path = robomach::testing::TempDir("audit_hypotheses_hum") + "/hammer.csv";
  io::WriteFrfCsv(path, hummed, io::FrfQuantity::kAccelerance, 0);
  const dynamics::FrfSet read = io::ReadFrfCsv(path).frfs;
  const calibration::NoiseModels noise = calibration::EstimateNoise(read, {});
  // Every hum line inside an FRF's usable band is named, with its mains
  // frequency, and no other line is.
  for (const auto& [key, n] : noise) {
    std::set<long long> found;
    for (const auto& x : n.excluded_lines) {
      EXPECT_GT(x.mains_hz, 0.0) << key.ToString() << ": " << calibration::DescribeExcludedLine(x);
      EXPECT_GT(x.ratio, 6.0);
      found.insert(std::llround(x.freq_hz));
    }
    const dynamics::Frf& frf = read.at(key);
    for (long long mains : {50LL, 100LL, 150LL}) {
      int line = -1;
      for (int i = 0; i < frf.size(); ++i) {
        if (std::llround(frf.freq_hz()(i) * 1e3) == mains * 1000) line = i;
      }
      ASSERT_GE(line, 0);
      // Within the usable stretch around it (the line itself is excluded).
      const bool in_band = n.usable[static_cast<size_t>(line - 1)] && n.usable[static_cast<size_t>(line + 1)];
      if (in_band) EXPECT_TRUE(found.count(mains)) << key.ToString() << " hum at " << mains << " Hz not found";
    }
  }
  const dynamics::FrfSet measured = calibration::UsableData(read, noise);
  for (const auto& [key, frf] : measured) {
    for (int i = 0; i < frf.size(); ++i) {
      const double f = frf.freq_hz()(i);
      EXPECT_FALSE(std::abs(f - 50.0) < 1e-6 || std::abs(f - 100.0) < 1e-6 || std::abs(f - 150.0) < 1e-6)
          << key.ToString() << ": a hum line is in the fitted data";
    }
  }
  const AuditResult r = RunCase(c, measured);
  EXPECT_TRUE(r.significant_failure);
  EXPECT_TRUE(r.grade == AuditGrade::kExplained || r.grade == AuditGrade::kMostlyExplained) << r.verdict;
  EXPECT_EQ(r.missing_effects, std::vector<std::string>{"base_compliance"}) << r.verdict;
}

}  // namespace
}  // namespace robomach::audit
