// Speed of the foundation (issue #2 targets on this 2-core machine):
// one posture's evaluation (M_q, J, modes) <= 10 µs, a 2000-line modal FRF
// <= 100 µs, and a 10,000-posture batch.
#include <benchmark/benchmark.h>

#include <random>

#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/robot_config.h"

namespace {

using namespace robomach;

std::shared_ptr<const dynamics::RobotModel> Model() {
  static const auto model =
      io::LoadRobotConfig(std::string(ROBOMACH_SOURCE_DIR) + "/config/kr210.yaml").Build();
  return model;
}

Eigen::VectorXd P1() {
  Eigen::VectorXd q(6);
  q << 0.0, -1.5707963, 1.5707963, 0.0, 0.7853982, 0.0;
  return q;
}

void BM_EvaluatePosture_MqJModes(benchmark::State& state) {
  dynamics::PostureEvaluator ev(Model());
  const dynamics::PostureOptions opts{.cartesian = false, .modes = true};
  const Eigen::VectorXd q = P1();
  for (auto _ : state) benchmark::DoNotOptimize(ev.Evaluate(q, opts));
}
BENCHMARK(BM_EvaluatePosture_MqJModes);

void BM_EvaluatePosture_Everything(benchmark::State& state) {
  dynamics::PostureEvaluator ev(Model());
  const Eigen::VectorXd q = P1();
  for (auto _ : state) benchmark::DoNotOptimize(ev.Evaluate(q));
}
BENCHMARK(BM_EvaluatePosture_Everything);

void BM_ModalFrf2000Lines(benchmark::State& state) {
  const auto d = dynamics::EvaluatePosture(Model(), P1());
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0);
  for (auto _ : state) benchmark::DoNotOptimize(dynamics::ReceptanceModal(d, f));
}
BENCHMARK(BM_ModalFrf2000Lines);

void BM_DirectFrf2000Lines(benchmark::State& state) {
  const auto d = dynamics::EvaluatePosture(Model(), P1());
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0);
  for (auto _ : state) benchmark::DoNotOptimize(dynamics::ReceptanceDirect(d.system, f));
}
BENCHMARK(BM_DirectFrf2000Lines);

void BM_Batch10000Postures(benchmark::State& state) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::VectorXd> qs(10000);
  for (auto& q : qs) {
    q = P1();
    for (int j = 0; j < 6; ++j) q(j) += 0.5 * u(rng);
  }
  dynamics::PostureEvaluator ev(Model());
  for (auto _ : state) {
    for (const auto& q : qs) benchmark::DoNotOptimize(ev.Evaluate(q));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(qs.size()));
}
BENCHMARK(BM_Batch10000Postures)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
