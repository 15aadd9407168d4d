// Issue #36, one vocabulary: every options struct of calibration has a
// Validate() that passes its defaults and refuses a bad value of each
// checked field with an OptionError naming the field, its value and the
// bound (the words a tool's ValidateOptions turns into its option's).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/frf_estimate.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/global_modal_fit.h"
#include "robomach/calibration/modal_analysis.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "options_validate_support.h"
#include "robomach/common/errors.h"

namespace robomach::calibration {
namespace {

using ::testing::HasSubstr;

constexpr double kInf = std::numeric_limits<double>::infinity();

using robomach::testing::ExpectRefused;

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(VirtualHammerOptions{}.Validate());
  EXPECT_NO_THROW(FrfEstimateOptions{}.Validate());
  EXPECT_NO_THROW(NoiseOptions{}.Validate());
  EXPECT_NO_THROW(PeakPickOptions{}.Validate());
  EXPECT_NO_THROW(ModalFitOptions{}.Validate());
  EXPECT_NO_THROW(GlobalModalFitOptions{}.Validate());
  EXPECT_NO_THROW(ModalAnalysisOptions{}.Validate());
  EXPECT_NO_THROW(MatchOptions{}.Validate());
  EXPECT_NO_THROW(CalibrationOptions{}.Validate());
}

TEST(OptionsValidate, VirtualHammerOptionsNameFieldValueAndBound) {
  using O = VirtualHammerOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.sample_rate_hz = -1; }, "sample_rate_hz", {"sample_rate_hz -1", "> 0 Hz"});
  ExpectRefused<O>(d, [](O& o) { o.block_samples = 1; }, "block_samples", {"block_samples 1", "at least 2"});
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = 0; }, "fmin_hz", {"fmin_hz 0", "> 0 Hz"});
  ExpectRefused<O>(d, [](O& o) { o.fmax_hz = 0.1; }, "fmax_hz", {"fmax_hz 0.1", "above fmin_hz 0.25"});
  ExpectRefused<O>(d, [](O& o) { o.fmax_hz = 3000; }, "fmax_hz", {"fmax_hz 3000", "Nyquist frequency 2560"});
  // 5120 Hz / 2 samples = 2560 Hz lines: none between 0.25 and 500 Hz.
  ExpectRefused<O>(d, [](O& o) { o.block_samples = 2; }, "block_samples", {"block_samples 2", "leaves no line"});
  ExpectRefused<O>(d, [](O& o) { o.relative_noise = -1; }, "relative_noise", {"relative_noise -1", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.absolute_noise_m_per_N = -1; }, "absolute_noise_m_per_N",
                   {"absolute_noise_m_per_N -1", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.absolute_noise_m_per_s_per_N = -2; }, "absolute_noise_m_per_s_per_N",
                   {"absolute_noise_m_per_s_per_N -2", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.absolute_noise_m_per_s2_per_N = -3; }, "absolute_noise_m_per_s2_per_N",
                   {"absolute_noise_m_per_s2_per_N -3", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.hammer_cutoff_hz = -1; }, "hammer_cutoff_hz", {"hammer_cutoff_hz -1", ">= 0 Hz"});
  ExpectRefused<O>(d, [](O& o) { o.averages = 0; }, "averages", {"averages 0", "at least 1"});
  ExpectRefused<O>(d, [](O& o) { o.coherence = true; o.averages = 1; }, "averages", {"averages 1", "at least 2"});
  ExpectRefused<O>(d, [](O& o) { o.directions.clear(); }, "directions", {"no direction pair", "at least one"});
}

TEST(OptionsValidate, FrfEstimateOptionsNameFieldValueAndBound) {
  using O = FrfEstimateOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.force_window_s = kInf; }, "force_window_s", {"force_window_s = inf", "finite"});
  ExpectRefused<O>(d, [](O& o) { o.force_window_pre_s = -1; }, "force_window_pre_s",
                   {"force_window_pre_s = -1", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.force_window_taper_s = -1; }, "force_window_taper_s",
                   {"force_window_taper_s = -1", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.exponential_tau_s = -1; }, "exponential_tau_s",
                   {"exponential_tau_s = -1", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.fmax_hz = -1; }, "fmax_hz", {"fmax_hz = -1", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.trigger_fraction = 0; }, "trigger_fraction", {"trigger_fraction = 0", "in (0, 1)"});
  ExpectRefused<O>(d, [](O& o) { o.double_hit_fraction = 0.01; }, "double_hit_fraction",
                   {"double_hit_fraction = 0.01", "[trigger_fraction 0.05, 1)"});
  ExpectRefused<O>(d, [](O& o) { o.flat_top_samples = 1; }, "flat_top_samples", {"flat_top_samples = 1", ">= 2"});
  ExpectRefused<O>(d, [](O& o) { o.force_range_N = -1; }, "force_range_N", {"force_range_N = -1", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.response_range = {1.0, -2.0}; }, "response_range",
                   {"response_range[1] = -2", ">= 0"});
  ExpectRefused<O>(d, [](O& o) { o.leakage_fraction = 1; }, "leakage_fraction", {"leakage_fraction = 1", "in (0, 1)"});
}

TEST(OptionsValidate, NoiseOptionsNameFieldValueAndBound) {
  using O = NoiseOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.min_snr = 0; }, "min_snr", {"min_snr must be finite and > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.averages = -1; }, "averages", {"averages must be >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.knots_per_octave = 9; }, "knots_per_octave", {"in (0, 8]", "got 9"});
  ExpectRefused<O>(d, [](O& o) { o.max_gap_lines = -1; }, "max_gap_lines", {"must be >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.min_run_lines = 0; }, "min_run_lines", {"must be >= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.outlier_threshold = 2; }, "outlier_threshold", {">= 3", "got 2"});
  ExpectRefused<O>(d, [](O& o) { o.outlier_threshold_off_mains = 5; }, "outlier_threshold_off_mains",
                   {">= outlier_threshold 6", "got 5"});
  ExpectRefused<O>(d, [](O& o) { o.outlier_window_lines = 3; }, "outlier_window_lines", {"in [4, 64]", "got 3"});
  ExpectRefused<O>(d, [](O& o) { o.max_outlier_run_lines = 0; }, "max_outlier_run_lines",
                   {"must be >= 1", "got 0"});
}

TEST(OptionsValidate, PeakPickOptionsNameFieldValueAndBound) {
  using O = PeakPickOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.min_relative_height = 2; }, "min_relative_height",
                   {"min_relative_height: expected a value in [0, 1], got 2"});
  ExpectRefused<O>(d, [](O& o) { o.half_window_lines = 0; }, "half_window_lines",
                   {"half_window_lines: expected a value >= 1, got 0"});
}

TEST(OptionsValidate, ModalFitOptionsNameFieldValueAndBound) {
  using O = ModalFitOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = -1; }, "fmin_hz", {"fmin_hz: expected a value >= 0, got -1"});
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = 100; o.fmax_hz = 50; }, "fmax_hz",
                   {"fmax_hz: expected a value > fmin_hz 100, got 50"});
  ExpectRefused<O>(d, [](O& o) { o.min_order = 0; }, "min_order", {"expected a value >= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_order = 1; }, "max_order", {"expected a value >= min_order 2", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.stable_freq_tol = 0; }, "stable_freq_tol", {"expected a value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.stable_damping_tol = 0; }, "stable_damping_tol", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.min_stable_orders = 0; }, "min_stable_orders", {">= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_damping_ratio = 0; }, "max_damping_ratio", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_damping_ratio = 2; }, "max_damping_ratio", {"in [0, 1]", "got 2"});
  ExpectRefused<O>(d, [](O& o) { o.min_relative_contribution = -1; }, "min_relative_contribution",
                   {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.max_added_modes = -1; }, "max_added_modes", {">= 0", "got -1"});
}

TEST(OptionsValidate, GlobalModalFitOptionsNameFieldValueAndBound) {
  using O = GlobalModalFitOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = -1; }, "fmin_hz", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = 10; o.fmax_hz = 10; }, "fmax_hz", {"> fmin_hz 10", "got 10"});
  ExpectRefused<O>(d, [](O& o) { o.min_order = 1; }, "min_order", {">= 2", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.max_order = 5; }, "max_order", {">= min_order + 2 = 6", "got 5"});
  ExpectRefused<O>(d, [](O& o) { o.stable_freq_tol = 0; }, "stable_freq_tol", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.stable_damping_tol = -1; }, "stable_damping_tol", {"> 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.cluster_freq_tol = 0; }, "cluster_freq_tol", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.min_stable_orders = 0; }, "min_stable_orders", {">= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.min_cluster_fraction = 2; }, "min_cluster_fraction", {"[0, 1]", "got 2"});
  ExpectRefused<O>(d, [](O& o) { o.max_damping_ratio = 1.5; }, "max_damping_ratio", {"[0, 1]", "got 1.5"});
  ExpectRefused<O>(d, [](O& o) { o.min_relative_contribution = -1; }, "min_relative_contribution",
                   {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.max_added_modes = -1; }, "max_added_modes", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.uniform_weights_power = 3; }, "uniform_weights_power", {"[-1, 2]", "got 3"});
  ExpectRefused<O>(d, [](O& o) { o.dense_modes = -1; }, "dense_modes", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.max_modes_per_band = -1; }, "max_modes_per_band", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.driving_point = -2; }, "driving_point", {">= -1", "got -2"});
  ExpectRefused<O>(d, [](O& o) { o.model_error_power = -2; }, "model_error_power", {"[-1, 2]", "got -2"});
  ExpectRefused<O>(d, [](O& o) { o.model_error_ratio = 0; }, "model_error_ratio", {"> 0", "got 0"});
}

TEST(OptionsValidate, ModalAnalysisOptionsNameTheNestedField) {
  using O = ModalAnalysisOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.fit.max_order = 3; }, "fit.max_order",
                   {"fit.max_order: expected a value >= min_order + 2 = 6, got 3"});
  ExpectRefused<O>(d, [](O& o) { o.min_common_lines = -1; }, "min_common_lines", {">= 0", "got -1"});
}

TEST(OptionsValidate, MatchOptionsNameFieldValueAndBound) {
  using O = MatchOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.min_relative_visibility = 0; }, "min_relative_visibility", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.min_relative_visibility = 2; }, "min_relative_visibility",
                   {"[0, 1]", "got 2"});
  ExpectRefused<O>(d, [](O& o) { o.max_log_freq_ratio = 0; }, "max_log_freq_ratio", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.direction_weight = -1; }, "direction_weight", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.direction_weight = kInf; }, "direction_weight", {"finite", "got inf"});
}

TEST(OptionsValidate, CalibrationOptionsNameFieldValueAndBound) {
  using O = CalibrationOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.free_parameters.clear(); }, "free_parameters", {"at least one", "got none"});
  ExpectRefused<O>(d, [](O& o) { o.matching.direction_weight = -1; }, "matching.direction_weight",
                   {"matching.direction_weight: expected a value >= 0, got -1"});
  ExpectRefused<O>(d, [](O& o) { o.modal_fit.min_order = 0; }, "modal_fit.min_order",
                   {"modal_fit.min_order: expected a value >= 1, got 0"});
  ExpectRefused<O>(d, [](O& o) { o.freq_sigma = 0; }, "freq_sigma", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.peak_sigma = -1; }, "peak_sigma", {"> 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.freq_sigma = kInf; }, "freq_sigma", {"freq_sigma: expected a finite value", "got inf"});
  ExpectRefused<O>(d, [](O& o) { o.peak_sigma = kInf; }, "peak_sigma", {"peak_sigma: expected a finite value", "got inf"});
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = -1; }, "fmin_hz", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.fmax_hz = 0; }, "fmax_hz", {"> fmin_hz 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_iterations = 0; }, "max_iterations", {">= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_match_rounds = 0; }, "max_match_rounds", {">= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.weak_relative_std = 0; }, "weak_relative_std", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.robust_scale = -1; }, "robust_scale", {"must be >= 0", "got -1"});
}

}  // namespace
}  // namespace robomach::calibration
