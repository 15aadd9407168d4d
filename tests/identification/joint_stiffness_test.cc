#include "robomach/identification/joint_stiffness.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/identification/campaign_synth.h"
#include "robomach/identification/compliance_model.h"
#include "robomach/identification/load_case.h"
#include "robomach/identification/test_plan.h"
#include "test_campaign.h"

namespace robomach::identification {
namespace {

using testing::Kr210;
using testing::SeedCampaign;
using ::testing::HasSubstr;

// Published quantiles of χ²₃ (NIST/SEMATECH e-Handbook, table 1.3.6.7.4):
// upper 5 %: 7.815, 1 %: 11.345, 0.1 %: 16.266. Bisection on the closed-form
// survival function reaches ~1e-12; the table has 4 significant digits.
TEST(ChiSquare3, MatchesPublishedQuantiles) {
  EXPECT_NEAR(ChiSquare3UpperQuantile(0.05), 7.815, 5e-4);
  EXPECT_NEAR(ChiSquare3UpperQuantile(0.01), 11.345, 5e-4);
  EXPECT_NEAR(ChiSquare3UpperQuantile(0.001), 16.266, 5e-4);
}

// Noise-free data: the identification must return the truth. The only
// model error is the linearisation (synthesis uses the static equilibrium),
// ~|Δq|²R / |D| ≈ 1e-3 relative of D in the worst case and much less on
// average; the estimate inherits that, so 1e-3 relative bounds it.
TEST(IdentifyJointStiffness, NoiseFreeCampaignReturnsTruth) {
  const auto model = Kr210();
  CampaignOptions o;
  o.tracker_noise = 0.0;
  const auto cases = ToLoadCases(SeedCampaign(7, 12, o));
  IdentificationOptions io;  // noise 0.01 mm only weights the problem
  const JointStiffnessResult r = IdentifyJointStiffness(*model, cases, io);
  ASSERT_EQ(r.status, FitStatus::kConverged) << r.solver_message;
  const Eigen::VectorXd truth = model->joint_stiffness();
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(r.joint_stiffness(j) / truth(j), 1.0, 1e-3) << "joint " << j + 1;
    EXPECT_NEAR(r.linear_start(j) / truth(j), 1.0, 1e-3) << "joint " << j + 1;
  }
  EXPECT_TRUE(r.outliers.empty());
}

// Acceptance (issue #3), first half: a seed-shaped campaign (12 random
// postures in the machining workspace, two rope directions, 10/20/30 kg,
// tracker noise 0.01 mm) from the seed stiffness of config/kr210.yaml. For
// each joint, the truth lies inside the reported 95 % interval in at least
// 9 of 10 seeded repetitions.
//
// Why this is a fair test: with a correct covariance each interval covers
// the truth with p = 0.95, so a joint passes (>= 9 of 10) with probability
// 0.95^10 + 10·0.05·0.95^9 = 0.914. The seeds 1..10 were fixed before the
// first run and never changed.
TEST(IdentifyJointStiffness, SeedCampaignIntervalsCoverTruth) {
  const auto model = Kr210();
  const Eigen::VectorXd truth = model->joint_stiffness();
  std::vector<int> covered(6, 0);
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const auto ms = SeedCampaign(seed);
    ASSERT_EQ(ms.size(), 72u);  // 12 postures × 2 directions × 3 masses
    const JointStiffnessResult r = IdentifyJointStiffness(*model, ToLoadCases(ms));
    ASSERT_EQ(r.status, FitStatus::kConverged) << r.solver_message;
    ASSERT_TRUE(r.not_determined.empty()) << "seed " << seed;
    for (int j = 0; j < 6; ++j) {
      if (truth(j) >= r.lower_95(j) && truth(j) <= r.upper_95(j)) ++covered[j];
    }
  }
  for (int j = 0; j < 6; ++j) EXPECT_GE(covered[j], 9) << "joint " << j + 1;
}

// Acceptance (issue #3), second half: joints 1 to 3 within 5 %, in every one
// of 10 seeded repetitions. (Coverage is the test above and the calibration
// test below; asserting "9 of 10" for all six joints here as well would fail
// by chance with probability 1 − 0.914⁶ ≈ 0.42 even for exact intervals:
// with seeds 1..10 joint 6 was covered 8 times.)
//
// The campaign size follows from the Cramér-Rao bound, which no estimator
// beats: with 0.01 mm noise per tracker coordinate (√2 of it on a
// displacement) and 30 kg at most, k3's relative standard deviation is
// 4.5-6 % for 12 random postures and 3.6 % for the 12 best (D-optimal)
// postures, so "within 5 %" would fail in ~20-30 % of repetitions whatever
// the algorithm. 48 D-optimal postures bring it to 1.8 % (printed by
// `kq-identify --plan 48`), i.e. 5 % is 2.75 sigma. The campaign keeps the
// seed's shape otherwise: two rope directions per posture, 10/20/30 kg.
TEST(IdentifyJointStiffness, PlannedCampaignJoints1To3Within5Percent) {
  const auto model = Kr210();
  const Eigen::VectorXd truth = model->joint_stiffness();
  CampaignOptions co;
  PlanOptions po;
  po.num_postures = 48;
  po.p_load_tip = co.p_load_tip;
  po.p_target_tip = co.p_target_tip;
  const TestPlan plan = PlanLoadTests(*model, po);
  std::vector<std::string> ids;
  std::vector<Eigen::VectorXd> postures;
  std::vector<std::vector<Eigen::Vector3d>> pulleys;
  for (const PlannedLoad& l : plan.loads) {
    if (ids.empty() || ids.back() != l.pose_id) {
      ids.push_back(l.pose_id);
      postures.push_back(l.q);
      pulleys.emplace_back();
    }
    pulleys.back().push_back(l.p_pulley);
  }
  for (unsigned seed = 1; seed <= 10; ++seed) {
    co.seed = seed;
    const auto ms = SimulateCampaign(*model, ids, postures, pulleys, truth, co);
    ASSERT_EQ(ms.size(), 288u);
    const JointStiffnessResult r = IdentifyJointStiffness(*model, ToLoadCases(ms));
    ASSERT_EQ(r.status, FitStatus::kConverged) << r.solver_message;
    for (int j = 0; j < 3; ++j) {
      EXPECT_LT(std::abs(r.joint_stiffness(j) / truth(j) - 1.0), 0.05)
          << "seed " << seed << ", joint " << j + 1 << ", relative std " << r.relative_std(j);
    }
  }
}

// The reported uncertainty is calibrated: over 100 seeded seed-shaped
// campaigns each joint's 95 % interval covers the truth in 88..100 of them
// (binomial(100, 0.95): mean 95, sd 2.2; 88 is 3.2 sd below, a false alarm
// of ~0.1 % per joint), and z = log(k̂/k)/σ_θ has mean square 1 ± 0.2 over
// all 600 estimates (sd of the mean of 600 χ²₁ is 0.06 if independent; the
// joints of one campaign are correlated up to ~0.7, so ~0.1; 0.2 is 2 of
// those). Intervals that are too narrow or too wide both fail.
TEST(IdentifyJointStiffness, IntervalsAreCalibratedOver100Repetitions) {
  const auto model = Kr210();
  const Eigen::VectorXd truth = model->joint_stiffness();
  std::vector<int> covered(6, 0);
  double z2 = 0.0;
  for (unsigned seed = 101; seed <= 200; ++seed) {
    const JointStiffnessResult r = IdentifyJointStiffness(*model, ToLoadCases(SeedCampaign(seed)));
    for (int j = 0; j < 6; ++j) {
      if (truth(j) >= r.lower_95(j) && truth(j) <= r.upper_95(j)) ++covered[j];
      const double z = std::log(r.joint_stiffness(j) / truth(j)) / r.relative_std(j);
      z2 += z * z;
    }
  }
  for (int j = 0; j < 6; ++j) EXPECT_GE(covered[j], 88) << "joint " << j + 1;
  EXPECT_NEAR(z2 / 600.0, 1.0, 0.2);
}

// Two gross outliers (1 mm against a noise of 0.01 mm): the robust fit
// names exactly those two cases and returns the values of the clean data
// set. Leaving 2 of 72 cases out moves an estimate by ~σ·√(2/70) ≈ 0.17σ
// (σ the reported standard deviation), so 1σ is a >5-sigma bound on that.
TEST(IdentifyJointStiffness, RobustFitNamesOutliersAndRecoversValues) {
  const auto model = Kr210();
  CampaignOptions o;
  o.num_outliers = 2;
  o.outlier_size = 1e-3;
  std::vector<int> bad;
  const auto dirty = ToLoadCases(SeedCampaign(3, 12, o, &bad));
  o.num_outliers = 0;
  const auto clean_cases = ToLoadCases(SeedCampaign(3, 12, o));
  ASSERT_EQ(bad.size(), 2u);
  const JointStiffnessResult clean = IdentifyJointStiffness(*model, clean_cases);

  IdentificationOptions ro;
  ro.loss = RobustLoss::kCauchy;
  const JointStiffnessResult r = IdentifyJointStiffness(*model, dirty, ro);
  ASSERT_EQ(r.status, FitStatus::kConverged) << r.solver_message;
  EXPECT_EQ(r.outliers, bad);
  for (int c : r.outliers) EXPECT_TRUE(r.residuals[c].outlier);
  for (int j = 0; j < 6; ++j) {
    EXPECT_LT(std::abs(r.joint_stiffness(j) - clean.joint_stiffness(j)), clean.std_dev(j))
        << "joint " << j + 1;
  }
  bool named = false;
  for (const auto& a : r.advice) {
    if (a.find(dirty[bad[0]].case_id) != std::string::npos &&
        a.find(dirty[bad[1]].case_id) != std::string::npos) named = true;
  }
  EXPECT_TRUE(named);

  // A tracker noise understated 3× does not turn good cases into outliers:
  // the threshold follows the noise the residuals show.
  IdentificationOptions low = ro;
  low.tracker_noise = ro.tracker_noise / 3.0;
  const JointStiffnessResult rl = IdentifyJointStiffness(*model, dirty, low);
  EXPECT_EQ(rl.outliers, bad);
  // The sample median of 72 χ²₃ values has sd ≈ 1/(2 f(med) √72) = 0.31 with
  // f(2.366) = 0.188 the χ²₃ density at its median: 13 % of the median,
  // 6.6 % on its square root, ±0.2 here. 0.6 is 3 sd.
  EXPECT_NEAR(rl.robust_noise_ratio, 3.0, 0.6);
  // The Huber loss, too.
  ro.loss = RobustLoss::kHuber;
  EXPECT_EQ(IdentifyJointStiffness(*model, dirty, ro).outliers, bad);
  // Without a robust loss the two cases are still flagged (they are 70σ off).
  const JointStiffnessResult plain = IdentifyJointStiffness(*model, dirty);
  for (int c : bad) EXPECT_TRUE(plain.residuals[c].outlier);
  // ...and, kept in the fit, they flag the result (kq-identify exits 3);
  // the robust fit that left them out is not flagged for them.
  EXPECT_TRUE(plain.outliers_in_fit);
  EXPECT_TRUE(plain.flagged());
  EXPECT_FALSE(r.outliers_in_fit);
  EXPECT_EQ(r.flagged(), !r.weakly_identified.empty() || !r.not_determined.empty());
  EXPECT_FALSE(clean.outliers_in_fit);
}

// Issue #3: one posture with vertical loads only cannot determine the
// joints it does not see. A vertical force has no moment about the vertical
// joint-1 axis, and with load point and target on the tool axis joint 6 is
// neither loaded nor seen; one posture with one force direction gives one
// 3-vector of equations, so at most 3 of the 6 joints can be determined.
TEST(IdentifyJointStiffness, DegenerateCampaignFlagsJointsItCannotSee) {
  const auto model = Kr210();
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0, -90, 90, 0, 45, 0).finished() * (kPi / 180);
  std::vector<LoadCase> cases;
  for (double mkg : {10.0, 20.0, 30.0}) {
    LoadCase c;
    c.case_id = "V" + std::to_string(static_cast<int>(mkg));
    c.q = q;
    c.force = Eigen::Vector3d(0, 0, -mkg * kStandardGravity);
    c.displacement = PredictDisplacement(*model, c, model->joint_stiffness());
    cases.push_back(c);
  }
  const JointStiffnessResult r = IdentifyJointStiffness(*model, cases);
  EXPECT_TRUE(r.flagged());
  EXPECT_THAT(r.not_determined, ::testing::Contains(0));
  EXPECT_THAT(r.not_determined, ::testing::Contains(5));
  EXPECT_GE(r.not_determined.size(), 3u);
  EXPECT_EQ(r.determination[0], Determination::kNotDetermined);
  EXPECT_FALSE(std::isfinite(r.std_dev(0)));
  std::string all;
  for (const auto& a : r.advice) all += a + "\n";
  EXPECT_THAT(all, HasSubstr("joint 1 is not determined (the data do not depend on its stiffness): it is barely loaded"));
  EXPECT_THAT(all, HasSubstr("joint 6 is not determined"));
  EXPECT_THAT(all, HasSubstr("moment about the tool axis"));
  // Joints 2-5: four unknowns against one 3-vector of equations; at least
  // one exact trade-off among them, named as such, never "weakly".
  EXPECT_THAT(all, HasSubstr("exact trade-off"));
  for (int j = 1; j < 5; ++j) {
    if (r.determination[j] == Determination::kNotDetermined) {
      EXPECT_FALSE(std::isfinite(r.std_dev(j))) << "joint " << j + 1;
    }
  }
}

// Joint 6 loaded through a bracket but watched by a target on the tool axis:
// the target does not move when joint 6 turns, whatever the load. The
// advice must point at the target, not at the load.
TEST(IdentifyJointStiffness, TargetOnToolAxisIsNamedAsTheCause) {
  const auto model = Kr210();
  CampaignOptions o;
  o.p_target_tip = Eigen::Vector3d(0.0, 0.0, 0.2);  // on the tool axis
  const auto cases = ToLoadCases(SeedCampaign(2, 12, o));
  const JointStiffnessResult r = IdentifyJointStiffness(*model, cases);
  EXPECT_EQ(r.determination[5], Determination::kNotDetermined);
  EXPECT_LT(r.max_target_lever(5), 1e-9);  // exactly on the axis, up to rounding
  std::string all;
  for (const auto& a : r.advice) all += a + "\n";
  EXPECT_THAT(all, HasSubstr("tracker target barely moves when it turns"));
  EXPECT_THAT(all, HasSubstr("off the tool axis, tx_mm/ty_mm"));
  // The other joints are still determined, and their values are unaffected
  // by holding joint 6 (it has no effect on this target).
  for (int j = 0; j < 5; ++j) EXPECT_NE(r.determination[j], Determination::kNotDetermined) << j + 1;
}

// A stated noise 5× too small: the residuals show it, and the standard
// deviations are scaled up by √(χ²/dof) ≈ 5 instead of being overconfident.
TEST(IdentifyJointStiffness, UnderstatedNoiseInflatesCovariance) {
  const auto model = Kr210();
  const auto cases = ToLoadCases(SeedCampaign(4));
  IdentificationOptions o;
  o.tracker_noise = 2e-6;
  const JointStiffnessResult r = IdentifyJointStiffness(*model, cases, o);
  EXPECT_TRUE(r.covariance_inflated);
  // χ²/dof ≈ 25 with dof ≈ 210: its sampling std is 25·√(2/210) ≈ 2.4.
  EXPECT_NEAR(r.reduced_chi2, 25.0, 10.0);
  const JointStiffnessResult ref = IdentifyJointStiffness(*model, cases);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(r.relative_std(j) / ref.relative_std(j), 1.0, 0.3);
}

// Issue #10: a campaign whose joint 6 is weakly but genuinely informed.
// 16 postures of the machining workspace, two rope directions, 10/20/30 kg,
// tracker noise 0.01 mm, as the seed's campaign, but the load bracket only
// kWeakBracket off the tool axis, so the moment about joint 6 (and with it
// the information on k6, which grows as the moment squared) is small. The
// postures are fixed; only the tracker noise changes with `seed`.
constexpr double kWeakBracket = 0.05;  // [m]

std::vector<LoadCase> WeakJoint6Campaign(unsigned seed, double tracker_noise = 1e-5,
                                         double bracket = kWeakBracket) {
  const auto model = Kr210();
  CampaignOptions o;
  o.p_load_tip = Eigen::Vector3d(bracket, 0.0, 0.10);
  o.tracker_noise = tracker_noise;
  o.seed = seed;
  const auto postures = CampaignPostures(*model, 16, o, 4242);
  std::vector<std::string> ids;
  for (int p = 0; p < 16; ++p) ids.push_back("W" + std::to_string(p + 1));
  return ToLoadCases(SimulateCampaign(*model, ids, postures, model->joint_stiffness(), o));
}

// The independent reference: the Fisher information JᵀWJ of the campaign
// with J the central finite differences, in θ_j = log k_j, of the
// large-displacement static equilibrium (SolveStaticDeflection, the second
// method the synthesis uses, not the identification's linear model),
// W = 1/σ_D², σ_D = √2·0.01 mm. On noise-free data the fit sits at the
// truth, so its reported σ(θ_j) must equal √(F⁻¹)_jj. Agreement to 2 %:
// the linear model differs from the equilibrium by O(|Δq|) ~ 1e-3 relative,
// and the central differences (step 1e-3 in θ) by O(1e-6).
TEST(IdentifyJointStiffness, ReportedUncertaintyMatchesIndependentFisherInformation) {
  const auto model = Kr210();
  const auto cases = WeakJoint6Campaign(1, 0.0);
  const Eigen::VectorXd k0 = model->joint_stiffness();
  const double sigma = std::sqrt(2.0) * 1e-5, h = 1e-3;
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(6, 6);
  for (const LoadCase& c : cases) {
    Eigen::Matrix<double, 3, 6> J;
    for (int j = 0; j < 6; ++j) {
      Eigen::VectorXd kp = k0, km = k0;
      kp(j) *= std::exp(h);
      km(j) *= std::exp(-h);
      J.col(j) = (SolveStaticDeflection(*model, c, kp) - SolveStaticDeflection(*model, c, km)) / (2.0 * h);
    }
    F += J.transpose() * J / (sigma * sigma);
  }
  const Eigen::MatrixXd C = F.inverse();
  const JointStiffnessResult r = IdentifyJointStiffness(*model, cases);
  ASSERT_EQ(r.status, FitStatus::kConverged) << r.solver_message;
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(r.relative_std(j) / std::sqrt(C(j, j)), 1.0, 0.02) << "joint " << j + 1;
  }
  // The campaign is what the acceptance asks for: joint 6 at 30-60 %.
  EXPECT_GT(std::sqrt(C(5, 5)), 0.3);
  EXPECT_LT(std::sqrt(C(5, 5)), 0.6);
  std::cerr << "weak campaign: reference sigma(log k6) = " << std::sqrt(C(5, 5)) << ", reported "
            << r.relative_std(5) << "\n";
}

// Acceptance (issue #10): the weakly informed joint is reported "weakly
// determined" with its uncertainty, the advice names low sensitivity (the
// moment about its axis) and no trade-off, and the 95 % interval covers the
// truth in at least 9 of 10 seeded repetitions (exact intervals pass with
// probability 0.914, see SeedCampaignIntervalsCoverTruth; seeds 1..10 fixed
// before the first run). Never "not determined": the information is finite.
TEST(IdentifyJointStiffness, WeaklyInformedJointIsWeakWithCoveringInterval) {
  const auto model = Kr210();
  const double truth = model->joint_stiffness()(5);
  int covered = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const JointStiffnessResult r = IdentifyJointStiffness(*model, WeakJoint6Campaign(seed));
    ASSERT_EQ(r.status, FitStatus::kConverged) << r.solver_message;
    EXPECT_EQ(r.determination[5], Determination::kWeak) << "seed " << seed;
    EXPECT_TRUE(r.not_determined.empty()) << "seed " << seed;
    EXPECT_TRUE(std::isfinite(r.relative_std(5)));
    if (truth >= r.lower_95(5) && truth <= r.upper_95(5)) ++covered;
    std::string all;
    for (const auto& a : r.advice) all += a + "\n";
    EXPECT_THAT(all, HasSubstr("joint 6 is weakly determined (±")) << "seed " << seed;
    EXPECT_THAT(all, HasSubstr("low sensitivity")) << all;
    EXPECT_THAT(all, HasSubstr("moment about the tool axis")) << all;
    EXPECT_THAT(all, ::testing::Not(HasSubstr("not determined"))) << all;
    EXPECT_THAT(all, ::testing::Not(HasSubstr("trade-off"))) << all;
    std::cerr << "seed " << seed << ": k6 = " << r.joint_stiffness(5) << " [" << r.lower_95(5) << ", "
              << r.upper_95(5) << "], rel. std " << r.relative_std(5) << ", VIF " << r.variance_inflation(5)
              << "\n";
  }
  EXPECT_GE(covered, 9);
  RecordProperty("joint6_covered_of_10", covered);
  std::cerr << "joint 6: the 95 % interval covered the truth in " << covered << " of 10\n";
}

// Weaker still (bracket 20 mm: σ(log k6) ≈ 1.0 at the truth), the linear
// estimate of the compliance is negative in ~16 % of repetitions and the fit
// then drives k6 to infinity. That is still data, not a rank deficiency:
// the joint is weakly determined with a one-sided interval (a lower bound),
// never "not determined", and the intervals still cover the truth.
TEST(IdentifyJointStiffness, JointConsistentWithRigidIsWeakWithLowerBound) {
  const auto model = Kr210();
  const double truth = model->joint_stiffness()(5);
  int covered = 0, one_sided = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const JointStiffnessResult r = IdentifyJointStiffness(*model, WeakJoint6Campaign(seed, 1e-5, 0.02));
    ASSERT_EQ(r.status, FitStatus::kConverged) << r.solver_message;
    EXPECT_EQ(r.determination[5], Determination::kWeak) << "seed " << seed;
    EXPECT_TRUE(r.not_determined.empty()) << "seed " << seed;
    if (truth >= r.lower_95(5) && truth <= r.upper_95(5)) ++covered;
    if (!std::isfinite(r.relative_std(5))) {
      ++one_sided;
      EXPECT_EQ(r.joint_stiffness(5), truth);  // the prior (= the truth here) is kept
      std::string all;
      for (const auto& a : r.advice) all += a + "\n";
      EXPECT_THAT(all, HasSubstr("joint 6 is weakly determined: the data are consistent with a rigid joint"));
    }
  }
  EXPECT_GE(covered, 9);
  EXPECT_GE(one_sided, 1) << "no repetition exercised the rigid case; pick another bracket";
  std::cerr << "bracket 20 mm: covered " << covered << " of 10, " << one_sided << " one-sided\n";
}

// A near (not exact) trade-off: two load cases at one posture with rope
// directions close to each other give 6 equations whose joint columns are
// nearly dependent; the weakly determined joints are reported with the
// joints they trade off against, and the variance inflation says so.
TEST(IdentifyJointStiffness, NearTradeOffNamesThePartners) {
  const auto model = Kr210();
  // Postures close to each other: the columns of joints 2 and 3 (shoulder
  // and elbow, both horizontal axes) stay nearly proportional.
  CampaignOptions o;
  o.tracker_noise = 0.0;
  const auto cases = ToLoadCases(SeedCampaign(5, 3, o));
  const JointStiffnessResult r = IdentifyJointStiffness(*model, cases);
  ASSERT_EQ(r.status, FitStatus::kConverged) << r.solver_message;
  bool traded = false;
  for (int j : r.weakly_identified) {
    if (r.variance_inflation(j) >= 2.0) {
      traded = true;
      ASSERT_FALSE(r.trade_off_with[j].empty());
      // The named partner is the one most correlated with j.
      const int p = r.trade_off_with[j][0];
      for (int i = 0; i < 6; ++i) {
        if (i != j && i != p && std::isfinite(r.correlation(j, i))) {
          EXPECT_GE(std::abs(r.correlation(j, p)), std::abs(r.correlation(j, i)) - 1e-12);
        }
      }
      std::string all;
      for (const auto& a : r.advice) all += a + "\n";
      EXPECT_THAT(all, HasSubstr("joint " + std::to_string(j + 1) + " is weakly determined"));
      EXPECT_THAT(all, HasSubstr("near trade-off with joint"));
      std::cerr << all;
    }
  }
  EXPECT_TRUE(traded) << "this campaign has no near trade-off; pick another";
}

TEST(IdentifyJointStiffness, InvalidOptionsNameTheField) {
  IdentificationOptions o;
  o.tracker_noise = -1.0;
  EXPECT_THAT(testing::CaptureError([&] { o.Validate(); }), HasSubstr("tracker_noise"));
}

// One rule for a fit's and a plan's joints: rank-deficient (inf, NaN) is
// not determined, above the bound weak, else determined (the bound itself
// is still determined).
TEST(DeterminationFromRelativeStd, ClassifiesAtTheBound) {
  const double weak = IdentificationOptions{}.weak_relative_std;
  EXPECT_EQ(DeterminationFromRelativeStd(0.01, weak), Determination::kDetermined);
  EXPECT_EQ(DeterminationFromRelativeStd(weak, weak), Determination::kDetermined);
  EXPECT_EQ(DeterminationFromRelativeStd(std::nextafter(weak, 1.0), weak), Determination::kWeak);
  EXPECT_EQ(DeterminationFromRelativeStd(1e6, weak), Determination::kWeak);
  EXPECT_EQ(DeterminationFromRelativeStd(std::numeric_limits<double>::infinity(), weak), Determination::kNotDetermined);
  EXPECT_EQ(DeterminationFromRelativeStd(std::numeric_limits<double>::quiet_NaN(), weak), Determination::kNotDetermined);
}

// One vocabulary (issue #36): each determination goes through its name and
// back, and a name that is not one is refused.
TEST(Determination, RoundTripsThroughItsName) {
  for (Determination d : {Determination::kDetermined, Determination::kWeak, Determination::kNotDetermined}) {
    EXPECT_EQ(ParseDetermination(ToString(d)), d) << ToString(d);
  }
  EXPECT_THROW(ParseDetermination("weak"), std::invalid_argument);
}

// Issue #36: every RobustLoss goes through its name (kq-identify's --robust)
// and back; another name is refused naming all three.
TEST(RobustLoss, RoundTripsThroughItsName) {
  for (RobustLoss l : {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy}) {
    EXPECT_EQ(ParseRobustLoss(ToString(l)), l) << ToString(l);
  }
  try {
    ParseRobustLoss("lts");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "robust loss 'lts': expected none, huber or cauchy");
  }
}

}  // namespace
}  // namespace robomach::identification
