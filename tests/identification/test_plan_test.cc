#include "robomach/identification/test_plan.h"

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/identification/campaign_synth.h"
#include "robomach/identification/compliance_model.h"
#include "robomach/identification/joint_stiffness.h"
#include "test_campaign.h"

namespace robomach::identification {
namespace {

using testing::Kr210;

PlanOptions BracketPlan() {
  PlanOptions o;
  o.num_postures = 8;
  o.num_candidate_postures = 150;
  o.p_load_tip = Eigen::Vector3d(0.15, 0.0, 0.10);
  o.p_target_tip = Eigen::Vector3d(0.0, 0.12, 0.05);
  return o;
}

// The plan satisfies its constraints: joints inside the limits with the
// margin, load points above the floor, ropes within the cone, pulleys on the
// floor, and every planned case is a rope force of the given masses.
TEST(PlanLoadTests, PlanRespectsLimitsAndRopeGeometry) {
  const auto model = Kr210();
  const PlanOptions o = BracketPlan();
  const TestPlan plan = PlanLoadTests(*model, o);
  ASSERT_EQ(plan.loads.size(), 16u);
  ASSERT_EQ(plan.cases.size(), 48u);
  for (const PlannedLoad& l : plan.loads) {
    EXPECT_TRUE(model->chain().JointsOutsideLimits(l.q).empty());
    EXPECT_GE(l.p_load.z(), o.min_load_height - 1e-12);
    EXPECT_LE(std::acos(-l.rope_direction.z()), o.max_rope_angle + 1e-12);
    EXPECT_NEAR(l.p_pulley.z(), o.floor_z, 1e-12);
    EXPECT_NEAR(l.rope_direction.norm(), 1.0, 1e-12);
  }
}

// The predicted standard deviations are the Cramér-Rao bound of the
// estimator (linear model, Gaussian noise): simulating the plan's cases with
// noise and identifying must give the predicted relative std. Checked
// against the identification's own covariance (a second computation through
// Ceres) to 5 %: both are the same matrix at nearly the same point; the
// difference is the change of the Jacobian between the prior and the
// estimate (~|θ̂−θ| ≈ 1-3 %).
TEST(PlanLoadTests, ExpectedStdMatchesIdentificationCovariance) {
  const auto model = Kr210();
  const PlanOptions o = BracketPlan();
  const TestPlan plan = PlanLoadTests(*model, o);
  ASSERT_TRUE(plan.expected_relative_std.allFinite());
  std::vector<LoadCase> cases = plan.cases;
  for (LoadCase& c : cases) c.displacement = PredictDisplacement(*model, c, model->joint_stiffness());
  const JointStiffnessResult r = IdentifyJointStiffness(*model, cases);
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(r.relative_std(j) / plan.expected_relative_std(j), 1.0, 0.05) << "joint " << j + 1;
  }
}

// D-optimality: the plan's log det beats random postures with the same
// number of cases and the same rope cone (the seed-shaped campaign), for
// several random draws.
TEST(PlanLoadTests, PlanBeatsRandomCampaigns) {
  const auto model = Kr210();
  const PlanOptions o = BracketPlan();
  const TestPlan plan = PlanLoadTests(*model, o);
  const double sigma = std::sqrt(2.0) * o.tracker_noise;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const auto ms = testing::SeedCampaign(seed, o.num_postures);
    const Eigen::MatrixXd I =
        LogStiffnessInformation(*model, ToLoadCases(ms), model->joint_stiffness(), sigma);
    const double ld = std::log(I.determinant());
    EXPECT_GT(plan.log_det_information, ld) << "seed " << seed;
  }
}

// With load point and target on the tool axis (the default TCP), no plan can
// load or see joint 6: the expected std says so (infinite).
TEST(PlanLoadTests, TcpOnToolAxisCannotDetermineJoint6) {
  const auto model = Kr210();
  PlanOptions o;
  o.num_postures = 6;
  o.num_candidate_postures = 100;
  const TestPlan plan = PlanLoadTests(*model, o);
  EXPECT_GT(plan.expected_relative_std(5), 1.0);
  EXPECT_LT(plan.expected_relative_std(0), 0.1);
}

// num_candidate_postures 0 (the default) draws max(400, 4 N) candidates:
// the KR210's limits with the margin leave almost every random posture
// feasible, so the count is reached; an explicit count smaller than N is
// refused, 0 is not.
TEST(PlanLoadTests, AutomaticCandidateCount) {
  const auto model = Kr210();
  PlanOptions o;
  o.num_postures = 2;
  o.directions_per_posture = 1;
  o.masses_kg = {20.0};
  EXPECT_NO_THROW(o.Validate());
  EXPECT_EQ(PlanLoadTests(*model, o).num_candidates, 400);
  o.num_candidate_postures = 1;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

// A targeted plan (issue #37 §5): with the gradients of a quantity the user
// cares about (here one that rests on joints 2, 3 and 5, as a lobe bottom
// can), the plan minimises that quantity's variance instead of log det I.
// Checked through a second route (LogStiffnessInformation of the planned
// cases): the reported relative std is √(gᵀ I⁻¹ g); the targeted plan beats
// the D-optimal one on it by a clear margin; the half-width never grows with
// more postures; a joint no target feels is not flagged (joint 6 with the
// load and the target on the tool axis), and a band out of reach is flagged
// with an estimate of the postures that would reach it.
TEST(PlanLoadTests, TargetedPlanNarrowsItsTargetMoreThanTheDOptimalOne) {
  const auto model = Kr210();
  PlanOptions o;
  o.num_postures = 6;
  o.num_candidate_postures = 150;
  Eigen::VectorXd g(6);
  g << 0.0, 0.35, -0.25, 0.0, 0.4, 0.0;
  const TestPlan d_optimal = PlanLoadTests(*model, o);
  EXPECT_TRUE(d_optimal.verdict.flagged());  // joint 6 on the tool axis
  o.target_gradients = g;
  o.target_half_width = 0.01;  // out of reach of 6 postures (±2.9 %)
  const TestPlan targeted = PlanLoadTests(*model, o);
  const double sigma = std::sqrt(2.0) * o.tracker_noise;
  auto target_std = [&](const TestPlan& p) {
    const Eigen::MatrixXd I = LogStiffnessInformation(*model, p.cases, model->joint_stiffness(), sigma);
    const Eigen::MatrixXd sub = I.topLeftCorner(5, 5);  // joint 6 unseen: g(5) = 0 keeps the target determined
    return std::sqrt(g.head(5).dot(sub.ldlt().solve(g.head(5))));
  };
  ASSERT_EQ(targeted.expected_target_relative_std.size(), 1);
  EXPECT_NEAR(targeted.expected_target_relative_std(0) / target_std(targeted), 1.0, 1e-6);
  EXPECT_LT(target_std(targeted), 0.8 * target_std(d_optimal));
  ASSERT_EQ(targeted.target_half_width_by_postures.size(), 6u);
  for (size_t k = 1; k < 6; ++k) {
    EXPECT_LE(targeted.target_half_width_by_postures[k], targeted.target_half_width_by_postures[k - 1] * (1 + 1e-9));
  }
  EXPECT_NEAR(targeted.target_half_width_by_postures.back(), 1.959964 * targeted.expected_target_relative_std(0), 1e-6);
  EXPECT_EQ(targeted.postures_for_target_width, 0);
  // Variance as 1/k: 6 (2.85 / 1)² ≈ 49 postures.
  EXPECT_NEAR(targeted.postures_for_target_width_estimate,
              6 * std::pow(targeted.target_half_width_by_postures.back() / 0.01, 2), 1.0);
  ASSERT_EQ(targeted.verdict.findings.size(), 1u);  // the band, not joint 6
  EXPECT_NE(targeted.verdict.findings[0].message.find("postures would reach it"), std::string::npos)
      << targeted.verdict.findings[0].message;
  // A band within reach: the first k postures reach it, no finding.
  o.target_half_width = targeted.target_half_width_by_postures[3] * 1.0001;
  const TestPlan reached = PlanLoadTests(*model, o);
  EXPECT_FALSE(reached.verdict.flagged());
  EXPECT_GE(reached.postures_for_target_width, 1);
  EXPECT_LE(reached.postures_for_target_width, 4);
  // Gradients of the wrong size are refused.
  o.target_gradients = Eigen::VectorXd::Ones(5);
  EXPECT_THROW(PlanLoadTests(*model, o), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::identification
