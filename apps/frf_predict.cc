// frf-predict: pose-dependent tool-tip FRFs, modes and plots of a robot
// model at the postures of a posture file.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>

#include "cli_support.h"
#include "robomach/common/number_format.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/report/frf_plot.h"
#include "robomach/report/json.h"
#include "robomach/workflows/frf_predict.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "frf-predict";
// The postures `which` of the run, one row each: magnitude (with the |H|
// band when the run has one) and phase.
report::Figure PostureFigure(const workflows::FrfPredictRun& run, const std::vector<size_t>& which,
                             const std::string& title) {
  report::Figure fig(static_cast<int>(which.size()), 2, 760, 340);
  fig.title = title;
  for (size_t row = 0; row < which.size(); ++row) {
    const size_t p = which[row];
    const io::PosturePrediction& pred = run.predictions[p];
    std::vector<report::FrfCurve> curves;
    for (int a = 0; a < 3; ++a) {
      report::FrfCurve c;
      c.freq_hz = pred.freq_hz;
      c.receptance.resize(c.freq_hz.size());
      for (Eigen::Index i = 0; i < c.freq_hz.size(); ++i) c.receptance(i) = pred.H[i](a, a);
      c.label = std::string("H") + "xyz"[a] + "xyz"[a];
      c.color = report::PaletteColor(a);
      if (p < run.bands.size()) {
        c.band_freq_hz = run.bands[p].freq_hz;
        c.band_lower = run.bands[p].lower[a];
        c.band_upper = run.bands[p].upper[a];
      }
      curves.push_back(std::move(c));
    }
    std::vector<double> fn;
    for (const auto& m : run.dynamics[p].modes) fn.push_back(m.freq_hz);
    report::FillFrfPanels(curves, fn, "posture " + pred.pose_id + ": tool-tip receptance",
                          &fig.at(static_cast<int>(row), 0), &fig.at(static_cast<int>(row), 1));
    fig.at(static_cast<int>(row), 1).title = "phase";
  }
  return fig;
}

int Run(int argc, char** argv) {
  CLI::App app{
      "frf-predict: pose-dependent tool-tip frequency response of a robot model.\n"
      "Reads a robot config and a posture file (docs/formats.md §1); writes the 3x3 tool-tip\n"
      "receptance per posture (docs/formats.md §3), the modal table (§4), per-posture details\n"
      "(JSON) and plots (PNG)."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp());
  std::string robot_path, postures_path, out_path, modes_path, plot_path, plot_dir, details_path,
      freq_file, directions = "all", method = "modal";
  double fmin_hz = 0.625, fmax_hz = 500.0, df_hz = 0.625;
  std::vector<std::string> sets, adds;
  UncertaintyCli unc;
  bool verbose = false;
  app.add_option("--robot", robot_path, "robot config YAML (e.g. config/kr210.yaml)")->required();
  app.add_option("--postures", postures_path, "posture file CSV: pose_id,q1_deg..q6_deg")->required();
  app.add_option("--out", out_path,
                 "predicted FRFs, CSV receptance [m/N]; '-' = stdout; if omitted: stdout when no other output "
                 "(--plot, --plot-dir, --modes, --summary) is given, else not written");
  app.add_option("--modes", modes_path, "modal table CSV: freq_hz, damping_ratio, modal_mass_kg, ux,uy,uz");
  app.add_option("--summary,--details", details_path, "summary JSON per posture ('-' = stdout; --details is the old name): J, cond(J), M_q, K_q, C_q, Cartesian M, K, C, compliance, modes");
  app.add_option("--plot", plot_path, "one PNG sheet with all postures (magnitude and phase)")->check(PngFileName());
  app.add_option("--plot-dir", plot_dir, "folder for one PNG per posture (<pose_id>.png)");
  app.add_option("--fmin-hz", fmin_hz, "lowest frequency line [Hz]")->capture_default_str();
  app.add_option("--fmax-hz", fmax_hz, "highest frequency line [Hz]")->capture_default_str();
  app.add_option("--df-hz", df_hz, "frequency step [Hz]")->capture_default_str();
  app.add_option("--freq-file", freq_file, "CSV with a freq_hz column; replaces --fmin-hz/--fmax-hz/--df-hz");
  app.add_option("--directions", directions,
                 "response/excitation pairs to write, e.g. xx,yy,xy, or 'all'")->capture_default_str();
  app.add_option("--method", method, "modal (superposition) or direct (solve per line)")
      ->check(OneOf({"modal", "direct"}))->capture_default_str();
  app.add_option("--set", sets, "override a model parameter, NAME=VALUE in its unit (e.g. m6_kg=30.2)");
  app.add_option("--add", adds, "switch on an effect by name with its default parameters (e.g. tip_mass)");
  AddUncertaintyOptions(app, &unc, "--modes and --summary gain each mode's interval");
  app.add_flag("--verbose", verbose, "list model parameters and ignored input columns on stderr");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }

  return RunGuarded(kTool, [&]() -> int {
    RequireFolderOption("--plot-dir", plot_dir);
    RequireInputFile("--robot", robot_path, "robot config", {io::FileKind::kYaml}, io::kRobotConfigFormat);
    RequireInputFile("--postures", postures_path, "posture file", {io::FileKind::kCsv}, io::kPostureCsvFormat);
    if (!freq_file.empty()) RequireReadableFile(freq_file, "frequency file");
    CheckDistinctPaths({{"--robot", robot_path}, {"--postures", postures_path}, {"--freq-file", freq_file}},
                       {{"--out", out_path}, {"--modes", modes_path}, {"--summary", details_path},
                        {"--plot", plot_path}},
                       {{"--plot-dir", plot_dir}});
    const io::DirectionPairs pairs = FromOption("--directions", [&] { return io::ParseDirectionPairs(directions); });
    workflows::FrfPredictOptions o;
    o.robot_path = robot_path;
    o.postures_path = postures_path;
    o.freq_hz = !freq_file.empty() ? workflows::ReadFrequencyFile(freq_file)
                                   : FromFields({{"fmin_hz", "--fmin-hz"}, {"fmax_hz", "--fmax-hz"}, {"df_hz", "--df-hz"}},
                                                [&] { return workflows::FrequencyGrid(fmin_hz, fmax_hz, df_hz); });
    const Eigen::VectorXd& freq_hz = o.freq_hz;
    // A band far beyond any hammer test is a unit mistake (docs/plausibility.md).
    std::vector<std::string> implausible_options;
    if (freq_hz.size() > 0) {
      const std::string m = ImplausibleOption(
          "--fmax-hz", freq_file.empty() ? fmax_hz : freq_hz.maxCoeff(), dynamics::kMinPlausibleFmaxHz, dynamics::kMaxPlausibleFmaxHz, "Hz",
          "hammer tests (lines to 0.1 - 10 kHz; robot modes below 2 kHz)", "a frequency in kHz typed in the Hz option?",
          "a frequency in mHz typed in the Hz option?");
      if (!m.empty()) {
        implausible_options.push_back(m);
        Warn(kTool, freq_file.empty() ? m : m + " (the highest line of " + freq_file + ")");
      }
    }
    const bool carries_intervals = !modes_path.empty() || !details_path.empty() || !plot_path.empty() || !plot_dir.empty();
    if (!unc.paths.empty() && !carries_intervals) {
      throw UsageError("--uncertainty gives the modes' intervals in --modes and --summary and the |H| bands in "
                       "--plot and --plot-dir: give one of them");
    }
    unc.Finish();
    o.method = method;
    o.adds = adds;
    o.sets = sets;
    o.uncertainty_paths = unc.paths;
    o.uncertainty = unc.propagation;
    o.intervals = carries_intervals;
    o.band_postures = plot_path.empty() && plot_dir.empty() ? 0 : plot_dir.empty() ? 12 : SIZE_MAX;
    o.direction_pairs = pairs.size();
    StageProgressLines progress(kTool);
    const workflows::FrfPredictRun run =
        FromFields({{"adds", "--add"}, {"sets", "--set"}, {"uncertainty_paths", "--uncertainty"}, {"postures_path", "--postures"}},
                   [&] { return workflows::RunFrfPredict(o, progress.Messages(MessagePrinter(kTool)), progress.Callback()); });
    progress.Finish();
    if (verbose) {
      for (const auto& s : run.config.parameters.specs()) {
        std::cerr << kTool << ": parameter " << s.name << " = " << run.config.parameters.Get(s.name) << " " << s.unit << '\n';
      }
    }
    const std::vector<io::PosturePrediction>& preds = run.predictions;
    // Every output is complete before it appears (docs/formats.md §4).
    // Without --out the FRF CSV goes to stdout only when nothing else was
    // asked for: `--plot p.png` alone must not pour megabytes of CSV into
    // the terminal (issue #35).
    const bool other_outputs = !plot_path.empty() || !plot_dir.empty() || !modes_path.empty() || !details_path.empty();
    if (!out_path.empty() || !other_outputs) {
      io::WritePredictedFrfCsv(out_path.empty() ? "-" : out_path, preds, pairs);
    } else {
      Note(kTool, "no --out: the FRF CSV is not written, only the outputs asked for (give --out FILE, or --out - "
                  "for standard output)");
    }
    std::vector<std::string> ids;
    std::vector<std::vector<dynamics::Mode>> modes;
    for (size_t p = 0; p < run.postures.size(); ++p) {
      ids.push_back(run.postures[p].id);
      modes.push_back(run.dynamics[p].modes);
    }
    if (!modes_path.empty()) io::WriteModalTableCsv(modes_path, ids, modes, run.uncertainty ? &run.intervals : nullptr);
    if (!details_path.empty()) io::WriteFileAtomically(details_path, SummaryText(run.Summary(o, unc.method)));
    std::string title = "robomach frf-predict: " + robot_path;
    for (const auto& e : run.model->effects()) title += " + " + e.effect->name();
    if (!run.bands.empty()) title += " (" + FormatNumber(100.0 * unc.propagation.confidence, 3) + " % band)";
    if (!plot_path.empty()) {
      constexpr size_t kMaxSheet = 12;
      std::vector<size_t> first;
      for (size_t p = 0; p < std::min(preds.size(), kMaxSheet); ++p) first.push_back(p);
      if (preds.size() > kMaxSheet) {
        Warn(kTool, "the sheet shows the first 12 of " + std::to_string(preds.size()) +
                        " postures; use --plot-dir for one picture per posture");
      }
      PostureFigure(run, first, title).SavePng(plot_path);
    }
    if (!plot_dir.empty()) {
      io::EnsureDirectory(plot_dir);
      const std::map<std::string, std::string> stems = FileStemsForIds(kTool, "--plot-dir", ids);
      for (size_t p = 0; p < preds.size(); ++p) {
        PostureFigure(run, {p}, title)
            .SavePng((std::filesystem::path(plot_dir) / (stems.at(preds[p].pose_id) + ".png")).string());
      }
    }
    return run.unit_findings.empty() && implausible_options.empty() ? ExitCodeFor(run.prediction_status) : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
