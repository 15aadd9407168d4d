// frf-estimate: tool-tip FRFs (H1 or H2, with coherence) from raw
// impact-hammer time records, averaged over hits, with force and
// exponential windows; double hits and overloads are rejected by name
// (issue #18, item 4; docs/frf-estimate.md).
#include <CLI/CLI.hpp>

#include <cmath>

#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "robomach/common/number_format.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/frf_files.h"
#include "robomach/report/plot.h"
#include "robomach/report/json.h"
#include "robomach/workflows/frf_estimate.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "frf-estimate";

void SavePlot(const std::string& path, const workflows::FrfEstimateRun& run, io::FrfQuantity quantity,
              const std::string& estimator) {
  const calibration::FrfEstimateResult& r = run.result;
  report::Figure fig(2, 1, 1000, 400);
  fig.title = "frf-estimate: " + estimator + " of " + std::to_string(r.averages) + " hits";
  if (r.exponential_tau_s > 0.0) {
    fig.title += ", exponential window tau = " + FormatNumber(r.exponential_tau_s, 3) + " s (adds damping)";
  }
  report::Axes& mag = fig.at(0, 0);
  report::Axes& coh = fig.at(1, 0);
  mag.title = "|" + estimator + "| (" + io::ToString(quantity) + ")";
  mag.x_label = "frequency [Hz]";
  mag.y_label = "|H| [" + io::QuantityUnit(quantity) + "]";
  mag.log_y = true;
  coh.title = "coherence";
  coh.x_label = "frequency [Hz]";
  coh.y_label = "gamma^2 [-]";
  coh.y_min = 0.0;
  coh.y_max = 1.05;
  coh.legend = report::Axes::LegendPosition::kBottomLeft;
  int i = 0;
  for (const auto& [key, frf] : run.frfs->frfs) {
    report::Series m, c;
    for (int k = 0; k < frf.size(); ++k) {
      const double f = frf.freq_hz()(k);
      const double v = std::abs(io::FromReceptance(quantity, f, frf.receptance()(k)));
      if (!(v > 0.0)) continue;
      m.x.push_back(f);
      m.y.push_back(v);
    }
    const Eigen::VectorXd& g = r.channels[run.frfs->channel_of[i]].coherence;  // on r.freq_hz
    c.x.assign(r.freq_hz.data(), r.freq_hz.data() + g.size());
    c.y.assign(g.data(), g.data() + g.size());
    m.label = c.label = run.frfs->labels[i];
    m.color = c.color = report::PaletteColor(i);
    m.thickness = c.thickness = 1;
    mag.series.push_back(std::move(m));
    coh.series.push_back(std::move(c));
    ++i;
  }
  coh.series.push_back({.x = {r.freq_hz(0), r.freq_hz(r.freq_hz.size() - 1)}, .y = {0.9, 0.9}, .label = "0.9",
                        .color = {150, 150, 150}, .thickness = 1, .dashed = true});
  fig.SavePng(path);
}

int Run(int argc, char** argv) {
  CLI::App app{
      "frf-estimate: tool-tip FRFs from raw impact-hammer time records (docs/frf-estimate.md).\n"
      "Input CSV: time_s, force_N, one or more responses named by unit (<name>_m displacement,\n"
      "<name>_m_per_s velocity, <name>_m_per_s2 acceleration), and an optional hit column (else one\n"
      "file per hit), or UFF58 time records. Per response: H1 = Gfx/Gff (or H2 = Gxx/Gxf) averaged over the accepted hits,\n"
      "with the coherence, written as the FRF CSV of docs/formats.md section 3 (re-readable by\n"
      "frf-calibrate and model-audit) with '# averages: N' and the windows as metadata.\n"
      "Hits with a second force pulse (double hit) or a clipped/over-range channel (overload) are\n"
      "rejected and named on stderr and in --summary, never averaged."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             "\n3 here: fewer accepted hits than --min-hits, or a response that has not decayed by the end of its "
             "record (leakage), or a receptance outside 1e-12..1e-3 m/N (a unit mistake in a column name). 65 also: every hit rejected (the FRF file is then not written; --summary is).\n");
  // The options go straight into the workflow's fields (their defaults are the tool's).
  workflows::FrfEstimateRunOptions w;
  calibration::FrfEstimateOptions& o = w.estimate;
  std::vector<std::string> directions;
  std::string out_path, summary_path, plot_path, quantity = "receptance";
  app.add_option("records", w.record_paths,
                 "hammer record file(s): CSV, or UFF58 time records (function type 1: per hit the force record, "
                 "then its response records; docs/formats.md section 10.1)")->required();
  app.add_option("--out", out_path, "output FRF CSV (docs/formats.md section 3); '-' = stdout")->required();
  app.add_option("--pose-id", w.pose_id, "pose id written in the FRF file")->capture_default_str();
  app.add_option("--excitation", w.excitation, "hammer direction at the tool tip: x, y or z")->capture_default_str();
  app.add_option("--direction", directions,
                 "response direction per channel, NAME=AXIS (e.g. acc_tip=y); default from a name ending in "
                 "_x/_y/_z (or named x/y/z)");
  app.add_option("--quantity", quantity, "output quantity: receptance, mobility or accelerance")
      ->check(OneOf({"receptance", "mobility", "accelerance"}))
      ->capture_default_str();
  app.add_option("--estimator", w.estimator, "h1 (noise on the response) or h2 (noise on the force)")
      ->check(OneOf({"h1", "h2"}))
      ->capture_default_str();
  app.add_option("--fmax-hz", o.fmax_hz, "highest line written [Hz]; 0: sample rate / 2.56; above the Nyquist frequency (sample rate / 2): "
                 "exit 64, as frf-synth")->capture_default_str();
  app.add_option("--force-window-s", o.force_window_s,
                 "force window length after the hit [s]; 0: automatic (3 pulse lengths + 32 samples); "
                 "negative: no force window")
      ->capture_default_str();
  app.add_option("--force-window-pre-s", o.force_window_pre_s,
                 "force window lead before the hit [s]; 0: automatic (16 samples)")->capture_default_str();
  app.add_option("--force-window-taper-s", o.force_window_taper_s,
                 "cosine taper at each end of the force window [s]; 0: automatic (8 samples)")->capture_default_str();
  app.add_option("--exp-window-tau-s", o.exponential_tau_s,
                 "exponential window exp(-t/tau) from the hit on force and responses [s]; 0: none. Adds "
                 "1/(tau*omega_n) to every damping ratio (recorded in the output; see the docs); under 4 sample periods: "
                 "exit 64")
      ->capture_default_str();
  app.add_option("--double-hit-fraction", o.double_hit_fraction,
                 "a force sample outside the main pulse above this fraction of its peak is a double hit [-]")
      ->capture_default_str();
  app.add_option("--trigger-fraction", o.trigger_fraction,
                 "the pulse starts and ends where |force| crosses this fraction of the peak [-]")
      ->capture_default_str();
  app.add_option("--flat-top-samples", o.flat_top_samples,
                 "overload: this many consecutive samples at a channel's extreme value (clipping)")
      ->capture_default_str();
  app.add_option("--force-range-N", o.force_range_N, "overload: |force| at or beyond this [N]; 0: unknown")
      ->capture_default_str();
  std::vector<std::string> response_ranges;
  app.add_option("--response-range", response_ranges,
                 "overload: |response| at or beyond this, NAME=VALUE in the channel's SI unit (m, m/s or m/s^2), "
                 "e.g. acc_y=490 for a 50 g accelerometer; repeat per channel");
  app.add_option("--min-hits", w.min_hits, "fewer accepted hits than this: exit 3 (at least 1)")->capture_default_str();
  app.add_option("--summary", summary_path, "JSON summary: hits with status and notes, windows, warnings");
  app.add_option("--plot", plot_path, "PNG of |H| and the coherence")->check(PngFileName());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    const std::vector<FieldSource> fields = {
        {"force_window_s", "--force-window-s"},       {"force_window_pre_s", "--force-window-pre-s"},
        {"force_window_taper_s", "--force-window-taper-s"}, {"exponential_tau_s", "--exp-window-tau-s"},
        {"fmax_hz", "--fmax-hz"},                     {"trigger_fraction", "--trigger-fraction"},
        {"double_hit_fraction", "--double-hit-fraction"}, {"flat_top_samples", "--flat-top-samples"},
        {"force_range_N", "--force-range-N"},         {"response_range", "--response-range"},
        {"directions", "--direction"},                {"excitation", "--excitation"},
        {"estimator", "--estimator"},                 {"min_hits", "--min-hits"}};
    w.min_hits_name = "--min-hits";
    w.directions = FromFields(fields, [&] { return workflows::ParseDirections(directions); });
    for (const std::string& text : response_ranges) {
      const auto [name, value] = ParseAssignment("--response-range", text);
      w.response_ranges[name] = value;
    }
    ValidateOptions(fields, [&] { w.Validate(); });
    std::vector<std::pair<std::string, std::string>> inputs;
    for (const std::string& r : w.record_paths) {
      RequireReadableFile(r, "hammer record file");
      inputs.push_back({"records", r});
    }
    CheckDistinctPaths(inputs, {{"--out", out_path}, {"--summary", summary_path}, {"--plot", plot_path}});
    const io::FrfQuantity out_q = FromOption("--quantity", [&] { return io::ParseFrfQuantity(quantity); });
    // An OptionError's field as the option (exit 64).
    const workflows::FrfEstimateRun run = FromFields(fields, [&] { return workflows::RunFrfEstimate(w, MessagePrinter(kTool)); });
    const calibration::FrfEstimateResult& r = run.result;
    const int rc = run.every_hit_rejected() ? kExitDataError : ExitCodeFor(run.verdict.status());
    if (run.frfs) {
      io::WriteEstimatedFrfCsv(out_path, run.frfs->frfs, out_q, r.averages, run.frfs->metadata);
      if (!plot_path.empty()) {
        SavePlot(plot_path, run, out_q, w.estimator == "h1" ? "H1" : "H2");
      }
    }
    if (!summary_path.empty()) {
      nlohmann::json j = run.Summary(w.estimator);
      j["tool"] = kTool;
      j["records"] = w.record_paths;
      j["exit_code"] = rc;
      io::WriteFileAtomically(summary_path, report::DumpJson(j));
    }
    if (run.every_hit_rejected()) {
      std::cerr << kTool << ": every hit was rejected; no FRF written to " << out_path << '\n';
      CommitOutputsNow();  // the summary says why (exit 65 otherwise writes nothing)
      return rc;
    }
    std::cerr << kTool << ": " << run.Outcome() << ", written to " << out_path << '\n';
    return rc;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
