// The prediction workflow (dynamics::PredictFrfs): what it computes is the
// per-posture receptance of the other method (direct solve against modal
// superposition), and what it flags are the joint limits and singular
// postures, each naming the posture it concerns.
#include "robomach/dynamics/frf_prediction.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "robomach/dynamics/tool_tip_frf.h"
#include "test_models.h"

namespace robomach::dynamics {
namespace {

using testing::Kr210;
using testing::RandomPosture;

Eigen::VectorXd Lines() { return Eigen::VectorXd::LinSpaced(400, 0.0, 250.0); }

double MaxRelDiff(const std::vector<Eigen::Matrix3cd>& a, const std::vector<Eigen::Matrix3cd>& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (a[i] - b[i]).norm() / b[i].norm());
  return worst;
}

TEST(FrfPrediction, ModalEqualsDirectSolveAndPosturesInsideLimitsAreOk) {
  const auto model = Kr210();
  std::mt19937 rng(211);
  std::vector<NamedPosture> postures;
  for (int p = 0; p < 3; ++p) postures.push_back({"p" + std::to_string(p), RandomPosture(*model, rng)});
  const FrfPredictionResult modal = PredictFrfs(model, postures, Lines());
  PredictOptions direct_options;
  direct_options.method = ReceptanceMethod::kDirect;
  long calls = 0;
  direct_options.progress = [&](long done, long total) {
    EXPECT_EQ(done, ++calls);
    EXPECT_EQ(total, 3);
  };
  const FrfPredictionResult direct = PredictFrfs(model, postures, Lines(), direct_options);
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(modal.status(), RunStatus::kOk);
  EXPECT_TRUE(modal.verdict.findings.empty());
  ASSERT_EQ(modal.postures.size(), 3u);
  for (size_t p = 0; p < 3; ++p) {
    EXPECT_EQ(modal.postures[p].id, postures[p].id);
    ASSERT_EQ(modal.postures[p].H.size(), 400u);
    // The modal sum of real modes against one linear solve per line (the
    // damping is Rayleigh, so the real modes are exact): rounding only.
    EXPECT_LE(MaxRelDiff(modal.postures[p].H, direct.postures[p].H), 1e-9);
  }
}

TEST(FrfPrediction, JointOutsideLimitsAndSingularPostureAreFlaggedNotRefused) {
  const auto model = Kr210();
  const auto& lim = model->chain().limits();
  ASSERT_TRUE(lim[1].bounded);
  std::mt19937 rng(212);
  Eigen::VectorXd inside = RandomPosture(*model, rng);
  Eigen::VectorXd outside = inside;
  outside(1) = lim[1].upper + 0.1;
  Eigen::VectorXd singular(6);
  singular << 0.0, DegToRad(-90), DegToRad(90), 0.0, 0.0, 0.0;  // q5 = 0: the wrist singularity
  const FrfPredictionResult r =
      PredictFrfs(model, {{"in", inside}, {"out", outside}, {"wrist", singular}}, Lines());
  EXPECT_EQ(r.status(), RunStatus::kFlagged);
  ASSERT_EQ(r.verdict.findings.size(), 2u);
  EXPECT_EQ(r.verdict.findings[0].input_index, 1);
  EXPECT_NE(r.verdict.findings[0].message.find("posture out: joint 2"), std::string::npos) << r.verdict.findings[0].message;
  EXPECT_NE(r.verdict.findings[0].message.find("outside its limits"), std::string::npos);
  EXPECT_EQ(r.verdict.findings[1].input_index, 2);
  EXPECT_NE(r.verdict.findings[1].message.find("near a singularity"), std::string::npos) << r.verdict.findings[1].message;
  EXPECT_EQ(r.postures[1].joints_outside_limits, std::vector<int>{1});
  // Flagged, still computed: every posture has its finite FRF.
  for (const auto& p : r.postures) {
    for (const auto& h : p.H) ASSERT_TRUE(h.allFinite()) << p.id;
  }
}

TEST(FrfPrediction, BadFrequencyAndMethodAreRefused) {
  const auto model = Kr210();
  std::mt19937 rng(213);
  Eigen::VectorXd f = Lines();
  f(7) = NAN;
  EXPECT_THROW(PredictFrfs(model, {{"p", RandomPosture(*model, rng)}}, f), std::invalid_argument);
  f(7) = -1.0;
  EXPECT_THROW(PredictFrfs(model, {{"p", RandomPosture(*model, rng)}}, f), std::invalid_argument);
  EXPECT_THROW(ParseReceptanceMethod("modes"), std::invalid_argument);
  EXPECT_EQ(ParseReceptanceMethod("direct"), ReceptanceMethod::kDirect);
}

// One vocabulary (issue #36): each method goes through its name and back, and
// a name that is not one is refused.
TEST(ReceptanceMethod, RoundTripsThroughItsName) {
  for (ReceptanceMethod m : {ReceptanceMethod::kModal, ReceptanceMethod::kDirect}) {
    EXPECT_EQ(ParseReceptanceMethod(ToString(m)), m) << ToString(m);
  }
  EXPECT_THROW(ParseReceptanceMethod("Modal"), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::dynamics
