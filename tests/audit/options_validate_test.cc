// Issue #36, one vocabulary: every options struct of audit has a Validate()
// that passes its defaults and refuses a bad value of each checked field
// with an OptionError naming the field, its value and the bound.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "robomach/audit/error_patterns.h"
#include "robomach/audit/model_audit.h"
#include "options_validate_support.h"
#include "robomach/common/errors.h"

namespace robomach::audit {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(AuditOptions{}.Validate());
  EXPECT_NO_THROW(ErrorPatternOptions{}.Validate());
}

// The messages write doubles as std::to_string does ("1.000000").
TEST(OptionsValidate, AuditOptionsNameFieldValueAndBound) {
  using O = AuditOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.calibration_parameters.clear(); }, "calibration_parameters",
                   {"calibration_parameters is empty", "at least one"});
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = -1; }, "fmin_hz", {"0 <= fmin_hz < fmax_hz", "fmin_hz = -1.0"});
  ExpectRefused<O>(d, [](O& o) { o.fmax_hz = 0; }, "fmax_hz", {"0 <= fmin_hz < fmax_hz", "fmax_hz = 0.0"});
  ExpectRefused<O>(d, [](O& o) { o.num_bands = 0; }, "num_bands", {"num_bands must be >= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.significance_factor = 1; }, "significance_factor",
                   {"significance_factor must be > 1", "got 1.0"});
  ExpectRefused<O>(d, [](O& o) { o.explained_factor = 0.5; }, "explained_factor",
                   {"explained_factor must be > 1", "got 0.5"});
  ExpectRefused<O>(d, [](O& o) { o.mostly_explained_fraction = 1.5; }, "mostly_explained_fraction",
                   {"in (0, 1]", "got 1.5"});
  ExpectRefused<O>(d, [](O& o) { o.clear_bic_gap = -1; }, "clear_bic_gap", {"must be >= 0", "got -1.0"});
  ExpectRefused<O>(d, [](O& o) { o.max_iterations = 0; }, "max_iterations", {"must be >= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.fit_line_stride = -1; }, "fit_line_stride", {"must be >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.identifiable_chi2 = -1; }, "identifiable_chi2",
                   {"finite and >= 0", "got -1.0"});
  ExpectRefused<O>(d, [](O& o) { o.parameter_pairs_from = -1; }, "parameter_pairs_from",
                   {"must be >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.virtual_joints_fitted = -1; }, "virtual_joints_fitted",
                   {"must be >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.threads = 0; }, "threads", {"threads must be >= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.robust_scale = -1; }, "robust_scale", {"must be >= 0", "got -1.0"});
  ExpectRefused<O>(d, [](O& o) { o.uncertainty_confidence = 1; }, "uncertainty_confidence",
                   {"in (0, 1)", "got 1.0"});
  // dynamics::CheckValid's std::invalid_argument, as an OptionError with its text.
  ExpectRefused<O>(d, [](O& o) {
    o.parameter_uncertainty.parameters = {{"m6_kg", std::numeric_limits<double>::infinity()}};
    o.parameter_uncertainty.covariance = Eigen::MatrixXd::Identity(1, 1);
  }, "parameter_uncertainty", {"parameter uncertainty: m6_kg has the non-finite value inf"});
  ExpectRefused<O>(d, [](O& o) {
    o.parameter_uncertainty.parameters = {{"m6_kg", 20.0}, {"m6_kg", 21.0}};
    o.parameter_uncertainty.covariance = Eigen::MatrixXd::Identity(2, 2);
  }, "parameter_uncertainty", {"parameter uncertainty: parameter 'm6_kg' given twice"});
}

TEST(OptionsValidate, ErrorPatternOptionsNameFieldValueAndBound) {
  using O = ErrorPatternOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = -1; }, "fmin_hz", {"0 <= fmin_hz < fmax_hz", "fmin_hz = -1.0"});
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = 5; o.fmax_hz = 5; }, "fmax_hz",
                   {"0 <= fmin_hz < fmax_hz", "fmax_hz = 5.0"});
  ExpectRefused<O>(d, [](O& o) { o.matching.min_relative_visibility = 0; }, "matching.min_relative_visibility",
                   {"matching.min_relative_visibility: expected a value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.matching.min_relative_visibility = 2; }, "matching.min_relative_visibility",
                   {"matching.min_relative_visibility: expected a value in [0, 1]", "got 2"});
  ExpectRefused<O>(d, [](O& o) { o.matching.max_log_freq_ratio = 0; }, "matching.max_log_freq_ratio",
                   {"matching.max_log_freq_ratio: expected a value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.matching.direction_weight = -1; }, "matching.direction_weight",
                   {"matching.direction_weight: expected a value >= 0", "got -1"});
  // MatchOptions::Validate's own checks: an infinite weight is refused too.
  ExpectRefused<O>(d, [](O& o) { o.matching.direction_weight = std::numeric_limits<double>::infinity(); },
                   "matching.direction_weight", {"matching.direction_weight: expected a finite value", "got inf"});
  ExpectRefused<O>(d, [](O& o) { o.significance_factor = 0.5; }, "significance_factor",
                   {"significance_factor must be >= 1", "got 0.5"});
  ExpectRefused<O>(d, [](O& o) { o.significance_level = 0; }, "significance_level", {"in (0, 1)", "got 0.0"});
}

}  // namespace
}  // namespace robomach::audit
