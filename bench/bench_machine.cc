// Speed of the machine module (issue 13): 4x quadrature decoding >= 200 M
// samples/s on one core.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "robomach/machine/quadrature_decoder.h"

namespace {

using robomach::machine::QuadratureDecoder;

// A five-axis capture in which each axis steps with probability p per sample
// (p = 0.05: a 2 MHz card watching axes at ~100 k counts/s; p = 1: every axis
// moves at every sample, the worst case).
std::vector<std::uint16_t> Capture(double p, std::size_t n) {
  constexpr int kA[4] = {0, 1, 1, 0}, kB[4] = {0, 0, 1, 1};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int phase[5] = {0, 1, 2, 3, 0};
  std::vector<std::uint16_t> w(n);
  for (std::size_t s = 0; s < n; ++s) {
    std::uint16_t word = 0;
    for (int k = 0; k < 5; ++k) {
      if (u(rng) < p) phase[k] = (phase[k] + (u(rng) < 0.5 ? 1 : 3)) % 4;
      word |= static_cast<std::uint16_t>((kA[phase[k]] << (2 * k)) | (kB[phase[k]] << (2 * k + 1)));
    }
    w[s] = word;
  }
  return w;
}

void Decode(benchmark::State& state, double p, int filter) {
  const auto words = Capture(p, 1 << 22);
  for (auto _ : state) {
    QuadratureDecoder d({.num_axes = 5, .glitch_filter_samples = filter});
    // Blocks of 64 k words, as axis-decode reads a file.
    for (std::size_t at = 0; at < words.size(); at += 65536) d.Decode(words.data() + at, 65536);
    benchmark::DoNotOptimize(d.count(0));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(words.size()));
}

void BM_Decode_Typical_p005(benchmark::State& s) { Decode(s, 0.05, 0); }
void BM_Decode_Busy_p02(benchmark::State& s) { Decode(s, 0.2, 0); }
void BM_Decode_WorstCase_p1(benchmark::State& s) { Decode(s, 1.0, 0); }
void BM_Decode_Filter3_p005(benchmark::State& s) { Decode(s, 0.05, 3); }
BENCHMARK(BM_Decode_Typical_p005)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Decode_Busy_p02)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Decode_WorstCase_p1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Decode_Filter3_p005)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
