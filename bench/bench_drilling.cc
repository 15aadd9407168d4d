// Speed targets of issue 12: a 2 s simulation at 1 kHz control under 0.5 s;
// --tune for both controllers (pid, pd-tdc) under 30 s. Default scenario of
// config/drilling/.
#include <benchmark/benchmark.h>

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
