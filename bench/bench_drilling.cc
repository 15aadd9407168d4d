// Speed targets of issue 12: a 2 s simulation at 1 kHz control under 0.5 s;
// --tune for both controllers (pid, pd-tdc) under 30 s. Default scenario of
// config/drilling/.
#include <benchmark/benchmark.h>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>

#include "robomach/common/units.h"

#include "robomach/drilling/drilling_sim.h"
#include "robomach/io/drilling_files.h"

namespace {

using namespace robomach;

struct Setup {
  io::FlexibleRobotFile robot_file = io::ReadFlexibleRobotFile(
      std::string(ROBOMACH_SOURCE_DIR) + "/config/drilling/planar3r.yaml");
  io::DrillFile drill =
      io::ReadDrillFile(std::string(ROBOMACH_SOURCE_DIR) + "/config/drilling/drill_5mm.yaml");
  drilling::DrillingMaterial material =
      io::ReadMaterialFile(std::string(ROBOMACH_SOURCE_DIR) + "/config/drilling/q235.yaml");
  drilling::FlexibleJointRobot robot{robot_file.chain, robot_file.drives};
  drilling::DrillingScenario scenario{&robot, drill.drill, material, drill.process};
  drilling::SimOptions options;
  Setup() { options.motor_torque_limit = Eigen::VectorXd::Constant(robot.num_joints(), 10.0); }
};

void BM_Simulate2sAt1kHz(benchmark::State& state) {
  Setup s;
  const std::string kind = state.range(0) == 0 ? "pid" : "pd-tdc";
  for (auto _ : state) {
    auto ctl = drilling::MakeController(drilling::DefaultParameters(kind), s.scenario,
                                        s.options.motor_torque_limit);
    const drilling::SimResult r = s.scenario.Run(*ctl, s.options);
    benchmark::DoNotOptimize(r.cost);
  }
  state.SetLabel(kind);
}
BENCHMARK(BM_Simulate2sAt1kHz)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The integrator's inner loop: one Derivative() (M(q) and C q' + G by the
// robot's own composite-rigid-body / Newton-Euler pass, an LLT solve)
// against KDL's two solvers for the same terms (ChainDynParam::JntToMass
// and ChainIdSolver_RNE with q'' = 0), which Derivative() used before.
drilling::FlexibleJointState BenchState(const drilling::FlexibleJointRobot& robot) {
  const int n = robot.num_joints();
  drilling::FlexibleJointState x;
  x.q = Eigen::VectorXd::LinSpaced(n, -1.2, 1.1);
  x.qd = Eigen::VectorXd::LinSpaced(n, 0.4, -0.3);
  x.theta = robot.gear_ratio().cwiseProduct(x.q + Eigen::VectorXd::Constant(n, 1e-4));
  x.thetad = robot.gear_ratio().cwiseProduct(x.qd);
  return x;
}

void BM_Derivative(benchmark::State& state) {
  Setup s;
  const drilling::FlexibleJointState x = BenchState(s.robot);
  const Eigen::VectorXd tau = Eigen::VectorXd::Constant(s.robot.num_joints(), 0.5);
  drilling::FlexibleJointState dx;
  s.robot.Derivative(x, tau, tau, &dx);
  for (auto _ : state) {
    s.robot.Derivative(x, tau, tau, &dx);
    benchmark::DoNotOptimize(dx.qd.data());
  }
}
BENCHMARK(BM_Derivative)->Unit(benchmark::kMicrosecond);

void BM_KdlMassMatrixAndRne(benchmark::State& state) {
  Setup s;
  const drilling::FlexibleJointState x = BenchState(s.robot);
  const KDL::Chain& chain = s.robot.chain().kdl();
  const KDL::Vector g(0.0, 0.0, -kStandardGravity);
  KDL::ChainDynParam dyn(chain, g);
  KDL::ChainIdSolver_RNE rne(chain, g);
  const unsigned n = chain.getNrOfJoints();
  KDL::JntArray q(n), qd(n), qdd(n), h(n);
  KDL::JntSpaceInertiaMatrix M(n);
  KDL::Wrenches no_wrench(chain.getNrOfSegments(), KDL::Wrench::Zero());
  q.data = x.q;
  qd.data = x.qd;
  for (auto _ : state) {
    dyn.JntToMass(q, M);
    rne.CartToJnt(q, qd, qdd, no_wrench, h);
    benchmark::DoNotOptimize(h.data.data());
    benchmark::DoNotOptimize(M.data.data());
  }
}
BENCHMARK(BM_KdlMassMatrixAndRne)->Unit(benchmark::kMicrosecond);

void BM_TuneBoth(benchmark::State& state) {
  Setup s;
  for (auto _ : state) {
    for (const char* kind : {"pid", "pd-tdc"}) {
      const drilling::TuneResult t = drilling::TuneController(drilling::DefaultParameters(kind), s.scenario, s.options, 30);
      benchmark::DoNotOptimize(t.cost);
    }
  }
}
BENCHMARK(BM_TuneBoth)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
