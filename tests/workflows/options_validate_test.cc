// Issue #36, one vocabulary: every options struct of workflows has a
// Validate() that passes its defaults (or, where a default cannot be valid
// because a file is required, the smallest valid options) and refuses a bad
// value of each checked field with an OptionError naming the field, its
// value and the bound. PolishPlanOptions is in
// polish_plan_options_validate_test.cc (it links the CAD kernel).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "options_validate_support.h"
#include "robomach/common/errors.h"
#include "robomach/workflows/axis_synth.h"
#include "robomach/workflows/drilling_setup.h"
#include "robomach/workflows/frf_calibrate.h"
#include "robomach/workflows/frf_estimate.h"
#include "robomach/workflows/frf_predict.h"
#include "robomach/workflows/frf_synth.h"
#include "robomach/workflows/kq_identify.h"
#include "robomach/workflows/measured_frfs.h"
#include "robomach/workflows/model_audit.h"
#include "robomach/workflows/stability_lobes.h"
#include "robomach/workflows/stability_map.h"
#include "robomach/workflows/tracker_synth.h"

namespace robomach::workflows {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectRefused;

// The smallest valid options of the workflows that need files (the paths
// are only checked for being given here; the runs read them).
FrfCalibrateOptions Calibrate() {
  FrfCalibrateOptions o;
  o.robot_path = "robot.yaml";
  o.postures_path = "postures.csv";
  o.measured_files = {"measured.csv"};
  return o;
}

FrfEstimateRunOptions Estimate() {
  FrfEstimateRunOptions o;
  o.record_paths = {"hits.csv"};
  return o;
}

FrfPredictOptions Predict() {
  FrfPredictOptions o;
  o.robot_path = "robot.yaml";
  o.postures_path = "postures.csv";
  o.freq_hz = Eigen::VectorXd::LinSpaced(3, 10.0, 30.0);
  return o;
}

KqIdentifyOptions Identify() {
  KqIdentifyOptions o;
  o.robot_path = "robot.yaml";
  o.tracker_path = "tracker.csv";
  return o;
}

KqPlanOptions Plan() {
  KqPlanOptions o;
  o.robot_path = "robot.yaml";
  return o;
}

ModelAuditOptions Audit() {
  ModelAuditOptions o;
  o.robot_path = "robot.yaml";
  o.postures_path = "postures.csv";
  o.measured_files = {"measured.csv"};
  return o;
}

StabilityLobesOptions Lobes() {
  StabilityLobesOptions o;
  o.cut_path = "cut.yaml";
  o.frf_path = "tip.csv";
  return o;
}

StabilityMapOptions Map() {
  StabilityMapOptions o;
  o.region_path = "region.yaml";
  return o;
}

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(AxisSynthOptions{}.Validate());
  EXPECT_NO_THROW(DrillSimOptions{}.Validate());
  EXPECT_NO_THROW(FrfNoiseOptions{}.Validate());
  EXPECT_NO_THROW(FrfSynthOptions{}.Validate());
  EXPECT_NO_THROW(MeasuredFrfOptions{}.Validate());
  EXPECT_NO_THROW(TrackerSynthOptions{}.Validate());
  // A required file has no default: the smallest valid options, and the
  // defaults refused naming the missing file.
  EXPECT_NO_THROW(Calibrate().Validate());
  EXPECT_NO_THROW(Estimate().Validate());
  EXPECT_NO_THROW(Predict().Validate());
  EXPECT_NO_THROW(Identify().Validate());
  EXPECT_NO_THROW(Plan().Validate());
  EXPECT_NO_THROW(Audit().Validate());
  EXPECT_NO_THROW(Lobes().Validate());
  EXPECT_NO_THROW(Map().Validate());
  ExpectRefused<FrfCalibrateOptions>({}, [](auto&) {}, "robot_path", {"robot_path"});
  ExpectRefused<FrfEstimateRunOptions>({}, [](auto&) {}, "record_paths", {"record_paths"});
  ExpectRefused<FrfPredictOptions>({}, [](auto&) {}, "robot_path", {"robot_path"});
  ExpectRefused<KqIdentifyOptions>({}, [](auto&) {}, "robot_path", {"robot_path"});
  ExpectRefused<KqPlanOptions>({}, [](auto&) {}, "robot_path", {"robot_path"});
  ExpectRefused<ModelAuditOptions>({}, [](auto&) {}, "robot_path", {"robot_path"});
  ExpectRefused<StabilityLobesOptions>({}, [](auto&) {}, "robot_path", {"exactly one tool-tip source"});
  ExpectRefused<StabilityMapOptions>({}, [](auto&) {}, "region_path", {"region_path"});
}

TEST(OptionsValidate, AxisSynthOptionsNameFieldValueAndBound) {
  using O = AxisSynthOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.feed_mm_min = 0; }, "feed_mm_min",
                   {"feed_mm_min: expected a value in [0.001, 1e+06]", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.sample_rate_hz = 0.5; }, "sample_rate_hz", {"[1, 1e+08]", "got 0.5"});
  ExpectRefused<O>(d, [](O& o) { o.dwell_s = -1; }, "dwell_s", {"[0, 100000]", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.start_b_deg = 1000; }, "start_b_deg", {"[-720, 720]", "got 1000"});
  ExpectRefused<O>(d, [](O& o) { o.glitch_probability = 2; }, "glitch_probability", {"[0, 1]", "got 2"});
  ExpectRefused<O>(d, [](O& o) { o.max_rows = 1; }, "max_rows", {"[2, 1e+09]", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.capture_every = 0; }, "capture_every",
                   {"capture_every: expected a value in [1, 100000]", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.capture_settle = 10; }, "capture_settle",
                   {"capture_settle: expected a value in [0, capture_every 10)", "got 10"});
}

TEST(OptionsValidate, DrillSimOptionsNameFieldValueAndBound) {
  using O = DrillSimOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.controllers.clear(); }, "controllers", {"at least one controller"});
  ExpectRefused<O>(d, [](O& o) { o.tune_evaluations = 4; }, "tune_evaluations",
                   {"tune_evaluations 4", "[5, 1000]"});
  ExpectRefused<O>(d, [](O& o) { o.motor_torque_limit_Nm = 0; }, "motor_torque_limit_Nm",
                   {"motor_torque_limit_Nm 0", "a finite value > 0"});
}

TEST(OptionsValidate, FrfNoiseOptionsNameFieldValueAndBound) {
  using O = FrfNoiseOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.min_snr = 0; }, "min_snr", {"min_snr: expected a value in [0.001, 1e+06]", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.averages = -1; }, "averages", {"averages: expected a value in [0, 1e+06]", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.noise_model = "bogus"; }, "noise_model", {"'bogus'", "auto, coherence"});
}

TEST(OptionsValidate, FrfCalibrateOptionsNameFieldValueAndBound) {
  using O = FrfCalibrateOptions;
  const O d = Calibrate();
  ExpectRefused<O>(d, [](O& o) { o.max_iterations = 0; }, "max_iterations", {"[1, 100000]", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.robust_loss_sigma = -1; }, "robust_loss_sigma", {"[0, 1e+06]", "got -1"});
  // The band is checked here, before the files are read, naming both ends.
  ExpectRefused<O>(d, [](O& o) {
    o.fmin_hz = 600;
    o.fmax_hz = 500;
  }, "fmax_hz", {"fmax_hz: expected a value > fmin_hz 600", "got 500"});
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = -1; }, "fmin_hz", {"fmin_hz: expected a value >= 0", "got -1"});
  EXPECT_NO_THROW([] {
    O o = Calibrate();
    o.fmin_hz = 5;
    o.fmax_hz = std::numeric_limits<double>::infinity();  // all lines
    o.Validate();
  }());
  // The noise options are the tool's own (--min-snr): unprefixed.
  ExpectRefused<O>(d, [](O& o) { o.noise.min_snr = 0; }, "min_snr", {"[0.001, 1e+06]", "got 0"});
}

TEST(OptionsValidate, FrfEstimateRunOptionsNameFieldValueAndBound) {
  using O = FrfEstimateRunOptions;
  const O d = Estimate();
  ExpectRefused<O>(d, [](O& o) { o.min_hits = 0; }, "min_hits", {"min_hits 0", "[1, 1000000]"});
  ExpectRefused<O>(d, [](O& o) { o.estimator = "h3"; }, "estimator", {"h1 or h2", "'h3'"});
  ExpectRefused<O>(d, [](O& o) { o.excitation = "w"; }, "excitation", {"x, y or z", "'w'"});
}

TEST(OptionsValidate, FrfPredictOptionsNameFieldValueAndBound) {
  using O = FrfPredictOptions;
  const O d = Predict();
  ExpectRefused<O>(d, [](O& o) { o.freq_hz = Eigen::Vector2d(10.0, 5.0); }, "freq_hz",
                   {"strictly increasing", "got 5 at line 2 after 10"});
  ExpectRefused<O>(d, [](O& o) { o.freq_hz = Eigen::VectorXd::Constant(1, -1.0); }, "freq_hz", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.method = "exact"; }, "method", {"modal or direct", "'exact'"});
  // The propagation's options (dynamics::PropagationOptions::Validate).
  ExpectRefused<O>(d, [](O& o) { o.uncertainty.confidence = 95; }, "confidence", {"(0, 1)", "got 95"});
}

TEST(OptionsValidate, FrfSynthOptionsNameFieldValueAndBound) {
  using O = FrfSynthOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.hammer.block_samples = 1; }, "block_samples",
                   {"block_samples: expected a value in [2, ", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.hammer.relative_noise = 20; }, "relative_noise", {"relative_noise 20", "at most 10"});
  ExpectRefused<O>(d, [](O& o) { o.hammer.fmax_hz = -1; }, "fmax_hz", {"fmax_hz -1", "[0, 1e9] Hz"});
  ExpectRefused<O>(d, [](O& o) { o.hammer.fmin_hz = 1e30; }, "fmin_hz", {"fmin_hz 1e+30", "(0, 1e9] Hz"});
  ExpectRefused<O>(d, [](O& o) { o.hammer.fmin_hz = 600; }, "fmin_hz", {"fmin_hz 600", "below fmax_hz 500 Hz"});
  // NaN is "the config's rate"; infinity is a rate given, and refused.
  ExpectRefused<O>(d, [](O& o) { o.hammer.sample_rate_hz = INFINITY; }, "sample_rate_hz",
                   {"sample_rate_hz inf", "(0, 1e9] Hz"});
}

TEST(OptionsValidate, KqIdentifyOptionsNameFieldValueAndBound) {
  using O = KqIdentifyOptions;
  const O d = Identify();
  ExpectRefused<O>(d, [](O& o) { o.noise_mm = 0; }, "noise_mm", {"a finite noise > 0 mm", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.robust = "l1"; }, "robust", {"robust loss 'l1'", "expected none, huber or cauchy"});
}

TEST(OptionsValidate, KqPlanOptionsNameFieldValueAndBound) {
  using O = KqPlanOptions;
  const O d = Plan();
  ExpectRefused<O>(d, [](O& o) { o.num_postures = 0; }, "num_postures", {"[1, 500]", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.noise_mm = -1; }, "noise_mm", {"> 0 mm", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.masses_kg = {10.0, -1.0}; }, "masses_kg", {"masses > 0 kg", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.target_half_width = 1; }, "target_half_width", {"[0, 1)", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.max_rope_angle_deg = 0; }, "max_rope_angle_deg", {"(0, 90) deg", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_rope_angle_deg = 90; }, "max_rope_angle_deg", {"(0, 90) deg", "got 90"});
}

TEST(OptionsValidate, MeasuredFrfOptionsNameFieldValueAndBound) {
  using O = MeasuredFrfOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.min_snr = 0; }, "min_snr", {"min_snr 0", "[0.001, 1e6]"});
  ExpectRefused<O>(d, [](O& o) { o.averages = -1; }, "averages", {"averages -1", "[0, 1000000]"});
}

TEST(OptionsValidate, ModelAuditOptionsNameFieldValueAndBound) {
  using O = ModelAuditOptions;
  const O d = Audit();
  ExpectRefused<O>(d, [](O& o) { o.fmin_hz = -1; }, "fmin_hz", {"fmin_hz: expected a value in [0, 1e+09]", "got -1"});
  ExpectRefused<O>(d, [](O& o) {
    o.fmin_hz = 100;
    o.fmax_hz = 50;
  }, "fmax_hz", {"above fmin_hz (100 Hz)", "got 50"});
  ExpectRefused<O>(d, [](O& o) { o.max_iterations = 0; }, "max_iterations", {"[1, 100000]", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.virtual_joints = 51; }, "virtual_joints", {"[0, 50]", "got 51"});
  ExpectRefused<O>(d, [](O& o) { o.robust_loss_sigma = -1; }, "robust_loss_sigma", {"[0, 1e+06]", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.confidence = 1; }, "confidence", {"between 0 and 1", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.noise.averages = -1; }, "averages", {"[0, 1e+06]", "got -1"});
}

TEST(OptionsValidate, StabilityLobesOptionsNameFieldValueAndBound) {
  using O = StabilityLobesOptions;
  const O d = Lobes();
  ExpectRefused<O>(d, [](O& o) { o.speeds = -1; }, "speeds", {"speeds -1", "[0, 100000]"});
  ExpectRefused<O>(d, [](O& o) { o.max_lobe = 1001; }, "max_lobe", {"max_lobe 1001", "[0, 1000]"});
  ExpectRefused<O>(d, [](O& o) { o.sd_speeds = 0; }, "sd_speeds", {"sd_speeds 0", "[1, 10000]"});
  ExpectRefused<O>(d, [](O& o) { o.sd_steps = 1; }, "sd_steps", {"sd_steps 1", "[2, 1000]"});
  ExpectRefused<O>(d, [](O& o) { o.sd_steps_per_mode_period = 2; }, "sd_steps_per_mode_period",
                   {"sd_steps_per_mode_period 2", "[4, 1000]"});
  ExpectRefused<O>(d, [](O& o) { o.sd_modes = 0; }, "sd_modes", {"sd_modes 0", "[1, 200]"});
  ExpectRefused<O>(d, [](O& o) { o.sd_max_depth_mm = 0; }, "sd_max_depth_mm", {"sd_max_depth_mm 0", "is outside ["});
  ExpectRefused<O>(d, [](O& o) { o.threads = 300; }, "threads", {"threads 300", "[0, 256]"});
  ExpectRefused<O>(d, [](O& o) { o.tool_axis.setZero(); }, "tool_axis", {"non-zero vector"});
}

TEST(OptionsValidate, StabilityMapOptionsNameFieldValueAndBound) {
  using O = StabilityMapOptions;
  const O d = Map();
  ExpectRefused<O>(d, [](O& o) { o.max_depth_mm = 0; }, "max_depth_mm", {"max_depth_mm 0", "> 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_depth_mm = 1e30; }, "max_depth_mm", {"max_depth_mm 1e+30", "at most 10000 mm"});
  ExpectRefused<O>(d, [](O& o) { o.speeds = -1; }, "speeds", {"speeds -1", "0 to 100000"});
  ExpectRefused<O>(d, [](O& o) { o.rotation_evaluations = 7; }, "rotation_evaluations",
                   {"rotation_evaluations 7", ">= 8"});
  ExpectRefused<O>(d, [](O& o) { o.threads = 257; }, "threads", {"threads 257", "0 to 256"});
  ExpectRefused<O>(d, [](O& o) { o.uncertainty.confidence = 0; }, "confidence", {"(0, 1)", "got 0"});
  // The settings alone (Python's stability_map: no region file).
  O settings;
  EXPECT_NO_THROW(settings.ValidateSettings());
  settings.rotation_evaluations = 3;
  try {
    settings.ValidateSettings();
    ADD_FAILURE() << "rotation_evaluations 3 accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "rotation_evaluations");
    EXPECT_THAT(e.what(), HasSubstr("rotation_evaluations 3: expected >= 8"));
  }
}

TEST(OptionsValidate, TrackerSynthOptionsNameFieldValueAndBound) {
  using O = TrackerSynthOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.noise_mm = -1; }, "noise_mm", {"noise_mm: expected a value in [0, 1000]", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.outliers = -1; }, "outliers", {"outliers: expected a count >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.num_postures = 0; }, "num_postures", {"at least 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.outlier_mm = 2e4; }, "outlier_mm", {"[0, 10000]", "got 20000"});
  ExpectRefused<O>(d, [](O& o) { o.form = "chain"; }, "form", {"rope or force", "'chain'"});
}

}  // namespace
}  // namespace robomach::workflows
