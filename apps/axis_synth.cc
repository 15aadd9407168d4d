// axis-synth: what a five-axis machine with given errors and compensation
// tables would record for a programmed path: encoder counts (docs/formats.md §8.1)
// and optionally the raw quadrature capture (docs/formats.md §8.2) behind them.
#include <CLI/CLI.hpp>

#include <bit>
#include <fstream>

#include "cli_support.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/machine_files.h"
#include "robomach/io/number_format.h"
#include "robomach/workflows/axis_synth.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "axis-synth";

int Run(int argc, char** argv) {
  CLI::App app{
      "axis-synth: simulate the acquisition of a five-axis machine following a programmed path.\n"
      "The tool tip moves along the polyline at the feed; the machine's true kinematics (with the rotary\n"
      "errors of the machine file) give the real axis positions; the controller's compensation (tables and\n"
      "temperature log) is undone to get the measured positions, quantised to counts of each axis's resolution.\n"
      "The first counts row is the reference position: the machine file's origins must be the measured start\n"
      "position, or --machine-out writes a copy of the machine file with those origins."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp());
  std::string out_path, machine_out, capture_path;
  workflows::AxisSynthOptions o;
  app.add_option("--machine", o.machine_path, "machine file YAML (docs/formats.md §8.3)")->required();
  app.add_option("--program", o.program_path, "programmed path CSV x_mm,y_mm,z_mm,i,j,k (workpiece coordinates)")
      ->required();
  app.add_option("--out", out_path, "counts CSV to write (docs/formats.md §8.1); '-' = stdout")->required();
  app.add_option("--compensation", o.compensation_path,
                 "Siemens 840D sl table file (docs/formats.md §8.4) the controller applies");
  app.add_option("--temperature", o.temperature_path, "temperature log t_s,axis,K0_mm,tan_beta,P0_mm");
  app.add_option("--feed-mm-min", o.feed_mm_min, "tool tip speed along the path [mm/min]")->capture_default_str();
  app.add_option("--sample-rate-hz", o.sample_rate_hz, "counts rows per second [Hz]")->capture_default_str();
  app.add_option("--dwell-s", o.dwell_s, "time at the first point before moving [s]")->capture_default_str();
  app.add_option("--start-b-deg", o.start_b_deg,
                 "B near which the first point's inverse kinematics is chosen (then: nearest previous) [deg]; "
                 "radians or more than a turn are flagged (exit 3)")
      ->capture_default_str();
  app.add_option("--machine-out", machine_out, "write the machine file with origins = measured start position");
  app.add_option("--capture", capture_path, "also write the raw quadrature capture (docs/formats.md §8.2)");
  app.add_option("--capture-every", o.capture_every, "capture samples per counts row (capture rate = rate x this)")
      ->capture_default_str();
  app.add_option("--capture-settle", o.capture_settle,
                 "last capture samples of each row interval without an edge (a glitch filter of up to settle+1 "
                 "samples then sees every step by the row)")
      ->capture_default_str();
  app.add_option("--glitch-probability", o.glitch_probability,
                 "chance per capture sample of a one-sample glitch on one channel of an idle axis")
      ->capture_default_str();
  app.add_option("--seed", o.seed, "random seed (capture start phases, glitches)")->capture_default_str();
  app.add_option("--max-rows", o.max_rows,
                 "refuse (exit 64) a record longer than this many rows (about 45 bytes each) before writing it")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    const std::vector<FieldSource> fields = {
        {"feed_mm_min", "--feed-mm-min"},           {"sample_rate_hz", "--sample-rate-hz"},
        {"dwell_s", "--dwell-s"},                   {"start_b_deg", "--start-b-deg"},
        {"glitch_probability", "--glitch-probability"}, {"max_rows", "--max-rows"},
        {"capture_every", "--capture-every"},       {"capture_settle", "--capture-settle"},
        {"compensation_path", "--compensation"},    {"origins_at_start", "--machine-out"}};
    for (const FieldSource& f : fields) o.names[f.field] = f.name;
    FromFields(fields, [&] { o.Validate(); });
    // Said before the files are checked; the run flags them (exit 3).
    for (const std::string& w : o.UnitFindings()) Warn(kTool, w);
    RequireReadableFile(o.machine_path, "machine file");
    RequireReadableFile(o.program_path, "programmed path");
    if (!o.compensation_path.empty()) {
      RequireInputFile("--compensation", o.compensation_path, "compensation file", {io::FileKind::kMpf},
                       io::kCompensationFileFormat);
    }
    if (!o.temperature_path.empty()) {
      RequireInputFile("--temperature", o.temperature_path, "temperature log", {io::FileKind::kCsv},
                       io::kTemperatureLogFormat);
    }
    CheckDistinctPaths({{"--machine", o.machine_path}, {"--program", o.program_path},
                        {"--compensation", o.compensation_path}, {"--temperature", o.temperature_path}},
                       {{"--out", out_path}, {"--machine-out", machine_out}, {"--capture", capture_path}});
    o.origins_at_start = !machine_out.empty();
    const workflows::AxisSynthRun run =
        FromFields(fields, [&] { return workflows::RunAxisSynth(o, MessagePrinter(kTool)); });
    const io::MachineFile& mf = run.machine;
    const machine::CountsRecord& rec = run.record;
    // Capture first (it can fail on too fast a move), then the counts.
    if (!capture_path.empty()) {
      const auto written = FromFields(fields, [&] { return run.WriteCapture(o, capture_path); });
      std::cerr << kTool << ": capture of " << written.samples << " samples at "
                << io::FormatDouble(o.sample_rate_hz * o.capture_every) << " Hz (--every " << o.capture_every
                << " gives back the counts), " << written.glitches << " glitches\n";
    }
    if (!machine_out.empty()) io::WriteMachineFile(machine_out, mf);
    run.WriteCounts(o, out_path, machine_out);
    std::cerr << kTool << ": " << rec.rows() << " rows, " << io::FormatDouble(rec.t_s.back()) << " s\n";
    return ExitCodeFor(run.status());
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
