// Issue #36, one vocabulary: every options struct of common has a Validate()
// that passes its defaults and refuses a bad value of each checked field
// with an OptionError naming the field, its value and the bound; and the
// one-sided and nested checks of common/option_validate.h word their
// messages as CheckOptionRange does.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "options_validate_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/parallel.h"

namespace robomach {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) { EXPECT_NO_THROW(ParallelForOptions{}.Validate()); }

TEST(OptionsValidate, ParallelForOptionsNameFieldValueAndBound) {
  using O = ParallelForOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.threads = -1; }, "threads", {"threads: expected >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.chunk_size = -2; }, "chunk_size", {"chunk_size: expected >= 0", "got -2"});
  // ParallelFor refuses them with its name in front, the field unchanged.
  O bad;
  bad.threads = -1;
  try {
    ParallelFor(0, 3, [](long, int) {}, bad);
    ADD_FAILURE() << "threads -1 accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "threads");
    EXPECT_THAT(e.what(), HasSubstr("ParallelFor: threads: expected >= 0 (0 = all cores), got -1"));
  }
}

// A struct holding another (CalibrationOptions::modal_fit): the inner
// struct's field is named with the outer field in front.
struct InnerOptions {
  double tol{1.0};
  void Validate() const { CheckOptionAbove("tol", tol, 0.0); }
};

TEST(OptionValidate, ChecksWordTheirMessagesAsCheckOptionRange) {
  const auto what = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const OptionError& e) {
      return e.field() + " | " + e.what();
    }
    return "";
  };
  EXPECT_EQ(what([] { CheckOptionAbove("tol", 0.0, 0.0); }), "tol | tol: expected a value > 0, got 0");
  EXPECT_EQ(what([] { CheckOptionAbove("fmax_hz", std::numeric_limits<double>::infinity(), 0.0); }), "");
  EXPECT_EQ(what([] { CheckOptionAtLeast("count", 0, 1); }), "count | count: expected a value >= 1, got 0");
  EXPECT_EQ(what([] { CheckOptionAtLeast("x", std::nan(""), 0); }), "x | x: expected a value >= 0, got nan");
  EXPECT_EQ(what([] { CheckOptionFinite("x", -std::numeric_limits<double>::infinity()); }),
            "x | x: expected a finite value, got -inf");
  EXPECT_EQ(what([] { CheckOptionFinite("x", 3.0); }), "");
  EXPECT_EQ(what([] { CheckOptionBand("fmin_hz", -1, "fmax_hz", 10); }),
            "fmin_hz | fmin_hz: expected a value >= 0, got -1");
  EXPECT_EQ(what([] { CheckOptionBand("fmin_hz", 20, "fmax_hz", 10); }),
            "fmax_hz | fmax_hz: expected a value > fmin_hz 20, got 10");
  EXPECT_EQ(what([] { CheckOptionBand("fmin_hz", 0, "fmax_hz", std::numeric_limits<double>::infinity()); }), "");
  InnerOptions inner;
  inner.tol = -1;
  EXPECT_EQ(what([&] { ValidateNested("fit", inner); }), "fit.tol | fit.tol: expected a value > 0, got -1");
}

}  // namespace
}  // namespace robomach
