// axis-synth: what a five-axis machine with given errors and compensation
// tables would record for a programmed path: encoder counts (docs/formats.md §8.1)
// and optionally the raw quadrature capture (docs/formats.md §8.2) behind them.
#include <CLI/CLI.hpp>

#include <bit>
#include <cmath>
#include <fstream>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/machine_files.h"
#include "robomach/io/number_format.h"
#include "robomach/machine/synthesis.h"

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
  std::string machine_path, program_path, comp_path, temp_path, out_path, machine_out, capture_path;
  long max_rows = 1000000;
  double feed_mm_min = 2000.0, rate_hz = 8000.0, dwell_s = 0.0, start_b_deg = -90.0, glitch_p = 0.0;
  int capture_every = 10, settle = 2;
  unsigned seed = 1;
  app.add_option("--machine", machine_path, "machine file YAML (docs/formats.md §8.3)")->required();
  app.add_option("--program", program_path, "programmed path CSV x_mm,y_mm,z_mm,i,j,k (workpiece coordinates)")
      ->required();
  app.add_option("--out", out_path, "counts CSV to write (docs/formats.md §8.1); '-' = stdout")->required();
  app.add_option("--compensation", comp_path, "Siemens 840D sl table file (docs/formats.md §8.4) the controller applies");
  app.add_option("--temperature", temp_path, "temperature log t_s,axis,K0_mm,tan_beta,P0_mm");
  app.add_option("--feed-mm-min", feed_mm_min, "tool tip speed along the path [mm/min]")->capture_default_str();
  app.add_option("--sample-rate-hz", rate_hz, "counts rows per second [Hz]")->capture_default_str();
  app.add_option("--dwell-s", dwell_s, "time at the first point before moving [s]")->capture_default_str();
  app.add_option("--start-b-deg", start_b_deg,
                 "B near which the first point's inverse kinematics is chosen (then: nearest previous) [deg]; "
                 "radians or more than a turn are flagged (exit 3)")
      ->capture_default_str();
  app.add_option("--machine-out", machine_out, "write the machine file with origins = measured start position");
  app.add_option("--capture", capture_path, "also write the raw quadrature capture (docs/formats.md §8.2)");
  app.add_option("--capture-every", capture_every, "capture samples per counts row (capture rate = rate x this)")
      ->capture_default_str();
  app.add_option("--capture-settle", settle,
                 "last capture samples of each row interval without an edge (a glitch filter of up to settle+1 "
                 "samples then sees every step by the row)")
      ->capture_default_str();
  app.add_option("--glitch-probability", glitch_p,
                 "chance per capture sample of a one-sample glitch on one channel of an idle axis")
      ->capture_default_str();
  app.add_option("--seed", seed, "random seed (capture start phases, glitches)")->capture_default_str();
  app.add_option("--max-rows", max_rows,
                 "refuse (exit 64) a record longer than this many rows (about 45 bytes each) before writing it")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    CheckOptionRange("--feed-mm-min", feed_mm_min, 1e-3, 1e6);
    CheckOptionRange("--sample-rate-hz", rate_hz, 1.0, 1e8);
    CheckOptionRange("--dwell-s", dwell_s, 0.0, 1e5);
    CheckOptionRange("--start-b-deg", start_b_deg, -720.0, 720.0);
    CheckOptionRange("--glitch-probability", glitch_p, 0.0, 1.0);
    CheckOptionRange("--max-rows", max_rows, 2L, 1000000000L);
    if (capture_every < 1 || capture_every > 100000) throw UsageError("--capture-every: expected 1..100000");
    if (settle < 0 || settle >= capture_every) throw UsageError("--capture-settle: expected 0 <= settle < --capture-every");
    // Plausible ranges (docs/plausibility.md): feeds of machine tools 10 -
    // 100 000 mm/min (HSC rapids to 100 m/min), controller traces 100 Hz -
    // 100 kHz (840D sl servo trace: 8 kHz at most in the IPO/servo cycle).
    std::vector<std::string> implausible;
    for (const std::string& w :
         {ImplausibleOption("--feed-mm-min", feed_mm_min, 10.0, 100000.0, "mm/min",
                            "machine tool feeds (up to 100 m/min rapids)", "a feed in m/min typed in the mm/min option?",
                            "a feed in um/min typed in the mm/min option?"),
          ImplausibleOption("--sample-rate-hz", rate_hz, 10.0, 1e6, "Hz", "position traces (100 Hz - 100 kHz)",
                            "a rate in kHz typed in the Hz option?", "a rate in mHz typed in the Hz option?"),
          ImplausibleOption("--dwell-s", dwell_s, 0.0, 600.0, "s", "dwells before a measured move (under a minute)", "",
                            "a dwell in ms typed in the s option?")}) {
      if (!w.empty()) implausible.push_back(w);
    }
    // --start-b-deg, the only angle option: a nutating head's B within a
    // turn either way (the inverse kinematics repeats every turn); within
    // 2 pi and not whole it is radians (-1.5708 for -90 deg), the rule of
    // the _deg fields (CheckDegreesNotRadians, src/io/plausible.h).
    if (const std::string w = RadiansInDegreeOption("--start-b-deg", start_b_deg); !w.empty()) {
      implausible.push_back(w);
    } else if (const std::string w = ImplausibleOption(
                   "--start-b-deg", start_b_deg, -360.0, 360.0, "deg", "a nutating head's B (within a turn of 0)",
                   "an angle in gradians (400 a turn) or a turn too many typed?",
                   "an angle in gradians (400 a turn) or a turn too many typed?");
               !w.empty()) {
      implausible.push_back(w);
    }
    for (const std::string& w : implausible) Warn(kTool, w);
    RequireReadableFile(machine_path, "machine file");
    RequireReadableFile(program_path, "programmed path");
    if (!comp_path.empty()) {
      RequireInputFile("--compensation", comp_path, "compensation file", {io::FileKind::kMpf}, io::kCompensationFileFormat);
    }
    if (!temp_path.empty()) {
      RequireInputFile("--temperature", temp_path, "temperature log", {io::FileKind::kCsv}, io::kTemperatureLogFormat);
    }
    CheckDistinctPaths({{"--machine", machine_path}, {"--program", program_path}, {"--compensation", comp_path},
                        {"--temperature", temp_path}},
                       {{"--out", out_path}, {"--machine-out", machine_out}, {"--capture", capture_path}});
    io::MachineFile mf = io::ReadMachineFile(machine_path);
    const machine::ProgrammedPath path = io::ReadProgramFile(program_path);
    io::CompensationTables tables;
    if (!comp_path.empty()) tables = io::ReadCompensationFile(comp_path, mf, "--compensation");
    std::vector<machine::TemperatureCompensation> temps;
    std::vector<std::string> temp_implausible;
    if (!temp_path.empty()) temps = io::ReadTemperatureLog(temp_path, mf, &temp_implausible);
    for (const auto* found : {&mf.implausible, &tables.implausible, &temp_implausible}) {
      for (const std::string& w : *found) Warn(kTool, w);
      implausible.insert(implausible.end(), found->begin(), found->end());
    }
    const machine::Compensation comp(static_cast<int>(mf.machine.axes.size()), tables.encoder, tables.cross_axis, temps);
    const machine::Compensation* comp_ptr = comp.empty() ? nullptr : &comp;

    machine::SynthesisOptions o;
    o.feed = MmToM(feed_mm_min) / 60.0;
    o.sample_rate_hz = rate_hz;
    o.dwell = dwell_s;
    o.initial_guess.assign(mf.machine.kinematic_axis.size(), 0.0);
    o.initial_guess[3] = DegToRad(start_b_deg);  // B of the nutating head (X, Y, Z, B, C)

    // A slow feed at a servo rate is a long record (33 mm/min on the cone
    // frustum: 4.1 M rows, 184 MB): said before anything is computed.
    if (const long rows = machine::SynthesisRows(path, o); rows > max_rows) {
      throw UsageError("--feed-mm-min " + io::FormatDouble(feed_mm_min) + " at --sample-rate-hz " +
                       io::FormatDouble(rate_hz) + ": the path's " + FormatNumber(MToMm(path.length()), 4) +
                       " mm take " + FormatNumber(static_cast<double>(rows) / rate_hz, 4) + " s, " + std::to_string(rows) +
                       " rows (about " + FormatNumber(static_cast<double>(rows) * 45e-6, 3) + " MB), more than --max-rows " +
                       std::to_string(max_rows) + ": raise --feed-mm-min, lower --sample-rate-hz, or raise --max-rows");
    }
    std::vector<double> origin(mf.machine.axes.size());
    for (size_t a = 0; a < origin.size(); ++a) origin[a] = mf.machine.axes[a].origin;
    if (!machine_out.empty()) {
      origin = machine::StartMeasured(mf.machine, comp_ptr, path, o);
      for (size_t a = 0; a < origin.size(); ++a) mf.machine.axes[a].origin = origin[a];
    }
    const machine::SynthesisResult res = machine::SynthesizeCounts(mf.machine, comp_ptr, path, o, origin);
    if (!res.ok) throw InputError({program_path, 0, 0}, "the machine cannot follow the path " + res.message);
    const auto& rec = res.record;
    const size_t n = mf.machine.axes.size();
    for (size_t a = 0; a < n; ++a) {
      if (rec.counts[a] != 0) {
        const auto& ax = mf.machine.axes[a];
        const double scale = ax.kind == machine::AxisKind::kLinear ? 1e3 : 180.0 / kPi;
        throw InputError({machine_path, 0, 0},
                         "axis " + ax.name + ": the path starts at measured " + FormatNumber(res.start_measured[a] * scale, 7) +
                             (ax.kind == machine::AxisKind::kLinear ? " mm" : " deg") + ", " + std::to_string(rec.counts[a]) +
                             " counts from origin " + io::FormatDouble(ax.origin * scale) +
                             "; the first counts row must be the reference position (docs/formats.md §8.1): set the "
                             "origins to the start position or pass --machine-out");
      }
    }
    std::vector<std::pair<std::string, std::string>> meta{{"generator", "axis-synth (robomach)"},
                                                          {"machine", machine_out.empty() ? machine_path : machine_out},
                                                          {"program", program_path},
                                                          {"sample_rate_hz", io::FormatDouble(rate_hz)}};
    // Capture first (it can fail on too fast a move), then the counts.
    if (!capture_path.empty()) {
      std::vector<std::string> names;
      for (const auto& a : mf.machine.axes) names.push_back(a.name);
      machine::CaptureSynthesizer cap(static_cast<int>(n), capture_every, settle, glitch_p, seed, names);
      io::WriteFileAtomically(capture_path, [&](std::ostream& out) {
        std::vector<std::uint16_t> words;
        auto flush = [&]() {
          if constexpr (std::endian::native == std::endian::big) {
            for (auto& w : words) w = static_cast<std::uint16_t>((w >> 8) | (w << 8));
          }
          out.write(reinterpret_cast<const char*>(words.data()), static_cast<std::streamsize>(words.size() * 2));
          words.clear();
        };
        cap.Start(rec.counts.data(), &words);
        for (long r = 1; r < rec.rows(); ++r) {
          try {
            cap.Next(rec.counts.data() + r * n, &words);
          } catch (const std::invalid_argument& e) {
            throw UsageError(std::string("--capture-every ") + std::to_string(capture_every) + ": " + e.what() +
                             "; raise --capture-every or lower --feed-mm-min");
          }
          if (words.size() > (1u << 16)) flush();
        }
        flush();
      });
      std::cerr << kTool << ": capture of " << (rec.rows() - 1) * capture_every + 1 << " samples at "
                << io::FormatDouble(rate_hz * capture_every) << " Hz (--every " << capture_every << " gives back the counts), "
                << cap.glitches() << " glitches\n";
    }
    if (!machine_out.empty()) io::WriteMachineFile(machine_out, mf);
    io::WriteFileAtomically(out_path, [&](std::ostream& out) {
      io::CountsWriter w(out, mf.machine.axes, meta);
      for (long r = 0; r < rec.rows(); ++r) w.Row(rec.t_s[r], rec.counts.data() + r * n);
    });
    std::cerr << kTool << ": " << rec.rows() << " rows, " << io::FormatDouble(rec.t_s.back()) << " s\n";
    return implausible.empty() ? kExitOk : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
