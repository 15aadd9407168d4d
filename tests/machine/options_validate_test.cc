// Issue #36, one vocabulary: every options struct of machine has a
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
#include "robomach/machine/quadrature_decoder.h"
#include "robomach/machine/synthesis.h"

namespace robomach::machine {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(QuadratureOptions{}.Validate());
  EXPECT_NO_THROW(SynthesisOptions{}.Validate());
}

TEST(OptionsValidate, QuadratureOptionsNameFieldValueAndBound) {
  using O = QuadratureOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.num_axes = 0; }, "num_axes", {"num_axes: expected a value in [1, 8]", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.num_axes = 9; }, "num_axes", {"[1, 8]", "got 9"});
  ExpectRefused<O>(d, [](O& o) { o.glitch_filter_samples = -1; }, "glitch_filter_samples",
                   {"glitch_filter_samples: expected a value in [0, 1e+06]", "got -1"});
  // The decoder checks its options first.
  try {
    QuadratureDecoder decoder({.num_axes = 9, .glitch_filter_samples = 0});
    ADD_FAILURE() << "accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "num_axes");
  }
}

TEST(OptionsValidate, SynthesisOptionsNameFieldValueAndBound) {
  using O = SynthesisOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.feed = 0; }, "feed", {"feed: expected a value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.feed = std::numeric_limits<double>::infinity(); }, "feed",
                   {"expected a finite value", "got inf"});
  ExpectRefused<O>(d, [](O& o) { o.sample_rate_hz = std::numeric_limits<double>::quiet_NaN(); }, "sample_rate_hz",
                   {"sample_rate_hz: expected a finite value", "got nan"});
  ExpectRefused<O>(d, [](O& o) { o.sample_rate_hz = -8000; }, "sample_rate_hz", {"> 0", "got -8000"});
  ExpectRefused<O>(d, [](O& o) { o.dwell = -1; }, "dwell", {"dwell: expected a value >= 0", "got -1"});
}

}  // namespace
}  // namespace robomach::machine
