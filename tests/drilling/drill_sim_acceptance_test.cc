// Issue 12 acceptance on the control side: on the default scenario and on
// a second robot, PD-TDC tuned with the same cost as PID settles sooner than
// PID, and its error over the last 10 % of the run stays below 0.01 deg.
// Tuning takes ~20 s of CPU per robot, too long for a unit test, so the
// tuned gains are recorded here: the defaults (DefaultParameters) come from
// drill-sim --tune on the default scenario, and those of the second robot
// from
//   drill-sim --robot config/drilling/planar3r_large.yaml
//             --drill config/drilling/drill_5mm.yaml
//             --material config/drilling/q235.yaml --controller pid,pd-tdc --tune
// (30 simulations each; rounded to 3 digits).
#include <cmath>

#include <gtest/gtest.h>

#include "robomach/drilling/drilling_sim.h"
#include "robomach/io/drilling_files.h"
#include "test_support.h"

namespace robomach::drilling {
namespace {

using robomach::testing::SourcePath;

struct Outcome {
  SimResult pid, tdc;
};

Outcome RunBoth(const std::string& robot_yaml, const ControllerParameters& pid_p,
                const ControllerParameters& tdc_p) {
  const io::FlexibleRobotFile rf = io::ReadFlexibleRobotFile(SourcePath(robot_yaml));
  const io::DrillFile df = io::ReadDrillFile(SourcePath("config/drilling/drill_5mm.yaml"));
  const DrillingMaterial m = io::ReadMaterialFile(SourcePath("config/drilling/q235.yaml"));
  FlexibleJointRobot robot(rf.chain, rf.drives);
  DrillingScenario sc(&robot, df.drill, m, df.process);
  SimOptions o;
  o.motor_torque_limit = Eigen::VectorXd::Constant(robot.num_joints(), 10.0);
  Outcome out;
  auto pid = MakeController(pid_p, sc, o.motor_torque_limit);
  out.pid = sc.Run(*pid, o);
  auto tdc = MakeController(tdc_p, sc, o.motor_torque_limit);
  out.tdc = sc.Run(*tdc, o);
  return out;
}

void Check(const Outcome& r, const std::string& what) {
  ASSERT_FALSE(r.pid.diverged) << what;
  ASSERT_FALSE(r.tdc.diverged) << what;
  ASSERT_FALSE(std::isnan(r.tdc.settling_time)) << what << ": PD-TDC never settles";
  // PID either never settles (NaN) or later than PD-TDC.
  if (!std::isnan(r.pid.settling_time)) EXPECT_LT(r.tdc.settling_time, r.pid.settling_time) << what;
  EXPECT_LT(RadToDeg(r.tdc.max_abs_error_last_10pc.maxCoeff()), 0.01) << what;
  std::printf("%s: settling pid %.3f s, pd-tdc %.3f s; max |e| pid %.4f deg, pd-tdc %.4f deg; "
              "last 10 %% pd-tdc %.2e deg\n",
              what.c_str(), r.pid.settling_time, r.tdc.settling_time,
              RadToDeg(r.pid.max_abs_error.maxCoeff()), RadToDeg(r.tdc.max_abs_error.maxCoeff()),
              RadToDeg(r.tdc.max_abs_error_last_10pc.maxCoeff()));
}

TEST(DrillSimAcceptance, DefaultScenarioPdTdcSettlesSoonerThanPid) {
  Check(RunBoth("config/drilling/planar3r.yaml", DefaultParameters("pid"), DefaultParameters("pd-tdc")),
        "seed robot");
}

TEST(DrillSimAcceptance, SecondRobotPdTdcSettlesSoonerThanPid) {
  Check(RunBoth("config/drilling/planar3r_large.yaml", {"pid", 48.3, 0.947, 2.11, 0.005},
                {"pd-tdc", 28.2, 0.2, 0.249, 0.005}),
        "large robot");
}

}  // namespace
}  // namespace robomach::drilling
