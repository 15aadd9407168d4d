// Issue #36, one vocabulary: every options struct of dynamics has a
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
#include "robomach/dynamics/frf_prediction.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/uncertainty.h"

namespace robomach::dynamics {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(PropagationOptions{}.Validate());
  EXPECT_NO_THROW(PredictOptions{}.Validate());
  EXPECT_NO_THROW(PostureOptions{}.Validate());
}

TEST(OptionsValidate, PropagationOptionsNameFieldValueAndBound) {
  using O = PropagationOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.confidence = 95; }, "confidence",
                   {"confidence: expected a level in (0, 1), got 95", "a percentage?"});
  ExpectRefused<O>(d, [](O& o) { o.confidence = 0; }, "confidence", {"in (0, 1)", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.samples = 10; }, "samples", {"100 - 10 000 000", "got 10"});
  ExpectRefused<O>(d, [](O& o) { o.nonlinearity_tolerance = 0; }, "nonlinearity_tolerance",
                   {"expected (0, 1]", "got 0"});
}

TEST(OptionsValidate, PredictOptionsNameFieldValueAndBound) {
  using O = PredictOptions;
  const O d;
  O direct;
  direct.method = ReceptanceMethod::kDirect;
  EXPECT_NO_THROW(direct.Validate());
  ExpectRefused<O>(d, [](O& o) { o.method = static_cast<ReceptanceMethod>(7); }, "method",
                   {"expected modal (0) or direct (1)", "got 7"});
}

// Every combination of PostureOptions' flags is valid: nothing to refuse.
TEST(OptionsValidate, PostureOptionsAcceptEveryCombination) {
  for (int bits = 0; bits < 64; ++bits) {
    PostureOptions o;
    o.cartesian = (bits & 1) != 0;
    o.modes = (bits & 2) != 0;
    o.jacobian_condition = (bits & 4) != 0;
    o.static_compliance = (bits & 8) != 0;
    o.modal_masses = (bits & 16) != 0;
    o.damping_ratios = (bits & 32) != 0;
    EXPECT_NO_THROW(o.Validate()) << bits;
  }
}

}  // namespace
}  // namespace robomach::dynamics
