// Benchmarks of issue #4: a 5-posture, 2-direction, 2000-line calibration
// (target < 5 s) and the modal fit of one 4000-line FRF (target < 0.2 s).
#include <benchmark/benchmark.h>

#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"

namespace robomach::calibration {
namespace {

struct Data {
  io::RobotConfig cfg;
  PostureMap postures;
  dynamics::FrfSet measured;
};

// The acceptance scenario: truth m6 +20 %, d6 −15 %, alpha +30 %, beta −25 %,
// five demonstration postures, xx and yy, 0.25..500 Hz (2000 lines), 2 % noise.
const Data& Scenario() {
  static const Data d = [] {
    Data d{io::LoadRobotConfig(std::string(ROBOMACH_SOURCE_DIR) + "/config/kr210.yaml"), {}, {}};
    dynamics::ParameterSet truth = d.cfg.parameters;
    truth.Set("m6_kg", 1.2 * truth.Get("m6_kg"));
    truth.Set("d6_m", 0.85 * truth.Get("d6_m"));
    truth.Set("alpha_s", 1.3 * truth.Get("alpha_s"));
    truth.Set("beta_per_s", 0.75 * truth.Get("beta_per_s"));
    std::vector<NamedPosture> np;
    for (const auto& p : io::ReadPostureFile(std::string(ROBOMACH_SOURCE_DIR) + "/config/postures_demo.csv", 6)) {
      np.push_back({p.id, p.q});
      d.postures[p.id] = p.q;
    }
    VirtualHammerOptions o;
    o.relative_noise = 0.02;
    o.seed = 11;
    d.measured = SynthesizeHammerTest(dynamics::RobotModel::Build(d.cfg.description, truth), np, o);
    return d;
  }();
  return d;
}

// Modal fits of the 10 measured FRFs plus the calibration: what a user waits for.
void BM_Calibration_5Postures_2Directions_2000Lines(benchmark::State& state) {
  const Data& d = Scenario();
  CalibrationOptions o;
  o.objective = static_cast<Objective>(state.range(0));
  for (auto _ : state) {
    const MeasuredFeatures f = ExtractFeatures(d.measured);
    const CalibrationResult r = Calibrate(d.cfg.description, d.cfg.parameters, d.postures, d.measured, f, o);
    benchmark::DoNotOptimize(r.parameters.values().data());
  }
  state.SetLabel(ToString(o.objective));
}
BENCHMARK(BM_Calibration_5Postures_2Directions_2000Lines)
    ->Arg(static_cast<int>(Objective::kModalTwoStage))
    ->Arg(static_cast<int>(Objective::kModalJoint))
    ->Arg(static_cast<int>(Objective::kWholeCurve))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// One 4000-line FRF: posture P1, Hxx, 0.125..500 Hz, 2 % noise.
void BM_ModalFit_4000Lines(benchmark::State& state) {
  const Data& d = Scenario();
  VirtualHammerOptions o;
  o.block_samples = 40960;  // Δf = 0.125 Hz
  o.fmin_hz = 0.125;
  o.relative_noise = 0.02;
  o.directions = {{Axis::kX, Axis::kX}};
  const dynamics::FrfSet one =
      SynthesizeHammerTest(d.cfg.Build(), {{"P1", d.postures.at("P1")}}, o);
  const dynamics::Frf& frf = one.at({"P1", Axis::kX, Axis::kX});
  if (frf.size() != 4000) state.SkipWithError("expected 4000 lines");
  for (auto _ : state) {
    const ModalFitResult r = FitModes(frf);
    benchmark::DoNotOptimize(r.modes.data());
  }
}
BENCHMARK(BM_ModalFit_4000Lines)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace
}  // namespace robomach::calibration

BENCHMARK_MAIN();
