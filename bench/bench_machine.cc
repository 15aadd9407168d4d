// Speed of the machine module (issue 13): 4x quadrature decoding >= 200 M
// samples/s on one core.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "robomach/machine/quadrature_decoder.h"

#include <filesystem>
#include <fstream>

#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/machine_files.h"
#include "robomach/machine/synthesis.h"
#include "robomach/workflows/acquisition_inputs.h"

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

// axis-acquire's work on a 60 s, 8 kHz, five-axis record (480,001 rows) with
// the default tables, temperature log and --program: read the counts, apply
// compensation and kinematics, track the contour error, write the acquired
// path CSV (17 digits). Target: < 1 s.
struct AcquireFixture {
  std::string dir, counts_path, out_path, comp_path, temp_path, prog_path;
  robomach::io::MachineFile mf;
};

const AcquireFixture& Fixture() {
  namespace fs = std::filesystem;
  using namespace robomach;
  static AcquireFixture f = [] {
    AcquireFixture f;
    const std::string src = ROBOMACH_SOURCE_DIR;
    f.dir = (fs::temp_directory_path() / "robomach_bench_machine").string();
    fs::create_directories(f.dir);
    f.counts_path = f.dir + "/counts.csv";
    f.out_path = f.dir + "/tcp.csv";
    f.mf = io::ReadMachineFile(src + "/config/machine/dmu80p.yaml");
    f.comp_path = src + "/config/machine/dmu80p_comp.mpf";
    f.temp_path = src + "/config/machine/dmu80p_temperature.csv";
    f.prog_path = src + "/config/machine/cone_frustum.csv";
    // The record: the cone frustum at a feed that takes 60 s.
    const auto tables = io::ReadCompensationFile(f.comp_path, f.mf);
    const machine::Compensation comp(5, tables.encoder, tables.cross_axis, io::ReadTemperatureLog(f.temp_path, f.mf));
    const machine::ProgrammedPath path = io::ReadProgramFile(f.prog_path);
    machine::SynthesisOptions o;
    o.feed = path.length() / 60.0;
    o.sample_rate_hz = 8000.0;
    o.initial_guess = {0, 0, 0, DegToRad(-90.0), 0};
    const auto origin = machine::StartMeasured(f.mf.machine, &comp, path, o);
    for (int a = 0; a < 5; ++a) f.mf.machine.axes[a].origin = origin[a];
    const auto res = machine::SynthesizeCounts(f.mf.machine, &comp, path, o, origin);
    io::WriteFileAtomically(f.counts_path, [&](std::ostream& out) {
      io::CountsWriter w(out, f.mf.machine.axes);
      for (long r = 0; r < res.record.rows(); ++r) w.Row(res.record.t_s[r], res.record.counts.data() + r * 5);
    });
    return f;
  }();
  return f;
}

void BM_AcquirePipeline_60s_8kHz(benchmark::State& state) {
  using namespace robomach;
  const AcquireFixture& f = Fixture();
  long rows = 0;
  for (auto _ : state) {
    const auto tables = io::ReadCompensationFile(f.comp_path, f.mf);
    const machine::Compensation comp(5, tables.encoder, tables.cross_axis, io::ReadTemperatureLog(f.temp_path, f.mf));
    const machine::ProgrammedPath path = io::ReadProgramFile(f.prog_path);
    const machine::CountsRecord rec = io::ReadCountsFile(f.counts_path, f.mf);
    machine::Acquisition acq(f.mf.machine, &comp);
    machine::ContourTracker tracker(path);
    // As axis-acquire does it: rows computed in order while earlier chunks
    // are formatted and written, on two threads.
    io::WriteFileAtomically(f.out_path, [&](std::ostream& out) {
      benchmark::DoNotOptimize(workflows::WriteAcquiredPath(out, rec, f.mf.machine.axes, &acq, &tracker));
    });
    rows = rec.rows();
  }
  state.counters["rows"] = static_cast<double>(rows);
}
BENCHMARK(BM_AcquirePipeline_60s_8kHz)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// Its parts: reading the counts; compensation + kinematics + contour; writing.
void BM_AcquirePart_ReadCounts(benchmark::State& state) {
  const AcquireFixture& f = Fixture();
  for (auto _ : state) benchmark::DoNotOptimize(robomach::io::ReadCountsFile(f.counts_path, f.mf));
}
BENCHMARK(BM_AcquirePart_ReadCounts)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_AcquirePart_Compute(benchmark::State& state) {
  using namespace robomach;
  const AcquireFixture& f = Fixture();
  const auto tables = io::ReadCompensationFile(f.comp_path, f.mf);
  const machine::Compensation comp(5, tables.encoder, tables.cross_axis, io::ReadTemperatureLog(f.temp_path, f.mf));
  const machine::ProgrammedPath path = io::ReadProgramFile(f.prog_path);
  const machine::CountsRecord rec = io::ReadCountsFile(f.counts_path, f.mf);
  for (auto _ : state) {
    machine::Acquisition acq(f.mf.machine, &comp);
    machine::ContourTracker tracker(path);
    double sum = 0.0;
    for (long r = 0; r < rec.rows(); ++r) sum += tracker.Next(acq.Process(rec.t_s[r], rec.counts.data() + r * 5).pose).distance;
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_AcquirePart_Compute)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_AcquirePart_Write(benchmark::State& state) {
  using namespace robomach;
  const AcquireFixture& f = Fixture();
  machine::AcquiredSample s;
  s.real = {0.123456789, -0.5, -0.3, -1.0, 2.0};
  machine::ContourError e{1e-7, 1e-6, 0.1};
  for (auto _ : state) {
    io::WriteFileAtomically(f.out_path, [&](std::ostream& out) {
      io::AcquiredPathWriter w(out, f.mf.machine.axes, true);
      for (long r = 0; r < 480001; ++r) w.Row(r / 8000.0, s, &e);
    });
  }
}
BENCHMARK(BM_AcquirePart_Write)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
