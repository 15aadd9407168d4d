#include "robomach/drilling/controller_runs.h"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "drilling/drilling_test_models.h"
#include "robomach/drilling/controllers.h"
#include "test_support.h"

namespace robomach::drilling {
namespace {

using ::testing::HasSubstr;
using testing::PlanarRodArm;
using testing::SeedDrives;
using testing::Q235Like;
using testing::SeedProcess;

// drill-sim's runs: every kind in order with its given gains (else the
// defaults), the same series as building the controller and running the
// scenario by hand, and the TDE condition only for pd-tdc, where it is
// ||I - M^-1 Mbar|| with Mbar = alpha diag(M_eff) (computed here from the
// definition).
TEST(RunControllers, EachKindAsGivenOrDefaultWithTheTdeConditionForPdTdc) {
  FlexibleJointRobot robot(PlanarRodArm(true), SeedDrives(5.0));
  DrillingScenario sc(&robot, DrillGeometry{}, Q235Like(), SeedProcess(0.2));
  ControllerRunOptions o;
  o.kinds = {"pid", "pd-tdc"};
  ControllerParameters pid = DefaultParameters("pid");
  pid.omega *= 0.8;
  o.given["pid"] = pid;
  o.motor_torque_limit = Eigen::VectorXd::Constant(3, 10.0);
  long ends = 0, last_done = -1;
  const std::vector<ControllerRun> runs = RunControllers(sc, o, [&](const ControllerRunProgress& p) {
    EXPECT_FALSE(p.tuning);
    ends += p.finished;
    last_done = p.done;
  });
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(ends, 2);
  EXPECT_EQ(last_done, sc.num_samples());
  EXPECT_EQ(runs[0].parameters.kind, "pid");
  EXPECT_EQ(runs[0].parameters.omega, pid.omega);
  EXPECT_EQ(runs[1].parameters.omega, DefaultParameters("pd-tdc").omega);
  EXPECT_FALSE(runs[0].tuned);
  EXPECT_TRUE(std::isnan(runs[0].tde_measure));
  EXPECT_FALSE(runs[0].tde_condition_fails());

  const Eigen::MatrixXd M = sc.effective_inertia();
  const Eigen::MatrixXd Mbar = (M.diagonal() * runs[1].parameters.third).asDiagonal();
  const double tde = (Eigen::MatrixXd::Identity(3, 3) - M.inverse() * Mbar).operatorNorm();
  EXPECT_NEAR(runs[1].tde_measure, tde, 1e-12 * tde);

  auto ctl = MakeController(pid, sc, o.motor_torque_limit);
  SimOptions so;
  so.motor_torque_limit = o.motor_torque_limit;
  const SimResult by_hand = sc.Run(*ctl, so);
  ASSERT_EQ(by_hand.series.q.cols(), runs[0].result.series.q.cols());
  EXPECT_EQ((by_hand.series.q - runs[0].result.series.q).cwiseAbs().maxCoeff(), 0.0);
}

// Every name is checked before any work, and the torque limit needs one
// value per joint.
TEST(RunControllers, RefusesAnUnknownKindAndAWrongTorqueLimit) {
  FlexibleJointRobot robot(PlanarRodArm(true), SeedDrives(5.0));
  DrillingScenario sc(&robot, DrillGeometry{}, Q235Like(), SeedProcess(0.2));
  ControllerRunOptions o;
  o.kinds = {"pid", "lqr"};
  o.motor_torque_limit = Eigen::VectorXd::Constant(3, 10.0);
  bool worked = false;
  EXPECT_THAT(robomach::testing::CaptureError([&] { RunControllers(sc, o, [&](const ControllerRunProgress&) { worked = true; }); }),
              HasSubstr("lqr"));
  EXPECT_FALSE(worked);
  o.kinds = {"pd"};
  o.motor_torque_limit = Eigen::VectorXd::Constant(2, 10.0);
  EXPECT_THAT(robomach::testing::CaptureError([&] { RunControllers(sc, o); }), HasSubstr("one motor torque limit per joint (3)"));
}

// The TDE condition fails for a NaN measure (a singular inertia) of a kind
// that uses it, and never for a kind that does not.
TEST(ControllerRun, TdeConditionFailsOnNaNOnlyForKindsThatUseIt) {
  ControllerRun r;
  r.tde_measure = NAN;
  EXPECT_FALSE(r.tde_condition_fails());
  r.uses_tde = true;
  EXPECT_TRUE(r.tde_condition_fails());
  r.tde_measure = 0.5;
  EXPECT_FALSE(r.tde_condition_fails());
  r.tde_measure = 1.0;
  EXPECT_TRUE(r.tde_condition_fails());
}

// How a tuning ended (issue #36, one SolverStatus): BOBYQA's first
// simulation is at the start (pid's defaults lie well inside the bounds),
// whose cost is computed here by hand with the tuning's substep rule; the
// tuned cost is below it (kConverged, or kNotConverged at the evaluation
// limit, as the message says) or equal to it (kNotImproved, the start
// returned). Equal to 1e-9: the optimiser's rescaling of the logarithms may
// move the start by an ulp. Every run diverging would be kFailed.
TEST(TuneController, StatusSaysHowTheTuningEndedAgainstTheStartsCost) {
  FlexibleJointRobot robot(PlanarRodArm(true), SeedDrives(5.0));
  DrillingScenario sc(&robot, DrillGeometry{}, Q235Like(), SeedProcess(0.2));
  SimOptions so;
  so.motor_torque_limit = Eigen::VectorXd::Constant(3, 10.0);
  const ControllerParameters start = DefaultParameters("pid");
  SimOptions ranking = so;
  ranking.record = false;
  ranking.max_omega_h = 0.2;
  const double start_cost = sc.Run(*MakeController(start, sc, so.motor_torque_limit), ranking).cost;
  ASSERT_LT(start_cost, 1e6);  // the start does not diverge
  for (int evaluations : {5, 40}) {
    SCOPED_TRACE(evaluations);
    const TuneResult t = TuneController(start, sc, so, evaluations);
    ASSERT_NE(t.status, SolverStatus::kFailed);
    if (t.status == SolverStatus::kNotImproved) {
      EXPECT_NEAR(t.cost, start_cost, 1e-9 * start_cost);
      continue;
    }
    EXPECT_LT(t.cost, start_cost);
    EXPECT_EQ(t.status, t.message == "converged" ? SolverStatus::kConverged : SolverStatus::kNotConverged);
    if (t.message == "max_evaluations") EXPECT_EQ(t.evaluations, evaluations);
  }
}

// --gains KIND=OMEGA,ZETA[,THIRD[,FILTER_S]]: the numbers given replace the
// kind's defaults in that order; a missing, extra, negative, zero or NaN
// value is refused (the filter time constant may be 0: no filter).
TEST(ParametersFromGains, GivenNumbersReplaceTheDefaultsInOrder) {
  const ControllerParameters d = DefaultParameters("pid");
  const ControllerParameters two = ParametersFromGains("pid", {50.0, 0.8});
  EXPECT_EQ(two.kind, "pid");
  EXPECT_EQ(two.omega, 50.0);
  EXPECT_EQ(two.zeta, 0.8);
  EXPECT_EQ(two.third, d.third);
  EXPECT_EQ(two.filter_time_constant, d.filter_time_constant);
  const ControllerParameters four = ParametersFromGains("pid", {50.0, 0.8, 3.0, 0.0});
  EXPECT_EQ(four.third, 3.0);
  EXPECT_EQ(four.filter_time_constant, 0.0);
  for (const std::vector<double>& bad : std::vector<std::vector<double>>{
           {50.0}, {50.0, 0.8, 3.0, 0.01, 1.0}, {-50.0, 0.8}, {50.0, 0.0}, {NAN, 0.8}, {50.0, 0.8, 0.0}, {50.0, 0.8, 3.0, -1.0}}) {
    EXPECT_THAT(robomach::testing::CaptureError([&] { ParametersFromGains("pid", bad); }), HasSubstr("expected 2 to 4 numbers"));
  }
  EXPECT_THAT(robomach::testing::CaptureError([&] { ParametersFromGains("lqr", {50.0, 0.8}); }), HasSubstr("lqr"));
}

TEST(ParseChiselModel, TheThreeNamesAndNothingElse) {
  EXPECT_EQ(ParseChiselModel("seed_scaling"), ChiselModel::kSeedScaling);
  EXPECT_EQ(ParseChiselModel("orthogonal"), ChiselModel::kOrthogonal);
  EXPECT_EQ(ParseChiselModel("none"), ChiselModel::kNone);
  EXPECT_THAT(robomach::testing::CaptureError([] { ParseChiselModel("Orthogonal"); }), HasSubstr("seed_scaling, orthogonal or none"));
}

}  // namespace
}  // namespace robomach::drilling
