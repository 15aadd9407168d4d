// Issue #36, one vocabulary: every options struct of identification has a
// Validate() that passes its defaults and refuses a bad value of each
// checked field with an OptionError naming the field, its value and the
// bound.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "options_validate_support.h"
#include "robomach/common/errors.h"
#include "robomach/identification/campaign_synth.h"
#include "robomach/identification/joint_stiffness.h"
#include "robomach/identification/test_plan.h"

namespace robomach::identification {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(IdentificationOptions{}.Validate());
  EXPECT_NO_THROW(PlanOptions{}.Validate());
  EXPECT_NO_THROW(CampaignOptions{}.Validate());
}

TEST(OptionsValidate, IdentificationOptionsNameFieldValueAndBound) {
  using O = IdentificationOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.tracker_noise = -1; }, "tracker_noise",
                   {"tracker_noise: expected a finite value > 0 m", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.loss_scale = 0; }, "loss_scale", {"a value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.outlier_false_alarm = 1; }, "outlier_false_alarm", {"in (0, 1)", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.weak_relative_std = 0; }, "weak_relative_std", {"a value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_iterations = 0; }, "max_iterations", {"at least 1", "got 0"});
}

TEST(OptionsValidate, PlanOptionsNameFieldValueAndBound) {
  using O = PlanOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.num_postures = 0; }, "num_postures", {"num_postures: expected at least 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.directions_per_posture = 0; }, "directions_per_posture",
                   {"at least 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.masses_kg.clear(); }, "masses_kg", {"at least one mass", "got none"});
  ExpectRefused<O>(d, [](O& o) { o.masses_kg = {10.0, -1.0}; }, "masses_kg", {"masses > 0 kg", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.tracker_noise = 0; }, "tracker_noise", {"a value > 0 m", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_rope_angle = 2; }, "max_rope_angle", {"[0, pi/2) rad", "got 2"});
  ExpectRefused<O>(d, [](O& o) { o.num_candidate_postures = 5; }, "num_candidate_postures",
                   {"at least num_postures", "got 5"});
  ExpectRefused<O>(d, [](O& o) { o.num_azimuths = 0; }, "num_azimuths", {"at least 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.joint_limit_margin = -1; }, "joint_limit_margin", {">= 0 rad", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.weak_relative_std = 0; }, "weak_relative_std", {"a value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.target_gradients = Eigen::MatrixXd::Constant(6, 1, std::nan("")); },
                   "target_gradients", {"expected finite numbers", "NaN"});
  ExpectRefused<O>(d, [](O& o) { o.target_half_width = -1; }, "target_half_width", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.target_confidence = 1; }, "target_confidence", {"in (0, 1)", "got 1"});
}

TEST(OptionsValidate, CampaignOptionsNameFieldValueAndBound) {
  using O = CampaignOptions;
  const O d;
  const double inf = std::numeric_limits<double>::infinity();
  ExpectRefused<O>(d, [](O& o) { o.masses_kg.clear(); }, "masses_kg", {"at least one mass", "got none"});
  ExpectRefused<O>(d, [](O& o) { o.masses_kg = {10.0, 0.0}; }, "masses_kg",
                   {"masses_kg: expected a value > 0, got 0"});
  ExpectRefused<O>(d, [&](O& o) { o.masses_kg = {inf}; }, "masses_kg", {"expected a finite value", "got inf"});
  ExpectRefused<O>(d, [](O& o) { o.tracker_noise = -1; }, "tracker_noise", {"expected a value >= 0", "got -1"});
  ExpectRefused<O>(d, [&](O& o) { o.tracker_noise = inf; }, "tracker_noise", {"finite", "got inf"});
  ExpectRefused<O>(d, [](O& o) { o.num_outliers = -1; }, "num_outliers", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.outlier_size = -1; }, "outlier_size", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.rope_A_distance = -1; }, "rope_A_distance", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.rope_B_distance = 0.05; }, "rope_B_distance",
                   {"rope_B_distance: expected a value > rope_A_distance 0.1, got 0.05"});
  ExpectRefused<O>(d, [](O& o) { o.min_reach = -1; }, "min_reach", {">= 0", "got -1"});
}

}  // namespace
}  // namespace robomach::identification
