// The global modal fit (issue #34 §4: a 1600-line FRF in well under a
// second): a synthetic 1600-line FRF with three modes and 1 % noise, and
// the real files of ../shared/external (skipped when absent). The noise
// model is estimated outside the timed loop (the fit is what is timed).
#include <cmath>
#include <complex>
#include <filesystem>
#include <random>
#include <string>

#include <benchmark/benchmark.h>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/global_modal_fit.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/io/frf_files.h"

namespace {

using robomach::dynamics::Frf;
using cd = std::complex<double>;

Frf Synthetic1600() {
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 1600;
  Eigen::VectorXd f(n);
  Eigen::VectorXcd h(n);
  const double fr[3] = {1070.0, 1960.0, 2620.0}, zr[3] = {0.03, 0.02, 0.025}, kr[3] = {2e7, 3e7, 5e7};
  for (int k = 0; k < n; ++k) {
    f(k) = 2.5 * (k + 1);
    const double w = 2 * M_PI * f(k);
    cd v = 0.0;
    for (int r = 0; r < 3; ++r) {
      const double wn = 2 * M_PI * fr[r];
      v += wn * wn / kr[r] / (wn * wn - w * w + cd(0, 2 * zr[r] * wn * w));
    }
    h(k) = v * (1.0 + 0.01 / std::sqrt(2.0) * cd(g(rng), g(rng)));
  }
  return Frf::FromSamples(f, h);
}

void BM_GlobalFit_Synthetic1600Lines(benchmark::State& state) {
  const Frf frf = Synthetic1600();
  for (auto _ : state) benchmark::DoNotOptimize(robomach::calibration::FitModesGlobal({frf}));
}
BENCHMARK(BM_GlobalFit_Synthetic1600Lines)->Unit(benchmark::kMillisecond);

void BM_SingleFit_Synthetic1600Lines(benchmark::State& state) {
  const Frf frf = Synthetic1600();
  for (auto _ : state) benchmark::DoNotOptimize(robomach::calibration::FitModes(frf));
}
BENCHMARK(BM_SingleFit_Synthetic1600Lines)->Unit(benchmark::kMillisecond);

std::string Shared(const std::string& rel) {
  return std::string(ROBOMACH_SOURCE_DIR) + "/../shared/external/frf_uff58/" + rel;
}

void BM_GlobalFit_Dataset58(benchmark::State& state) {
  const std::string path = Shared("ufffiles_jl/dataset58_FRF.unv");
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("../shared/external is absent");
    return;
  }
  Frf frf = robomach::io::ReadFrfFile(path).frfs.begin()->second;
  frf = frf.WithNoise(robomach::calibration::EstimateFrfNoise(frf).sigma_m_per_N);
  for (auto _ : state) benchmark::DoNotOptimize(robomach::calibration::FitModesGlobal({frf}));
}
BENCHMARK(BM_GlobalFit_Dataset58)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
