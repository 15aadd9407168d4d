// Issue #36: the validators of the drilling options structs. The defaults
// pass; a bad value of each checked field throws OptionError whose field()
// is the field and whose what() names the value and the bound.
#include <cmath>
#include <functional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "options_validate_support.h"
#include "robomach/common/errors.h"
#include "robomach/drilling/controller_runs.h"
#include "robomach/drilling/drill_forces.h"
#include "robomach/drilling/drilling_sim.h"
#include "robomach/drilling/force_fit.h"

namespace robomach::drilling {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectOptionError;

TEST(DrillingOptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(ForceModelOptions{}.Validate());
  EXPECT_NO_THROW(ForceFitOptions{}.Validate());
  EXPECT_NO_THROW(SimOptions{}.Validate());
  EXPECT_NO_THROW(ControllerRunOptions{}.Validate());
  ControllerRunOptions o;
  o.kinds = {"pid", "pd", "pd-tdc"};
  o.tune = true;
  o.motor_torque_limit = Eigen::VectorXd::Constant(3, 10.0);
  EXPECT_NO_THROW(o.Validate());
}

TEST(DrillingOptionsValidate, ForceModelOptionsNameTheField) {
  ForceModelOptions o;
  o.num_elements = 0;
  ExpectOptionError([&] { o.Validate(); }, "num_elements", "num_elements: expected a value >= 1, got 0");
  // The force model checks them at its entry.
  ExpectOptionError([&] { ComputeDrillForces(DrillGeometry{}, DrillingMaterial{}, DrillState{}, o); },
                    "num_elements", "got 0");
}

TEST(DrillingOptionsValidate, ForceFitOptionsNameTheField) {
  ForceFitOptions o;
  o.max_iterations = 0;
  ExpectOptionError([&] { o.Validate(); }, "max_iterations", "max_iterations: expected a value >= 1, got 0");
  o = {};
  o.model.num_elements = -3;
  ExpectOptionError([&] { o.Validate(); }, "model.num_elements", "model.num_elements: expected a value >= 1, got -3");
}

TEST(DrillingOptionsValidate, SimOptionsNameTheField) {
  SimOptions o;
  o.max_omega_h = 0.0;
  ExpectOptionError([&] { o.Validate(); }, "max_omega_h", "max_omega_h: expected a value > 0, got 0");
  o.max_omega_h = 3.0;  // beyond RK4's stability on an undamped mode
  ExpectOptionError([&] { o.Validate(); }, "max_omega_h", "max_omega_h: expected a value in [0, 2.8], got 3");
  o.max_omega_h = NAN;
  ExpectOptionError([&] { o.Validate(); }, "max_omega_h", "got nan");
  o = {};
  o.motor_torque_limit = Eigen::Vector3d(10.0, -1.0, 10.0);
  ExpectOptionError([&] { o.Validate(); }, "motor_torque_limit",
                    "motor_torque_limit: expected a value >= 0, got -1");
  o.motor_torque_limit = Eigen::Vector3d(10.0, INFINITY, 10.0);
  ExpectOptionError([&] { o.Validate(); }, "motor_torque_limit", "motor_torque_limit: expected a finite value, got inf");
}

TEST(DrillingOptionsValidate, ControllerRunOptionsNameTheField) {
  ControllerRunOptions o;
  o.kinds = {"pid", "lqr"};
  ExpectOptionError([&] { o.Validate(); }, "kinds", "unknown controller kind 'lqr': expected pid, pd or pd-tdc");
  o = {};
  o.tune = true;
  o.tune_evaluations = 0;
  ExpectOptionError([&] { o.Validate(); }, "tune_evaluations",
                    "tune_evaluations: expected a value >= 1, got 0");
  o.tune = false;  // the budget is only used when tuning
  EXPECT_NO_THROW(o.Validate());
  o.motor_torque_limit = Eigen::Vector2d(5.0, -2.0);
  ExpectOptionError([&] { o.Validate(); }, "motor_torque_limit", "motor_torque_limit: expected a value >= 0, got -2");
}

}  // namespace
}  // namespace robomach::drilling
