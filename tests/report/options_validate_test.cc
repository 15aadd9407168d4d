// Issue #36, one vocabulary: every options struct of report has a
// Validate() that passes its defaults and refuses a bad value of each
// checked field with an OptionError naming the field, its value and the
// bound.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "options_validate_support.h"
#include "robomach/common/errors.h"
#include "robomach/report/audit_report.h"

namespace robomach::report {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) { EXPECT_NO_THROW(AuditReportOptions{}.Validate()); }

TEST(OptionsValidate, AuditReportOptionsNameFieldValueAndBound) {
  using O = AuditReportOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = -1; }, "fmin_hz", {"fmin_hz: expected a value >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) {
    o.fmin_hz = 100;
    o.fmax_hz = 50;
  }, "fmax_hz", {"fmax_hz: expected a value > fmin_hz 100", "got 50"});
}

}  // namespace
}  // namespace robomach::report
