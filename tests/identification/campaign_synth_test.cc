#include "robomach/identification/campaign_synth.h"

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/identification/compliance_model.h"
#include "test_campaign.h"

namespace robomach::identification {
namespace {

using testing::Kr210;

// The postures keep every promise of CampaignPostures: inside the joint
// limits, load point 0.3 m above the floor and min_reach from the base axis,
// every rope within 60° of vertical.
TEST(CampaignSynth, PosturesSatisfyTheirConstraints) {
  const auto model = Kr210();
  const CampaignOptions o;
  const auto qs = CampaignPostures(*model, 20, o, 4);
  ASSERT_EQ(qs.size(), 20u);
  for (const auto& q : qs) {
    EXPECT_TRUE(model->chain().JointsOutsideLimits(q).empty());
    LoadCase c;
    c.q = q;
    c.p_load_tip = o.p_load_tip;
    c.p_target_tip = o.p_target_tip;
    const CaseKinematics k = EvaluateCaseKinematics(*model, c);
    EXPECT_GE(k.p_BL.z(), 0.3);
    EXPECT_GE(k.p_BL.head<2>().norm(), o.min_reach);
    for (const auto& pulley : o.pulleys) {
      const Eigen::Vector3d d = (pulley - k.p_BL).normalized();
      EXPECT_GE(-d.z(), 0.5 - 1e-12);
    }
  }
}

// The simulated readings: p0 is the target's true position plus noise of the
// stated sigma, p1 − p0 the static deflection plus noise, the rope points lie
// on the rope. The sample standard deviation of 12·2·3·3 = 216 noise values
// has a relative standard error of 1/√(2·216) ≈ 4.8 %; 15 % is 3 of those.
TEST(CampaignSynth, ReadingsCarryTheStatedNoise) {
  const auto model = Kr210();
  CampaignOptions o;
  o.tracker_noise = 1e-5;
  const auto qs = CampaignPostures(*model, 12, o, 8);
  std::vector<std::string> ids(qs.size(), "P");
  const auto ms = SimulateCampaign(*model, ids, qs, model->joint_stiffness(), o);
  ASSERT_EQ(ms.size(), 72u);
  double sum2 = 0.0;
  int count = 0;
  for (const auto& m : ms) {
    LoadCase c;
    c.q = m.q;
    c.p_load_tip = o.p_load_tip;
    c.p_target_tip = o.p_target_tip;
    const CaseKinematics k = EvaluateCaseKinematics(*model, c);
    const Eigen::Vector3d e = m.p0 - k.p_BT;
    sum2 += e.squaredNorm();
    count += 3;
    // A and B within a few sigma of the rope line from the load point.
    const Eigen::Vector3d d = (m.rope_B - m.rope_A).normalized();
    const Eigen::Vector3d off = (m.rope_A - k.p_BL) - d * d.dot(m.rope_A - k.p_BL);
    EXPECT_LT(off.norm(), 10 * o.tracker_noise);
    EXPECT_GT(m.mass_kg, 0.0);
  }
  EXPECT_NEAR(std::sqrt(sum2 / count) / o.tracker_noise, 1.0, 0.15);
}

// Outliers: exactly the requested number, distinct, each moving p1 by
// outlier_size (the noise is zero here, so the error is the outlier alone
// against the noise-free reading of the same case).
TEST(CampaignSynth, OutliersHaveTheRequestedSize) {
  const auto model = Kr210();
  CampaignOptions o;
  o.tracker_noise = 0.0;
  const auto qs = CampaignPostures(*model, 4, o, 2);
  std::vector<std::string> ids(qs.size(), "P");
  const auto clean = SimulateCampaign(*model, ids, qs, model->joint_stiffness(), o);
  o.num_outliers = 3;
  o.outlier_size = 2e-3;
  std::vector<int> bad;
  const auto dirty = SimulateCampaign(*model, ids, qs, model->joint_stiffness(), o, &bad);
  ASSERT_EQ(bad.size(), 3u);
  for (size_t c = 0; c < clean.size(); ++c) {
    const bool is_bad = std::find(bad.begin(), bad.end(), static_cast<int>(c)) != bad.end();
    EXPECT_NEAR((dirty[c].p1 - clean[c].p1).norm(), is_bad ? 2e-3 : 0.0, 1e-15) << c;
  }
}

}  // namespace
}  // namespace robomach::identification
