// axis-decode: raw quadrature capture (docs/formats.md §8.2) to encoder counts
// (docs/formats.md §8.1), streamed in constant memory.
#include <CLI/CLI.hpp>

#include <bit>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/machine_files.h"
#include "robomach/io/number_format.h"
#include "robomach/machine/quadrature_decoder.h"
#include "robomach/report/posture_json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "axis-decode";

int Run(int argc, char** argv) {
  CLI::App app{
      "axis-decode: decode a raw quadrature capture (docs/formats.md §8.2: little-endian uint16 words, bits 2k/2k+1 =\n"
      "A/B of the k-th axis of the machine file) into encoder counts (docs/formats.md §8.1), 4x, with error events\n"
      "(A and B of one axis changing in one sample) counted per axis. Streams captures of any size."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() + "\nExit 3: outputs written, but the capture had error events (positions uncertain).");
  std::string machine_path, capture_path, out_path, summary_path;
  double rate_hz = 0.0;
  long every = 1;
  int filter = 0;
  app.add_option("--machine", machine_path, "machine file YAML (docs/formats.md §8.3): axis names and order")->required();
  app.add_option("--capture", capture_path, "raw capture, uint16 little-endian words")->required();
  app.add_option("--sample-rate-hz", rate_hz, "capture sample rate [Hz]")->required();
  app.add_option("--every", every, "write the counts at samples 0, N, 2N, ...")->capture_default_str();
  app.add_option("--glitch-filter", filter,
                 "accept a new level of a channel only after N equal samples (0 or 1: off); edges are then "
                 "seen N-1 samples late")
      ->capture_default_str();
  app.add_option("--out", out_path, "counts CSV to write; '-' = stdout")->required();
  app.add_option("--summary", summary_path, "JSON {\"error_events\": {axis: n}, \"samples\": n, ...}");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) throw UsageError("--sample-rate-hz: expected a rate > 0 Hz");
    if (every < 1) throw UsageError("--every: expected N >= 1");
    if (filter < 0 || filter > 1000000) throw UsageError("--glitch-filter: expected 0..1000000 samples");
    RequireReadableFile(machine_path, "machine file");
    RequireReadableFile(capture_path, "capture");
    CheckDistinctPaths({{"--machine", machine_path}, {"--capture", capture_path}},
                       {{"--out", out_path}, {"--summary", summary_path}});
    const io::MachineFile mf = io::ReadMachineFile(machine_path);
    const auto& axes = mf.machine.axes;
    const auto bytes = std::filesystem::file_size(capture_path);
    if (bytes % 2 != 0) {
      throw InputError({capture_path, 0, 0}, "size " + std::to_string(bytes) +
                                                 " bytes is not a whole number of 16-bit words (truncated capture?)");
    }
    if (bytes == 0) throw InputError({capture_path, 0, 0}, "the capture is empty");
    const long long total = static_cast<long long>(bytes / 2);

    machine::QuadratureDecoder decoder({.num_axes = static_cast<int>(axes.size()), .glitch_filter_samples = filter});
    ProgressLine progress(kTool, "samples", static_cast<long>(total));
    io::WriteFileAtomically(out_path, [&](std::ostream& out) {
      std::ifstream in(capture_path, std::ios::binary);
      if (!in) throw InputError({capture_path, 0, 0}, "cannot open file for reading");
      io::CountsWriter writer(out, axes,
                              {{"generator", "axis-decode (robomach)"},
                               {"capture", capture_path},
                               {"sample_rate_hz", io::FormatDouble(rate_hz)},
                               {"every", std::to_string(every)},
                               {"glitch_filter", std::to_string(filter)}});
      std::vector<std::uint16_t> block(1 << 16);
      long long pos = 0, next_out = 0;
      while (pos < total) {
        const long long want = std::min<long long>(static_cast<long long>(block.size()), total - pos);
        in.read(reinterpret_cast<char*>(block.data()), want * 2);
        if (in.gcount() != want * 2) throw InputError({capture_path, 0, 0}, "read error");
        if constexpr (std::endian::native == std::endian::big) {
          for (auto& w : block) w = static_cast<std::uint16_t>((w >> 8) | (w << 8));
        }
        long long at = 0;
        while (at < want) {
          // Decode up to and including the next output sample.
          const long long len = std::min(want - at, next_out - (pos + at) + 1);
          decoder.Decode(block.data() + at, static_cast<std::size_t>(len));
          at += len;
          if (pos + at - 1 == next_out) {
            writer.Row(static_cast<double>(next_out) / rate_hz, decoder.counts().data());
            next_out += every;
          }
        }
        pos += want;
        progress.Update(static_cast<long>(pos));
      }
    });
    progress.Finish();
    long long events = 0;
    nlohmann::json j;
    j["samples"] = decoder.samples();
    j["sample_rate_hz"] = rate_hz;
    j["every"] = every;
    j["glitch_filter"] = filter;
    j["error_events"] = nlohmann::json::object();
    j["final_counts"] = nlohmann::json::object();
    for (size_t a = 0; a < axes.size(); ++a) {
      j["error_events"][axes[a].name] = decoder.error_events()[a];
      j["final_counts"][axes[a].name] = decoder.counts()[a];
      events += decoder.error_events()[a];
    }
    if (!summary_path.empty()) io::WriteFileAtomically(summary_path, report::DumpJson(j));
    if (events > 0) {
      std::string per;
      for (size_t a = 0; a < axes.size(); ++a) {
        if (decoder.error_events()[a] > 0) per += " " + axes[a].name + ": " + std::to_string(decoder.error_events()[a]);
      }
      Warn(kTool, std::to_string(events) + " error events (A and B changed in one sample; each leaves the position "
                  "uncertain by 2 counts):" + per + ". Raise the sample rate or use --glitch-filter.");
      return kExitFlagged;
    }
    return kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
