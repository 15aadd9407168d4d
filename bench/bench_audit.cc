// Benchmark of issue #5: the full model audit of five postures with every
// library effect a candidate (target < 60 s), on the shipped demo data
// (config/demo: a hidden spindle-interface contact, 2 % noise), and the
// pieces it repeats: one whole-curve evaluation per candidate model.
#include <benchmark/benchmark.h>

#include "robomach/audit/model_audit.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"

namespace robomach::audit {
namespace {

struct Data {
  io::RobotConfig cfg;
  calibration::PostureMap postures;
  dynamics::FrfSet measured;
};

const Data& Demo() {
  static const Data d = [] {
    const std::string root = ROBOMACH_SOURCE_DIR;
    Data d{io::LoadRobotConfig(root + "/config/kr210.yaml"), {}, {}};
    for (const auto& p : io::ReadPostureFile(root + "/config/demo/postures.csv", 6)) d.postures[p.id] = p.q;
    d.measured = io::ReadFrfFile(root + "/config/demo/hammer.csv").frfs;
    return d;
  }();
  return d;
}

// What a user waits for: model-audit on the demo data, all 7 candidates,
// 2 threads (the machine's cores).
void BM_FullAudit_5Postures_AllCandidates(benchmark::State& state) {
  const Data& d = Demo();
  AuditOptions o;
  o.threads = static_cast<int>(state.range(0));
  std::string verdict;
  for (auto _ : state) {
    const AuditResult r = RunAudit(d.cfg.description, d.cfg.parameters, d.postures, d.measured, o);
    verdict = r.verdict;
    benchmark::DoNotOptimize(r.candidates.data());
  }
  state.SetLabel(verdict.substr(0, 60));
}
BENCHMARK(BM_FullAudit_5Postures_AllCandidates)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// One evaluation of every measured FRF by a candidate model: build, five
// postures (complex modes), 10 × 2000 single-entry lines.
void BM_WholeCurveErrors_PerEffect(benchmark::State& state) {
  const Data& d = Demo();
  const std::vector<std::string> effects = dynamics::EffectRegistry::Instance().Names();
  const std::string effect = effects.at(static_cast<size_t>(state.range(0)));
  const auto [desc, params] = WithEffect(d.cfg.description, d.cfg.parameters, effect);
  for (auto _ : state) {
    const ModelErrors e =
        ComputeErrors(dynamics::RobotModel::Build(desc, params), d.postures, d.measured, 0.0, 1e9, 8);
    benchmark::DoNotOptimize(e.rss);
  }
  state.SetLabel(effect);
}
BENCHMARK(BM_WholeCurveErrors_PerEffect)->DenseRange(0, 6)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace robomach::audit

BENCHMARK_MAIN();
