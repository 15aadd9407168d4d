// frf-predict: pose-dependent tool-tip FRFs, modes and plots of a robot
// model at the postures of a posture file.
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/number_format.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/frf_prediction.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/report/frf_plot.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "frf-predict";
// Postures x lines computed before anything is written (no partial outputs):
// 2e6 is a 100-posture campaign on a 20 000-line grid, about 1 GB of CSV
// with all nine direction pairs.
constexpr double kMaxFrfLines = 2e6;

Eigen::VectorXd ReadFrequencyFile(const std::string& path) {
  const io::CsvTable t = io::CsvTable::ReadFile(path);
  t.RequireColumn("freq_hz");
  Eigen::VectorXd f(t.num_rows());
  for (int r = 0; r < t.num_rows(); ++r) {
    f(r) = t.Number(r, "freq_hz");
    if (f(r) < 0.0) throw t.ErrorAt(r, "freq_hz", "expected a frequency >= 0");
    if (r > 0 && !(f(r) > f(r - 1))) {
      throw t.ErrorAt(r, "freq_hz", "frequencies must be strictly increasing");
    }
  }
  if (f.size() == 0) throw InputError({path, 0, 0}, "no frequency lines");
  return f;
}

report::Figure PostureFigure(const std::vector<const io::PosturePrediction*>& preds,
                             const std::vector<const dynamics::PostureDynamics*>& dyn,
                             const std::string& title,
                             const std::vector<const dynamics::ReceptanceBand*>& bands = {}) {
  report::Figure fig(static_cast<int>(preds.size()), 2, 760, 340);
  fig.title = title;
  for (size_t p = 0; p < preds.size(); ++p) {
    std::vector<report::FrfCurve> curves;
    for (int a = 0; a < 3; ++a) {
      report::FrfCurve c;
      c.freq_hz = preds[p]->freq_hz;
      c.receptance.resize(c.freq_hz.size());
      for (Eigen::Index i = 0; i < c.freq_hz.size(); ++i) c.receptance(i) = preds[p]->H[i](a, a);
      c.label = std::string("H") + "xyz"[a] + "xyz"[a];
      c.color = report::PaletteColor(a);
      if (p < bands.size() && bands[p]) {
        c.band_freq_hz = bands[p]->freq_hz;
        c.band_lower = bands[p]->lower[a];
        c.band_upper = bands[p]->upper[a];
      }
      curves.push_back(std::move(c));
    }
    std::vector<double> fn;
    for (const auto& m : dyn[p]->modes) fn.push_back(m.freq_hz);
    report::FillFrfPanels(curves, fn, "posture " + preds[p]->pose_id + ": tool-tip receptance",
                          &fig.at(static_cast<int>(p), 0), &fig.at(static_cast<int>(p), 1));
    fig.at(static_cast<int>(p), 1).title = "phase";
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
    Eigen::VectorXd freq_hz;
    if (!freq_file.empty()) {
      freq_hz = ReadFrequencyFile(freq_file);
    } else {
      if (!(fmin_hz >= 0.0) || !(fmax_hz > fmin_hz) || !(df_hz > 0.0) || !std::isfinite(fmax_hz) ||
          !std::isfinite(df_hz)) {
        throw UsageError("expected finite 0 <= --fmin-hz < --fmax-hz and --df-hz > 0, got --fmin-hz " +
                         FormatNumber(fmin_hz, 7) + ", --fmax-hz " + FormatNumber(fmax_hz, 7) + ", --df-hz " +
                         FormatNumber(df_hz, 7));
      }
      // Count in double first: a tiny step would overflow the integer.
      const double lines = std::floor((fmax_hz - fmin_hz) / df_hz + 1e-9) + 1.0;
      if (lines > dynamics::kMaxFrequencyLines) {
        std::string why = fmax_hz > dynamics::kMaxPlausibleFmaxHz
                              ? "; --fmax-hz " + FormatNumber(fmax_hz, 7) + " Hz is beyond the " +
                                    FormatNumber(dynamics::kMaxPlausibleFmaxHz, 7) +
                                    " Hz of hammer tests (a frequency in mHz, or a line count, typed in the Hz option?)"
                              : "";
        throw UsageError("--fmin-hz " + FormatNumber(fmin_hz, 7) + " to --fmax-hz " + FormatNumber(fmax_hz, 7) +
                         " in steps of --df-hz " + FormatNumber(df_hz, 7) + " is " + FormatNumber(lines, 7) +
                         " frequency lines, more than the " + FormatNumber(dynamics::kMaxFrequencyLines, 7) +
                         " allowed (FFT analysers give 400 - 25 600)" + why + ": raise --df-hz or lower --fmax-hz");
      }
      const long n = static_cast<long>(lines);
      freq_hz = Eigen::VectorXd::LinSpaced(n, fmin_hz, fmin_hz + (n - 1) * df_hz);
    }

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
    if (!unc.paths.empty() && modes_path.empty() && details_path.empty() && plot_path.empty() && plot_dir.empty()) {
      throw UsageError("--uncertainty gives the modes' intervals in --modes and --summary and the |H| bands in "
                       "--plot and --plot-dir: give one of them");
    }
    unc.Finish();
    const dynamics::PropagationOptions& uo = unc.propagation;
    io::RobotConfig cfg = LoadRobotConfigWarned(kTool, robot_path);
    ApplyAddsAndSets(adds, sets, &cfg);
    std::optional<dynamics::ParameterUncertainty> uncertainty;
    // The config's `uncertainty:` files serve the outputs that carry intervals.
    const std::vector<std::string> uncertainty_paths =
        unc.paths.empty() && modes_path.empty() && details_path.empty() && plot_path.empty() && plot_dir.empty()
            ? std::vector<std::string>{}
            : unc.PathsFor(cfg);
    if (!uncertainty_paths.empty()) {
      uncertainty = io::ReadParameterUncertainties(uncertainty_paths);
      for (const std::string& set : sets) {
        const std::string name = set.substr(0, set.find('='));
        for (const auto& up : uncertainty->parameters) {
          if (up.name == name) {
            throw UsageError("--set " + name + " and --uncertainty (" + uncertainty->source + ") both give " + name +
                             ": the file's estimate goes with its covariance; drop one of the two");
          }
        }
      }
      const std::string changed = dynamics::UseEstimates(*uncertainty, &cfg.parameters);
      if (!changed.empty()) Note(kTool, changed);
    }
    if (verbose) {
      for (const auto& s : cfg.parameters.specs()) {
        std::cerr << kTool << ": parameter " << s.name << " = " << cfg.parameters.Get(s.name) << " "
                  << s.unit << '\n';
      }
    }
    const auto model = cfg.Build();
    std::vector<std::string> posture_units;  // radians under _deg headers, ...
    const std::vector<io::Posture> postures =
        io::ReadPostureFile(postures_path, model->num_joints(), &posture_units);
    for (const std::string& w : posture_units) Warn(kTool, w);
    // Everything is computed before anything is written (no partial
    // outputs), so bound the memory: 3×3 complex values per line and posture.
    const double values = static_cast<double>(postures.size()) * static_cast<double>(freq_hz.size());
    // About 60 bytes per direction pair and line in the CSV (formats.md §3).
    const double csv_gb = values * static_cast<double>(pairs.size()) * 60e-9;
    if (values > kMaxFrfLines) {
      throw UsageError(std::to_string(postures.size()) + " postures × " + std::to_string(freq_hz.size()) +
                       " frequency lines is more than " + FormatNumber(kMaxFrfLines, 7) + " FRF lines (a CSV of about " +
                       FormatNumber(csv_gb, 2) + " GB): split the posture file or coarsen the grid");
    }

    std::vector<dynamics::NamedPosture> named;
    for (const io::Posture& p : postures) named.push_back({p.id, p.q});
    ProgressLine progress(kTool, "postures", static_cast<long>(postures.size()));
    dynamics::PredictOptions po;
    po.method = dynamics::ParseReceptanceMethod(method);
    po.progress = [&](long done, long) { progress.Update(done); };
    dynamics::FrfPredictionResult result = dynamics::PredictFrfs(model, named, freq_hz, po);
    progress.Finish();
    for (const Finding& f : result.findings) {
      Warn(kTool, postures_path + ":" + std::to_string(postures[f.input_index].line) + ": " + f.message);
    }
    std::vector<io::PosturePrediction> preds;
    std::vector<dynamics::PostureDynamics> dyns;
    for (dynamics::PosturePredictionResult& r : result.postures) {
      preds.push_back({r.id, freq_hz, std::move(r.H)});
      dyns.push_back(std::move(r.dynamics));
    }

    // The intervals and bands are computed before any output is written.
    std::vector<dynamics::PostureModeIntervals> intervals;
    if (uncertainty) {
      ProgressLine up(kTool, "postures' intervals", static_cast<long>(postures.size()));
      for (size_t p = 0; p < postures.size(); ++p) {
        intervals.push_back(dynamics::ModalIntervals(cfg.description, cfg.parameters, postures[p].q, *uncertainty, uo));
        up.Update(static_cast<long>(p + 1));
      }
      up.Finish();
      for (size_t p = 0; p < postures.size(); ++p) {
        std::cerr << kTool << ": " << dynamics::IntervalLine(postures[p].id, intervals[p], uo.confidence) << '\n';
      }
    }
    // The |H| bands of the postures drawn (issue #37 §3).
    std::vector<dynamics::ReceptanceBand> bands;
    std::string band_title;
    if (uncertainty && (!plot_path.empty() || !plot_dir.empty())) {
      const size_t drawn = plot_dir.empty() ? std::min<size_t>(preds.size(), 12) : preds.size();
      ProgressLine bp(kTool, "|H| bands", static_cast<long>(drawn));
      for (size_t p = 0; p < drawn; ++p) {
        bands.push_back(dynamics::DirectReceptanceBand(cfg.description, cfg.parameters, postures[p].q, *uncertainty,
                                                       preds[p].freq_hz, uo));
        bp.Update(static_cast<long>(p + 1));
      }
      bp.Finish();
      std::cerr << kTool << ": the plots show the " << FormatNumber(100.0 * uo.confidence, 3) << " % band of |H| ("
                << dynamics::ToString(bands.front().propagation.method_used) << ": "
                << bands.front().propagation.reason << ")\n";
      band_title = " (" + FormatNumber(100.0 * uo.confidence, 3) + " % band)";
    }
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
    for (size_t p = 0; p < postures.size(); ++p) {
      ids.push_back(postures[p].id);
      modes.push_back(dyns[p].modes);
    }
    if (!modes_path.empty()) io::WriteModalTableCsv(modes_path, ids, modes, uncertainty ? &intervals : nullptr);
    if (!details_path.empty()) {
      nlohmann::json j;
      j["robot"] = robot_path;
      nlohmann::json params;
      for (const auto& s : model->parameters().specs()) params[s.name] = model->parameters().Get(s.name);
      j["parameters"] = params;
      j["postures"] = nlohmann::json::array();
      for (size_t p = 0; p < postures.size(); ++p) {
        j["postures"].push_back(io::PostureToJson(ids[p], dyns[p]));
        if (uncertainty) j["postures"].back()["mode_intervals"] = io::ModeIntervalsToJson(intervals[p]);
      }
      if (uncertainty) {
        j["uncertainty"] = {{"files", uncertainty_paths},
                            {"confidence", uo.confidence},
                            {"method", unc.method},
                            {"parameters", io::ParameterUncertaintyToJson(*uncertainty)}};
      }
      io::WriteFileAtomically(details_path, SummaryText(j));
    }
    std::string title = "robomach frf-predict: " + robot_path;
    for (const auto& e : model->effects()) title += " + " + e.effect->name();
    title += band_title;
    const auto band_of = [&](size_t p) -> const dynamics::ReceptanceBand* {
      return p < bands.size() ? &bands[p] : nullptr;
    };
    if (!plot_path.empty()) {
      constexpr size_t kMaxSheet = 12;
      std::vector<const io::PosturePrediction*> pp;
      std::vector<const dynamics::PostureDynamics*> dd;
      std::vector<const dynamics::ReceptanceBand*> bb;
      for (size_t p = 0; p < std::min(preds.size(), kMaxSheet); ++p) {
        pp.push_back(&preds[p]);
        dd.push_back(&dyns[p]);
        bb.push_back(band_of(p));
      }
      if (preds.size() > kMaxSheet) {
        Warn(kTool, "the sheet shows the first 12 of " + std::to_string(preds.size()) +
                        " postures; use --plot-dir for one picture per posture");
      }
      PostureFigure(pp, dd, title, bb).SavePng(plot_path);
    }
    if (!plot_dir.empty()) {
      io::EnsureDirectory(plot_dir);
      std::vector<std::string> ids;
      for (const auto& pred : preds) ids.push_back(pred.pose_id);
      const std::map<std::string, std::string> stems = FileStemsForIds(kTool, "--plot-dir", ids);
      for (size_t p = 0; p < preds.size(); ++p) {
        PostureFigure({&preds[p]}, {&dyns[p]}, title, {band_of(p)})
            .SavePng((std::filesystem::path(plot_dir) / (stems.at(preds[p].pose_id) + ".png")).string());
      }
    }
    return posture_units.empty() && cfg.implausible.empty() && implausible_options.empty() ? ExitCodeFor(result.status()) : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
