// frf-synth: a virtual hammer test. Writes "measured" tool-tip FRFs of a
// robot model (effects and parameters as asked) at the postures of a posture
// file, on a hammer-test grid, with seeded noise, as CSV or UFF58.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cctype>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "cli_support.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/number_format.h"
#include "robomach/dynamics/frf_prediction.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "frf-synth";
// --noise-rel is a fraction of |H| (docs/plausibility.md): hammer tests show
// 0.1 to 10 %; above 50 % it is flagged (a percentage typed for a fraction:
// --noise-rel 2 for 2 %), above 1000 % nothing of the FRF is left: refused.
constexpr double kMaxPlausibleRelativeNoise = 0.5;
// Plausible ranges of the other options (docs/plausibility.md). Hammer tests
// of robots and machine tools: lines to 0.1 - 10 kHz, sampled at 1 - 200 kHz
// (Schmitz and Smith, "Machining Dynamics", ch. 2; the seed's 5120 Hz); hammer
// tips cut off at 0.5 kHz (soft) to 10 kHz and more (steel; PCB 086 series
// data sheets). Noise floors: tool-tip receptances are 1e-8 - 1e-5 m/N, a
// floor 1e-4 - 1e-2 of the peak (Ewins, "Modal Testing", §3); accelerometers
// resolve 1e-4 - 1e-2 m/s² under 10 - 1000 N impacts.
using dynamics::kMinPlausibleFmaxHz;
using dynamics::kMaxPlausibleFmaxHz;
constexpr double kMinPlausibleSampleRateHz = 100.0, kMaxPlausibleSampleRateHz = 1e6;
constexpr double kMinPlausibleHammerCutoffHz = 50.0, kMaxPlausibleHammerCutoffHz = 50000.0;
constexpr double kMaxPlausibleNoiseMPerN = 1e-6;        // receptance floor
constexpr double kMaxPlausibleNoiseMPerSPerN = 1e-3;    // mobility floor
constexpr double kMaxPlausibleNoiseMPerS2PerN = 10.0;   // accelerance floor
constexpr double kMaxFrequencyHz = 1e9;                 // refused above (exit 64)
constexpr double kMaxRelativeNoise = 10.0;

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
  std::string robot_path, postures_path, out_path, summary_path, directions = "xx,yy", quantity = "receptance";
  std::vector<std::string> sets, adds;
  calibration::VirtualHammerOptions o;
  double fs_hz = NAN;
  app.add_option("--robot", robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--postures", postures_path, "posture file CSV: pose_id,q1_deg..q6_deg")->required();
  app.add_option("--out", out_path, "output file: .csv (docs/formats.md §3) or .uff/.unv (UFF58 ASCII); '-' = stdout (CSV); another extension is refused (exit 64)")->required();
  app.add_option("--summary", summary_path,
                 "summary JSON (docs/formats.md §4.1): inputs, grid, noise, per FRF its peak; '-' = stdout");
  app.add_option("--set", sets, "override a model parameter, NAME=VALUE in its unit (e.g. m6_kg=31.5)");
  app.add_option("--add", adds, "switch on an effect by name with its default parameters (e.g. tip_mass)");
  app.add_option("--directions", directions, "response/excitation pairs, e.g. xx,yy,xy")->capture_default_str();
  app.add_option("--sample-rate-hz", fs_hz, "sampling frequency [Hz]; default: the config's hammer_test.sample_rate_hz, else 5120");
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
    // The format follows --out's extension: refuse one we do not write (a
    // .png would get CSV text).
    std::string ext = std::filesystem::path(out_path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const bool uff = ext == ".uff" || ext == ".unv" || ext == ".uf";
    if (out_path != "-" && !uff && ext != ".csv") {
      throw UsageError("--out " + out_path + ": expected a file name ending in .csv (the FRF CSV of docs/formats.md "
                       "§3) or .uff, .unv (UFF58), or '-' for standard output (CSV)");
    }
    CheckOptionRange("--block-samples", static_cast<double>(o.block_samples), 2, 1 << 22);
    CheckOptionRange("--averages", o.averages, o.coherence ? 2 : 1, 100000);
    if (std::isinf(o.relative_noise)) {  // "1e400" reads as infinity
      throw UsageError("--noise-rel " + FormatNumber(o.relative_noise, 7) +
                       ": expected a finite noise rms >= 0, as a fraction of the FRF (0.02 = 2 %)");
    }
    if (o.relative_noise > kMaxRelativeNoise) {
      throw UsageError("--noise-rel " + FormatNumber(o.relative_noise, 7) +
                       ": expected the noise as a fraction of the FRF (0.02 = 2 %), at most 10; the noise would bury "
                       "the FRF " + FormatNumber(o.relative_noise, 7) + " times over: for 2 % give --noise-rel 0.02");
    }
    std::vector<std::string> implausible;
    if (o.relative_noise > kMaxPlausibleRelativeNoise) {
      implausible.push_back("implausible (unit mistake?): --noise-rel " + FormatNumber(o.relative_noise, 7) +
                            " is a noise rms of " + FormatNumber(100.0 * o.relative_noise, 3) +
                            " % of the FRF; hammer tests have 0.1 to 10 % (plausible up to 50 %): a percentage typed "
                            "for a fraction? 2 % is --noise-rel 0.02");
    }
    // Impossible values (exit 64), then implausible ones (exit 3).
    for (const auto& [name, v] : {std::pair{"--fmax-hz", o.fmax_hz}, std::pair{"--hammer-cutoff-hz", o.hammer_cutoff_hz}}) {
      if (!(v >= 0.0 && v <= kMaxFrequencyHz)) {
        throw UsageError(std::string(name) + " " + FormatNumber(v, 7) + ": expected a frequency in [0, 1e9] Hz");
      }
    }
    if (std::isfinite(fs_hz) && !(fs_hz > 0.0 && fs_hz <= kMaxFrequencyHz)) {
      throw UsageError("--sample-rate-hz " + FormatNumber(fs_hz, 7) + ": expected a rate in (0, 1e9] Hz");
    }
    for (const auto& [name, v] : {std::pair{"--noise-abs-m-per-N", o.absolute_noise_m_per_N},
                                  std::pair{"--noise-abs-m-per-s-per-N", o.absolute_noise_m_per_s_per_N},
                                  std::pair{"--noise-abs-m-per-s2-per-N", o.absolute_noise_m_per_s2_per_N}}) {
      if (!(v >= 0.0) || !std::isfinite(v)) throw UsageError(std::string(name) + " " + FormatNumber(v, 7) + ": expected a noise rms >= 0");
    }
    const auto flag = [&](const std::string& m) {
      if (!m.empty()) implausible.push_back(m);
    };
    flag(ImplausibleOption("--fmax-hz", o.fmax_hz, kMinPlausibleFmaxHz, kMaxPlausibleFmaxHz, "Hz",
                           "hammer tests (lines to 0.1 - 10 kHz)", "a frequency in kHz typed in the Hz option?",
                           "a frequency in mHz typed in the Hz option, or a line count?"));
    if (std::isfinite(fs_hz)) {
      flag(ImplausibleOption("--sample-rate-hz", fs_hz, kMinPlausibleSampleRateHz, kMaxPlausibleSampleRateHz, "Hz",
                             "hammer-test acquisition (1 - 200 kHz)", "a rate in kHz typed in the Hz option?",
                             "a rate in mHz typed in the Hz option?"));
    }
    if (o.hammer_cutoff_hz > 0.0) {
      flag(ImplausibleOption("--hammer-cutoff-hz", o.hammer_cutoff_hz, kMinPlausibleHammerCutoffHz,
                             kMaxPlausibleHammerCutoffHz, "Hz", "hammer tips (0.5 - 10 kHz; 0: flat)",
                             "a frequency in kHz typed in the Hz option?", "a frequency in mHz typed in the Hz option?"));
    }
    flag(ImplausibleOption("--noise-abs-m-per-N", o.absolute_noise_m_per_N, 0.0, kMaxPlausibleNoiseMPerN, "m/N",
                           "receptance noise floors (tool tips are 1e-8 - 1e-5 m/N)", "",
                           "a noise in mm/N or um/N typed in the m/N option?"));
    flag(ImplausibleOption("--noise-abs-m-per-s-per-N", o.absolute_noise_m_per_s_per_N, 0.0, kMaxPlausibleNoiseMPerSPerN,
                           "(m/s)/N", "mobility noise floors", "", "a noise in (mm/s)/N typed in the (m/s)/N option?"));
    flag(ImplausibleOption("--noise-abs-m-per-s2-per-N", o.absolute_noise_m_per_s2_per_N, 0.0,
                           kMaxPlausibleNoiseMPerS2PerN, "(m/s²)/N",
                           "accelerance noise floors (accelerometers resolve 1e-4 - 1e-2 m/s² under 10 - 1000 N)", "",
                           "a noise in (mm/s²)/N typed in the (m/s²)/N option?"));
    RequireInputFile("--robot", robot_path, "robot config", {io::FileKind::kYaml}, io::kRobotConfigFormat);
    RequireInputFile("--postures", postures_path, "posture file", {io::FileKind::kCsv}, io::kPostureCsvFormat);
    CheckDistinctPaths({{"--robot", robot_path}, {"--postures", postures_path}},
                       {{"--out", out_path}, {"--summary", summary_path}});
    o.directions.clear();
    for (const auto& [r, e] : FromOption("--directions", [&] { return io::ParseDirectionPairs(directions); })) {
      o.directions.emplace_back(static_cast<Axis>(r), static_cast<Axis>(e));
    }
    io::RobotConfig cfg = LoadRobotConfigWarned(kTool, robot_path);
    ApplyAddsAndSets(adds, sets, &cfg);
    o.sample_rate_hz = std::isfinite(fs_hz) ? fs_hz : calibration::ConfiguredSampleRateHz(cfg.description);
    // The options through the library's check, named as the user gave them:
    // the sample rate from the config is named with its file:line:col, and a
    // band the config's rate cannot hold (--fmax-hz not given) is the
    // config's mistake (65), not the command line's.
    std::vector<FieldSource> fields = {
        {"sample_rate_hz", "--sample-rate-hz"}, {"block_samples", "--block-samples"}, {"fmin_hz", "--fmin-hz"},
        {"fmax_hz", "--fmax-hz"}, {"relative_noise", "--noise-rel"}, {"absolute_noise_m_per_N", "--noise-abs-m-per-N"},
        {"absolute_noise_m_per_s_per_N", "--noise-abs-m-per-s-per-N"},
        {"absolute_noise_m_per_s2_per_N", "--noise-abs-m-per-s2-per-N"}, {"hammer_cutoff_hz", "--hammer-cutoff-hz"},
        {"averages", "--averages"}, {"directions", "--directions"}};
    const auto fs_where = cfg.extra_value_locations.find("hammer_test.sample_rate_hz");
    if (!std::isfinite(fs_hz) && fs_where != cfg.extra_value_locations.end()) {
      fields[0] = {"sample_rate_hz", fs_where->second.ToString() + ": hammer_test.sample_rate_hz", true};
      for (FieldSource& f : fields) {
        if ((f.field == "fmax_hz" || f.field == "block_samples") && app.count(f.name) == 0) f.from_input = true;
      }
    }
    try {
      ValidateOptions(fields, [&] { calibration::CheckValid(o); });
    } catch (const std::invalid_argument& e) {
      // An implausible option (a rate in kHz) is the likely cause: say so.
      std::string why;
      for (const std::string& w : implausible) why += "; the likely cause, " + w;
      if (why.empty()) throw;
      if (dynamic_cast<const UsageError*>(&e)) throw UsageError(e.what() + why);
      throw std::invalid_argument(e.what() + why);
    }
    const auto model = cfg.Build();
    std::vector<calibration::NamedPosture> postures;
    std::vector<std::string> posture_units;  // radians under _deg headers, ...
    for (const io::Posture& p : io::ReadPostureFile(postures_path, model->num_joints(), &posture_units)) {
      postures.push_back({p.id, p.q});
    }
    for (const std::string& w : posture_units) Warn(kTool, w);
    // Before the summary is made: its `warnings` lists every one printed.
    for (const std::string& w : implausible) Warn(kTool, w);
    const int exit_code = implausible.empty() && posture_units.empty() && cfg.implausible.empty() ? kExitOk : kExitFlagged;
    const dynamics::FrfSet frfs = calibration::SynthesizeHammerTest(model, postures, o);
    const io::FrfQuantity q = FromOption("--quantity", [&] { return io::ParseQuantity(quantity); });
    if (uff && out_path != "-") {
      if (o.coherence && o.averages > 1) {
        Warn(kTool, "UFF58 has no field for the number of averages: give --averages " +
                        std::to_string(o.averages) + " to the tools that read " + out_path);
      }
      io::WriteUff58(out_path, frfs, q);
    } else {
      io::WriteFrfCsv(out_path, frfs, q, o.coherence ? o.averages : 0);
    }
    if (!summary_path.empty()) {
      nlohmann::json j;
      j["tool"] = kTool;
      j["robot"] = robot_path;
      j["postures"] = postures_path;
      j["sets"] = sets;
      j["adds"] = adds;
      j["out"] = out_path;
      j["format"] = out_path != "-" && uff ? "uff58" : "csv";
      j["quantity"] = quantity;
      j["sample_rate_hz"] = o.sample_rate_hz;
      j["block_samples"] = o.block_samples;
      j["line_spacing_hz"] = o.sample_rate_hz / o.block_samples;
      j["fmin_hz"] = o.fmin_hz;
      j["fmax_hz"] = o.fmax_hz;
      j["noise_rel"] = o.relative_noise;
      j["noise_abs_m_per_N"] = o.absolute_noise_m_per_N;
      j["noise_abs_m_per_s_per_N"] = o.absolute_noise_m_per_s_per_N;
      j["noise_abs_m_per_s2_per_N"] = o.absolute_noise_m_per_s2_per_N;
      j["hammer_cutoff_hz"] = o.hammer_cutoff_hz;
      j["averages"] = o.averages;
      j["coherence"] = o.coherence;
      j["seed"] = o.seed;
      j["frf_count"] = frfs.size();
      // Per FRF: the line of largest |H| (receptance, with the noise, as written).
      nlohmann::json list = nlohmann::json::array();
      for (const auto& [key, frf] : frfs) {
        Eigen::Index k = 0;
        const double peak = frf.receptance().cwiseAbs().maxCoeff(&k);
        list.push_back({{"pose_id", key.pose_id},
                        {"response", std::string(1, AxisName(key.response))},
                        {"excitation", std::string(1, AxisName(key.excitation))},
                        {"lines", frf.size()},
                        {"freq_min_hz", frf.freq_hz()(0)},
                        {"freq_max_hz", frf.freq_hz()(frf.size() - 1)},
                        {"peak_freq_hz", frf.freq_hz()(k)},
                        {"peak_receptance_m_per_N", peak}});
      }
      j["frfs"] = list;
      j["flagged"] = exit_code == kExitFlagged;
      j["exit_code"] = exit_code;
      io::WriteFileAtomically(summary_path, SummaryText(j));
    }
    std::ostringstream msg;
    msg << kTool << ": wrote " << frfs.size() << " FRFs of " << calibration::HammerTestGrid(o).size()
        << " lines to " << out_path << '\n';
    std::cerr << msg.str();
    return exit_code;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
