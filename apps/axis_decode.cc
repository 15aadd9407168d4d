// axis-decode: raw quadrature capture (docs/formats.md §8.2) to encoder counts
// (docs/formats.md §8.1), streamed in constant memory.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/io/atomic_file.h"
#include "robomach/workflows/capture_decoding.h"
#include "robomach/io/counts_file.h"
#include "robomach/io/machine_file.h"
#include "robomach/io/number_format.h"
#include "robomach/report/json.h"

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
    // A counts CSV or a PNG given as the capture: named, not decoded to
    // millions of error events.
    io::RequireBinaryFile(capture_path, io::kCaptureFileFormat, "--capture");
    CheckDistinctPaths({{"--machine", machine_path}, {"--capture", capture_path}},
                       {{"--out", out_path}, {"--summary", summary_path}});
    // Capture cards sample quadrature at 1 kHz - 100 MHz (docs/plausibility.md).
    const std::string rate_w = ImplausibleOption("--sample-rate-hz", rate_hz, 1000.0, 1e8, "Hz",
                                                 "quadrature captures (1 kHz - 100 MHz)",
                                                 "a rate in kHz or MHz typed in the Hz option?",
                                                 "a rate in mHz typed in the Hz option?");
    if (!rate_w.empty()) Warn(kTool, rate_w);
    const io::MachineFile mf = io::ReadMachineFile(machine_path);
    for (const std::string& w : mf.implausible) Warn(kTool, w);
    const auto& axes = mf.machine.axes;
    ProgressLine progress(kTool, "samples", static_cast<long>(std::filesystem::file_size(capture_path) / 2));
    workflows::CaptureDecoding d;
    io::WriteFileAtomically(out_path, [&](std::ostream& out) {
      io::CountsWriter writer(out, axes,
                              {{"generator", "axis-decode (robomach)"},
                               {"capture", capture_path},
                               {"sample_rate_hz", io::FormatDouble(rate_hz)},
                               {"every", std::to_string(every)},
                               {"glitch_filter", std::to_string(filter)}});
      d = workflows::DecodeCaptureFile(capture_path, mf, rate_hz, every, filter,
                                [&](double t_s, const std::int64_t* counts) { writer.Row(t_s, counts); },
                                [&](long done, long) { progress.Update(done); });
    });
    progress.Finish();
    const nlohmann::json j = workflows::CaptureDecodingSummaryJson(d, axes, rate_hz, every, filter);
    if (!summary_path.empty()) io::WriteFileAtomically(summary_path, SummaryText(j));
    for (const Finding& f : d.verdict.findings) Warn(kTool, f.message);
    return mf.implausible.empty() && rate_w.empty() ? ExitCodeFor(d.status()) : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
