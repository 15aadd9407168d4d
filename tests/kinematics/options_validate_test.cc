// Issue #36, one vocabulary: every options struct of kinematics has a
// Validate() that passes its defaults and refuses a bad value of each
// checked field with an OptionError naming the field, its value and the
// bound.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "options_validate_support.h"
#include "robomach/common/errors.h"
#include "robomach/kinematics/inverse_kinematics.h"
#include "robomach/kinematics/pose_path.h"

namespace robomach::kinematics {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(IkOptions{}.Validate());
  EXPECT_NO_THROW(PosePathOptions{}.Validate());
}

TEST(OptionsValidate, IkOptionsNameFieldValueAndBound) {
  using O = IkOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.position_tolerance_m = 0; }, "position_tolerance_m",
                   {"position_tolerance_m: expected a value > 0, got 0"});
  ExpectRefused<O>(d, [](O& o) { o.rotation_tolerance_rad = -1; }, "rotation_tolerance_rad",
                   {"expected a value > 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.converged_position_m = 0; }, "converged_position_m", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.converged_rotation_rad = 0; }, "converged_rotation_rad", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_iterations = 0; }, "max_iterations", {"expected a value >= 1", "got 0"});
}

TEST(OptionsValidate, PosePathOptionsNameFieldValueAndBound) {
  using O = PosePathOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.ik.max_iterations = 0; }, "ik.max_iterations",
                   {"ik.max_iterations: expected a value >= 1, got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_joint_step_rad = 0; }, "max_joint_step_rad",
                   {"max_joint_step_rad: expected a value > 0, got 0"});
}

}  // namespace
}  // namespace robomach::kinematics
