// Issue #36, one vocabulary: every options struct of stability has a
// Validate() that passes its defaults and refuses a bad value of each
// checked field with an OptionError naming the field, its value and the
// bound; a nested struct's field is named as the outer struct holds it
// ("sd.max_depth").
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
#include "robomach/stability/lobes_workflow.h"
#include "robomach/stability/measured_tip_model.h"
#include "robomach/stability/mode_coupling.h"
#include "robomach/stability/posture_stability.h"
#include "robomach/stability/semi_discretization.h"
#include "robomach/stability/stability_map.h"
#include "robomach/stability/tip_dynamics.h"
#include "robomach/stability/zoa_lobes.h"

namespace robomach::stability {
namespace {

using ::testing::HasSubstr;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using robomach::testing::ExpectRefused;

// The posture analysis has no default speed (the caller gives the cut's):
// the smallest valid options have one.
PostureStabilityOptions OneSpeed() {
  PostureStabilityOptions o;
  o.spindle_speed_rad_s = Eigen::VectorXd::Constant(1, 1000.0);
  return o;
}

MapOptions MapWithOneSpeed() {
  MapOptions o;
  o.analysis = OneSpeed();
  return o;
}

TEST(OptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(ZoaOptions{}.Validate());
  EXPECT_NO_THROW(ModeCouplingOptions{}.Validate());
  EXPECT_NO_THROW(SdOptions{}.Validate());
  EXPECT_NO_THROW(MeasuredTipOptions{}.Validate());
  EXPECT_NO_THROW(LobesOptions{}.Validate());
  EXPECT_NO_THROW(DirectFrfFitOptions{}.Validate());
  // Not valid by default (no speed): with one speed, and the rest default.
  EXPECT_THROW(PostureStabilityOptions{}.Validate(), OptionError);
  EXPECT_NO_THROW(OneSpeed().Validate());
  EXPECT_NO_THROW(MapWithOneSpeed().Validate());
  MapOptions optimised = MapWithOneSpeed();
  optimised.optimise_rotation = true;  // the default interval [-pi/2, pi/2], 20 evaluations
  EXPECT_NO_THROW(optimised.Validate());
}

TEST(OptionsValidate, ZoaOptionsNameFieldValueAndBound) {
  using O = ZoaOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.max_lobe_index = -1; }, "max_lobe_index",
                   {"max_lobe_index: expected a value >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.min_spindle_speed_rad_s = -5; }, "min_spindle_speed_rad_s",
                   {"min_spindle_speed_rad_s: expected a value >= 0", "got -5"});
  ExpectRefused<O>(d, [](O& o) { o.min_spindle_speed_rad_s = kNaN; }, "min_spindle_speed_rad_s", {">= 0", "got nan"});
}

TEST(OptionsValidate, ModeCouplingOptionsNameFieldValueAndBound) {
  using O = ModeCouplingOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.max_depth = 0; }, "max_depth", {"max_depth: expected a value > 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_depth = kInf; }, "max_depth", {"expected a finite value", "got inf"});
  ExpectRefused<O>(d, [](O& o) { o.scan_points = 0; }, "scan_points", {"scan_points: expected a value >= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.depth_tolerance = -1e-4; }, "depth_tolerance",
                   {"depth_tolerance: expected a value > 0", "got -0.0001"});
}

TEST(OptionsValidate, SdOptionsNameFieldValueAndBound) {
  using O = SdOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.steps_per_period = -1; }, "steps_per_period", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.steps_per_mode_period = 0; }, "steps_per_mode_period", {"> 0", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.min_steps_per_period = 0; }, "min_steps_per_period", {">= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_monodromy_dimension = 0; }, "max_monodromy_dimension", {">= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.max_depth = -0.01; }, "max_depth", {"max_depth: expected a value > 0", "got -0.01"});
  ExpectRefused<O>(d, [](O& o) { o.depth_scan_points = 0; }, "depth_scan_points", {">= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.depth_tolerance = 0; }, "depth_tolerance", {"> 0", "got 0"});
}

TEST(OptionsValidate, PostureStabilityOptionsNameFieldValueAndBound) {
  using O = PostureStabilityOptions;
  const O d = OneSpeed();
  ExpectRefused<O>(d, [](O& o) { o.spindle_speed_rad_s.resize(0); }, "spindle_speed_rad_s",
                   {"at least one spindle speed", "got none"});
  ExpectRefused<O>(d, [](O& o) { o.spindle_speed_rad_s = Eigen::Vector2d(1000.0, -1.0); }, "spindle_speed_rad_s",
                   {"spindle_speed_rad_s: expected a value > 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.freq_lines = 1; }, "freq_lines", {"freq_lines: expected a value >= 2", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.zoa.max_lobe_index = -1; }, "zoa.max_lobe_index",
                   {"zoa.max_lobe_index: expected a value >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.mode_coupling.scan_points = 0; }, "mode_coupling.scan_points",
                   {"mode_coupling.scan_points: expected a value >= 1", "got 0"});
}

TEST(OptionsValidate, MapOptionsNameFieldValueAndBound) {
  using O = MapOptions;
  const O d = MapWithOneSpeed();
  ExpectRefused<O>(d, [](O& o) { o.rotation = kNaN; }, "rotation", {"expected a finite value", "got nan"});
  ExpectRefused<O>(d, [](O& o) {
    o.optimise_rotation = true;
    o.rotation_min = o.rotation_max = 0.25;
  }, "rotation_max", {"rotation_max: expected a value > rotation_min 0.25", "got 0.25"});
  ExpectRefused<O>(d, [](O& o) {
    o.optimise_rotation = true;
    o.rotation_evaluations = 7;
  }, "rotation_evaluations", {"rotation_evaluations: expected a value >= 8", "got 7"});
  ExpectRefused<O>(d, [](O& o) { o.threads = -1; }, "threads", {"threads: expected a value >= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.analysis.freq_lines = 1; }, "analysis.freq_lines",
                   {"analysis.freq_lines: expected a value >= 2", "got 1"});
  ExpectRefused<O>(d, [](O& o) { o.analysis.zoa.max_lobe_index = -2; }, "analysis.zoa.max_lobe_index",
                   {"analysis.zoa.max_lobe_index: expected a value >= 0", "got -2"});
}

TEST(OptionsValidate, MeasuredTipOptionsNameFieldValueAndBound) {
  using O = MeasuredTipOptions;
  ExpectRefused<O>(O{}, [](O& o) { o.sd_modes = 0; }, "sd_modes", {"sd_modes: expected a value >= 1", "got 0"});
}

TEST(OptionsValidate, LobesOptionsNameFieldValueAndBound) {
  using O = LobesOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.min_speed_rad_s = -1; }, "min_speed_rad_s", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) {
    o.min_speed_rad_s = 100;
    o.max_speed_rad_s = 50;
  }, "max_speed_rad_s", {"max_speed_rad_s: expected a value >= 100", "got 50"});
  ExpectRefused<O>(d, [](O& o) {
    o.method = LobeMethod::kSd;
    o.sd_speeds_rad_s = Eigen::Vector2d(100.0, 0.0);
  }, "sd_speeds_rad_s", {"sd_speeds_rad_s: expected a value > 0", "got 0"});
  O zoa_only = d;  // the SD's speeds are not used by the ZOA alone
  zoa_only.sd_speeds_rad_s = Eigen::Vector2d(100.0, 0.0);
  EXPECT_NO_THROW(zoa_only.Validate());
  ExpectRefused<O>(d, [](O& o) { o.max_lobe_index = -1; }, "max_lobe_index", {">= 0", "got -1"});
  ExpectRefused<O>(d, [](O& o) { o.sd_modes = 0; }, "sd_modes", {">= 1", "got 0"});
  ExpectRefused<O>(d, [](O& o) { o.threads = -2; }, "threads", {">= 0", "got -2"});
  ExpectRefused<O>(d, [](O& o) { o.sd.max_depth = 0; }, "sd.max_depth", {"sd.max_depth: expected a value > 0", "got 0"});
}

TEST(OptionsValidate, DirectFrfFitOptionsNameFieldValueAndBound) {
  using O = DirectFrfFitOptions;
  const O d;
  ExpectRefused<O>(d, [](O& o) { o.max_active_fraction = 1.5; }, "max_active_fraction",
                   {"max_active_fraction: expected a value in [0, 1]", "got 1.5"});
  ExpectRefused<O>(d, [](O& o) { o.max_noise_rms = 0.5; }, "max_noise_rms",
                   {"max_noise_rms: expected a value >= 1", "got 0.5"});
  ExpectRefused<O>(d, [](O& o) { o.max_noise_rms = kInf; }, "max_noise_rms", {"finite", "got inf"});
  // The nested fits' fields, as this struct holds them.
  ExpectRefused<O>(d, [](O& o) { o.fit.min_order = 0; }, "fit.min_order", {"fit.min_order", ">= 1", "got 0"});
}

// The functions that take the options check them first.
TEST(OptionsValidate, TheFunctionsTakingTheOptionsRefuseThem) {
  MillingProcess p;
  p.teeth = 2;
  p.radial_immersion = 0.5;
  p.coefficients.Kt = 6e8;
  p.coefficients.Kr = 2e8;
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(10, 100.0, 1000.0);
  const std::vector<Eigen::Matrix2cd> Phi(10, Eigen::Matrix2cd::Identity() * std::complex<double>(0, -1e-7));
  ZoaOptions zo;
  zo.max_lobe_index = -1;
  try {
    ComputeZoaLobes(f, Phi, p, zo);
    ADD_FAILURE() << "accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "max_lobe_index");
  }
  TipModalModel modes;
  modes.omega_rad_s = Eigen::VectorXd::Constant(1, 2.0 * 3.141592653589793 * 500.0);
  modes.zeta = Eigen::VectorXd::Constant(1, 0.02);
  modes.p = Eigen::MatrixXd::Constant(3, 1, 0.1);
  ModeCouplingOptions mc;
  mc.scan_points = 0;
  EXPECT_THROW(CriticalDepthModeCouplingModal(modes, Eigen::Matrix3d::Identity() * 1e8, mc), OptionError);
  SdOptions sd;
  sd.depth_tolerance = 0;
  EXPECT_THROW(SdLobes(modes, p, Eigen::VectorXd::Constant(1, 1000.0), sd), OptionError);
}

}  // namespace
}  // namespace robomach::stability
