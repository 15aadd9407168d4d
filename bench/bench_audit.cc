// Benchmark of issue #5: the full model audit of five postures with every
// library effect a candidate (target < 60 s), on the shipped demo data
// (config/demo: a hidden spindle-interface contact, 2 % noise), and the
// pieces it repeats: one whole-curve evaluation per candidate model.
#include <benchmark/benchmark.h>

#include <algorithm>

#include "robomach/audit/model_audit.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "audit/audit_test_support.h"
#include "realistic_hammer_test.h"
#include "robomach/io/robot_config.h"
#include "robomach/common/units.h"

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

// Issue #10's target: the full audit of 6 postures x 2 directions x 4096
// lines (accelerance of a 5120 Hz hammer test, 0.625..2560 Hz, 2 % noise
// plus an additive floor crossing the signal: the data of
// tests/audit/audit_realistic_test.cc) with every library effect a
// candidate, noise model and usable band included, 2 threads. The argument
// picks the hidden effect: 0 none, 1 a soft flange, 2 a soft foundation,
// 3 a long-reach tool (its mode makes every line up to 2.5 kHz usable: the
// most lines to fit).
void BM_FullAudit_Realistic_6x2x4096(benchmark::State& state) {
  const std::string root = ROBOMACH_SOURCE_DIR;
  const io::RobotConfig cfg = io::LoadRobotConfig(root + "/config/kr210.yaml");
  std::vector<calibration::NamedPosture> poses;
  calibration::PostureMap postures;
  for (const auto& p : io::ReadPostureFile(root + "/config/postures_demo.csv", 6)) poses.push_back({p.id, p.q});
  {
    const auto [id, deg] = robomach::testing::SixthPostureDeg();
    Eigen::VectorXd q6(6);
    for (int j = 0; j < 6; ++j) q6(j) = DegToRad(deg[j]);
    poses.push_back({id, q6});
  }
  for (const auto& p : poses) postures[p.id] = p.q;
  dynamics::RobotDescription d = cfg.description;
  dynamics::ParameterSet p = cfg.parameters;
  std::string label = "none";
  if (state.range(0) == 1) {
    std::tie(d, p) = WithEffect(d, p, "flange_compliance");
    p.Set("flange_compliance.bending_stiffness_Nm_per_rad", 1e6);
    label = "soft flange";
  } else if (state.range(0) == 2) {
    std::tie(d, p) = WithEffect(d, p, "base_compliance");
    p.Set("base_compliance.lateral_stiffness_N_per_m", 3e8);
    p.Set("base_compliance.rocking_stiffness_Nm_per_rad", 2e7);
    label = "soft foundation";
  } else if (state.range(0) == 3) {
    std::tie(d, p) = WithEffect(d, p, "tool_flexibility");
    p.Set("tool_flexibility.diameter_m", 0.012);
    p.Set("tool_flexibility.stick_out_m", 0.06);
    label = "long-reach tool";
  }
  p.Set("m6_kg", cfg.parameters.Get("m6_kg") + 3.0);
  p.Set("d6_m", cfg.parameters.Get("d6_m") + 0.015);
  const calibration::VirtualHammerOptions h = robomach::testing::RealisticHammerTest(11);
  const dynamics::FrfSet raw = calibration::SynthesizeHammerTest(dynamics::RobotModel::Build(d, p), poses, h);
  AuditOptions o;
  o.threads = 2;
  std::string verdict;
  for (auto _ : state) {
    const dynamics::FrfSet measured = calibration::UsableData(raw, calibration::EstimateNoise(raw, {}));
    const AuditResult r = RunAudit(cfg.description, cfg.parameters, postures, measured, o);
    verdict = r.verdict;
    benchmark::DoNotOptimize(r.candidates.data());
  }
  state.SetLabel(label + ": " + verdict.substr(0, 50));
}
BENCHMARK(BM_FullAudit_Realistic_6x2x4096)->DenseRange(0, 3)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// Issue #23 item 4: every case of tests/audit/audit_realistic_test.cc
// (audit/audit_test_support.h's RealisticCases: 0-5 one hidden library
// effect, 6 none, 7 a soft flange on a soft foundation, 8 an effect outside
// the library), exactly as the test runs it: six postures, the accelerance
// CSV written and read back, the noise model, every library effect a
// candidate, 2 threads (the default). Target: the slowest under 30 s.
void BM_AuditRealisticCase(benchmark::State& state) {
  namespace t = robomach::audit::testing;
  const t::RealisticCase k = t::RealisticCases().at(static_cast<size_t>(state.range(0)));
  t::Campaign c = t::MakeCampaign();
  const auto [id, deg] = robomach::testing::SixthPostureDeg();
  Eigen::VectorXd q(6);
  for (int j = 0; j < 6; ++j) q(j) = DegToRad(deg[j]);
  c.poses.push_back({id, q});
  c.postures[id] = q;
  const auto [d, p] = t::Truth(c, k.hidden);
  dynamics::FrfSet synth = calibration::SynthesizeHammerTest(dynamics::RobotModel::Build(d, p), c.poses,
                                                             robomach::testing::RealisticHammerTest(k.seed));
  if (k.alter != nullptr) k.alter(&synth);
  const std::string path = robomach::testing::TempDir("bench_audit_" + k.name) + "/hammer.csv";
  io::WriteFrfCsv(path, synth, io::FrfQuantity::kAccelerance, 0);
  const dynamics::FrfSet read = io::ReadFrfCsv(path).frfs;
  const dynamics::FrfSet measured = calibration::UsableData(read, calibration::EstimateNoise(read, {}));
  AuditOptions o;
  std::string verdict;
  for (auto _ : state) {
    const AuditResult r = RunAudit(c.cfg.description, c.cfg.parameters, c.postures, measured, o);
    verdict = r.verdict;
    benchmark::DoNotOptimize(r.candidates.data());
  }
  state.SetLabel(k.name + ": " + verdict.substr(0, 50));
}
BENCHMARK(BM_AuditRealisticCase)->DenseRange(0, 8)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

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
