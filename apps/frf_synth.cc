// frf-synth: a virtual hammer test. Writes "measured" tool-tip FRFs of a
// robot model (effects and parameters as asked) at the postures of a posture
// file, on a hammer-test grid, with seeded noise, as CSV or UFF58.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <sstream>

#include "cli_support.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/report/json.h"
#include "robomach/workflows/frf_synth.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "frf-synth";

int Run(int argc, char** argv) {
  CLI::App app{
      "frf-synth: a virtual hammer test with known truth.\n"
      "Writes the tool-tip FRFs of a robot model at the postures of a posture file\n"
      "(docs/formats.md §1) on a hammer-test grid with seeded noise, as the CSV of docs/formats.md §3\n"
      "or UFF58 (chosen by the extension of --out: .uff/.unv = UFF58). Grid: lines k*df with\n"
      "df = fs/N; defaults fs from the config's hammer_test.sample_rate_hz (else 5120 Hz) and\n"
      "N = 20480 samples (a 4 s record, df = 0.25 Hz), band 0.25..500 Hz (2000 lines).\n"
      "Noise per line: H (1 + rel n1) + floor(f) n2 (n1, n2 complex standard normal), with\n"
      "floor(f)^2 = [a_r^2 + (a_v/w)^2 + (a_a/w^2)^2] (1 + (f/fc)^4): sensor floors flat in receptance,\n"
      "mobility or accelerance, raised where the hammer's force spectrum rolls off above fc.\n"
      "--coherence writes the H1 coherence of that noise for --averages impacts:\n"
      "gamma^2 = |H|^2 / (|H|^2 + (n-1) sigma^2), sigma^2 = (rel |H|)^2 + floor^2."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp());
  std::string out_path, summary_path, directions = "xx,yy", quantity = "receptance";
  workflows::FrfSynthOptions w;
  calibration::VirtualHammerOptions& o = w.hammer;  // its sample rate NaN: the config's
  app.add_option("--robot", w.robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--postures", w.postures_path, "posture file CSV: pose_id,q1_deg..q6_deg")->required();
  app.add_option("--out", out_path, "output file: .csv (docs/formats.md §3) or .uff/.unv (UFF58 ASCII); '-' = stdout (CSV); another extension is refused (exit 64)")->required();
  app.add_option("--summary", summary_path,
                 "summary JSON (docs/formats.md §4.1): inputs, grid, noise, per FRF its peak; '-' = stdout");
  app.add_option("--set", w.sets, "override a model parameter, NAME=VALUE in its unit (e.g. m6_kg=31.5)");
  app.add_option("--add", w.adds, "switch on an effect by name with its default parameters (e.g. tip_mass)");
  app.add_option("--directions", directions, "response/excitation pairs, e.g. xx,yy,xy")->capture_default_str();
  app.add_option("--sample-rate-hz", o.sample_rate_hz, "sampling frequency [Hz]; default: the config's hammer_test.sample_rate_hz, else 5120");
  app.add_option("--block-samples", o.block_samples, "samples per record N; line spacing fs/N [Hz]")->capture_default_str();
  app.add_option("--fmin-hz", o.fmin_hz, "lowest line kept [Hz], > 0")->capture_default_str();
  app.add_option("--fmax-hz", o.fmax_hz, "highest line kept [Hz], at most the Nyquist frequency fs/2 (above: exit 64)")->capture_default_str();
  app.add_option("--noise-rel", o.relative_noise, "relative noise, rms of complex Gaussian [-] (0.02 = 2 %)")->capture_default_str();
  app.add_option("--noise-abs-m-per-N", o.absolute_noise_m_per_N,
                 "additive noise floor flat in receptance, rms [m/N]")->capture_default_str();
  app.add_option("--noise-abs-m-per-s-per-N", o.absolute_noise_m_per_s_per_N,
                 "additive noise floor flat in mobility (a velocity sensor), rms [(m/s)/N]")->capture_default_str();
  app.add_option("--noise-abs-m-per-s2-per-N", o.absolute_noise_m_per_s2_per_N,
                 "additive noise floor flat in accelerance (an accelerometer), rms [(m/s^2)/N]")->capture_default_str();
  app.add_option("--hammer-cutoff-hz", o.hammer_cutoff_hz,
                 "the hammer tip's force spectrum falls as 1/sqrt(1+(f/fc)^4) above this frequency, which raises the "
                 "floor by the inverse; 0: flat force spectrum [Hz]")->capture_default_str();
  app.add_option("--averages", o.averages,
                 "number of averaged impacts behind the noise levels; sets the coherence and is written as "
                 "'# averages: N' (CSV)")->capture_default_str();
  app.add_option("--seed", o.seed, "random seed of the noise")->capture_default_str();
  app.add_flag("--coherence", o.coherence, "also write a coherence (expected for the noise level)");
  app.add_option("--quantity", quantity, "receptance, mobility or accelerance")
      ->check(OneOf({"receptance", "mobility", "accelerance"}))->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    // The format follows --out's extension (a command-line mistake: exit 64).
    const workflows::FrfFileFormat format = [&] {
      try {
        return workflows::FrfSynthOutputFormat(out_path, "--out", /*allow_stdout=*/true);
      } catch (const OptionError& e) {
        throw UsageError(e.what());
      }
    }();
    // The options through the library's checks, named as the user gave them.
    std::vector<FieldSource> fields = {
        {"sample_rate_hz", "--sample-rate-hz"}, {"block_samples", "--block-samples"}, {"fmin_hz", "--fmin-hz"},
        {"fmax_hz", "--fmax-hz"}, {"relative_noise", "--noise-rel"}, {"absolute_noise_m_per_N", "--noise-abs-m-per-N"},
        {"absolute_noise_m_per_s_per_N", "--noise-abs-m-per-s-per-N"},
        {"absolute_noise_m_per_s2_per_N", "--noise-abs-m-per-s2-per-N"}, {"hammer_cutoff_hz", "--hammer-cutoff-hz"},
        {"averages", "--averages"}, {"directions", "--directions"}};
    for (const FieldSource& f : fields) w.names[f.field] = f.name;
    // NaN is the library's "the config's rate": one typed is refused here.
    if (app.count("--sample-rate-hz") > 0 && std::isnan(o.sample_rate_hz)) {
      throw UsageError("--sample-rate-hz nan: expected a rate in (0, 1e9] Hz");
    }
    FromFields(fields, [&] { w.Validate(); });
    RequireInputFile("--robot", w.robot_path, "robot config", {io::FileKind::kYaml}, io::kRobotConfigFormat);
    RequireInputFile("--postures", w.postures_path, "posture file", {io::FileKind::kCsv}, io::kPostureCsvFormat);
    CheckDistinctPaths({{"--robot", w.robot_path}, {"--postures", w.postures_path}},
                       {{"--out", out_path}, {"--summary", summary_path}});
    o.directions.clear();
    for (const auto& [r, e] : FromOption("--directions", [&] { return io::ParseDirectionPairs(directions); })) {
      o.directions.emplace_back(static_cast<Axis>(r), static_cast<Axis>(e));
    }
    const MessageSink tell = MessagePrinter(kTool);
    workflows::FrfSynthSetup setup =
        FromFields({{"adds", "--add"}, {"sets", "--set"}}, [&] { return workflows::PrepareFrfSynth(w, tell); });
    // The sample rate from the config is named with its file:line:col, and a
    // band the config's rate cannot hold (--fmax-hz not given) is the
    // config's mistake (65), not the command line's.
    if (!setup.sample_rate_at.empty()) {
      fields[0] = {"sample_rate_hz", setup.sample_rate_at + ": hammer_test.sample_rate_hz", true};
      for (FieldSource& f : fields) {
        if ((f.field == "fmax_hz" || f.field == "block_samples") && app.count(f.name) == 0) f.from_input = true;
      }
    }
    const workflows::FrfSynthRun run =
        FromFields(fields, [&] { return workflows::RunFrfSynth(w, std::move(setup), tell); });
    const dynamics::FrfSet& frfs = run.frfs;
    const int exit_code = ExitCodeFor(run.status());
    const io::FrfQuantity q = FromOption("--quantity", [&] { return io::ParseFrfQuantity(quantity); });
    workflows::WriteFrfSynthOutput(run, w, out_path, format, q, tell);
    if (!summary_path.empty()) {
      nlohmann::json j = run.Summary(w);
      j["tool"] = kTool;
      j["out"] = out_path;
      j["format"] = format == workflows::FrfFileFormat::kUff58 ? "uff58" : "csv";
      j["quantity"] = quantity;
      j["exit_code"] = exit_code;
      io::WriteFileAtomically(summary_path, SummaryText(j));
    }
    std::ostringstream msg;
    msg << kTool << ": wrote " << frfs.size() << " FRFs of " << calibration::HammerTestGrid(run.hammer).size()
        << " lines to " << out_path << '\n';
    std::cerr << msg.str();
    return exit_code;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
