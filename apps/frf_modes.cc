// frf-modes: modal parameter estimation of measured FRFs (issue #34 §3):
// the FRFs of a posture fitted together with common poles (or each alone),
// the modal table stability-lobes reads, the modal constants (mode shapes),
// stabilisation diagrams and fit overlays with the noise band
// (docs/frf-modes.md). The work is calibration::AnalyseModes.
#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "measured_data.h"
#include "robomach/calibration/modal_analysis.h"
#include "robomach/io/frf_quantity.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/modal_analysis_files.h"
#include "robomach/io/number_format.h"
#include "robomach/report/json.h"
#include "robomach/report/modal_fit_plot.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "frf-modes";

int Run(int argc, char** argv) {
  CLI::App app{
      "frf-modes: modal parameters of measured FRFs (CSV of docs/formats.md §3 or UFF58). The FRFs of one\n"
      "posture share their poles and are fitted together: LSCF to high orders, stable poles clustered across\n"
      "orders, residues per FRF, poles refined on all FRFs with the noise model's weights. Writes the modal\n"
      "table (formats.md §4, what stability-lobes --modal-table reads), the modal constants of every FRF\n"
      "(mode shapes), and per posture a picture of the stabilisation diagram and the fits (docs/frf-modes.md)."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             "\nExit 3: outputs written, but flagged: a fit found no stable mode, the band holds no usable line "
             "of an FRF, an FRF is fitted worse than 3 x its noise, a measured receptance is outside the plausible "
             "range, or the FRFs of a posture could not be fitted together (see the warnings, also in the summary).");
  std::vector<std::string> measured_files, pose_files;
  std::string out_path, constants_path, shapes_path, summary_path, plot_dir;
  calibration::ModalAnalysisOptions opt;
  NoiseCliOptions noise_opt;
  app.add_option("--measured", measured_files,
                 "measured FRF file (CSV or UFF58; UFF records that name no posture are posture P1); repeatable");
  app.add_option("--pose", pose_files, "ID=file.uff: a UFF58 file whose records name no posture; repeatable");
  app.add_option("--fmin-hz", opt.fit.fmin_hz, "lower end of the band to fit [Hz]")->capture_default_str();
  app.add_option("--fmax-hz", opt.fit.fmax_hz, "upper end of the band to fit [Hz] (default: the whole FRF)");
  app.add_option("--max-order", opt.fit.max_order,
                 "highest LSCF order of the stabilisation diagram (number of poles)")
      ->capture_default_str();
  std::string weights = "noise";
  app.add_option("--weights", weights,
                 "noise: 1/sigma of the noise model (the fit to within the noise), and where the fit leaves more than "
                 "twice the noise a model error white in the file's quantity added to sigma; quantity: every line of "
                 "the file's quantity alike (the unweighted least squares of modal software, which favours the peaks)")
      ->check(OneOf({"noise", "quantity"}))
      ->capture_default_str();
  app.add_flag("--per-frf", opt.per_frf, "fit each FRF alone (its own poles) instead of one set per posture");
  AddNoiseOptions(app, &noise_opt);
  app.add_option("--out", out_path,
                 "modal table CSV (pose_id,mode,freq_hz,damping_ratio,modal_mass_kg,ux,uy,uz,directions); '-' = "
                 "stdout")
      ->required();
  app.add_option("--modal-constants", constants_path,
                 "CSV of every FRF's modal constant and mode-shape component per mode");
  app.add_option("--mode-shapes", shapes_path,
                 "CSV of the mode shapes of a roving test (FRFs numbered by point: UFF nodes, or the "
                 "response_point/excitation_point columns of formats.md §3), mass-normalised if the test has a "
                 "driving point");
  app.add_option("--summary", summary_path, "JSON summary (modes, misfit per FRF, warnings)");
  app.add_option("--plot-dir", plot_dir, "folder for modes_<pose>.png (stabilisation diagram and fits)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    opt.weights_in_file_quantity = weights == "quantity";
    // The noise model's pass about a modal fit uses this tool's own fitter
    // (calibration::NoiseOptions::global_modal_fit).
    noise_opt.global_modal_fit = true;
    if (measured_files.empty() && pose_files.empty()) throw UsageError("give at least one --measured or --pose file");
    CheckOptionRange("--fmin-hz", opt.fit.fmin_hz, 0.0, 1e7);
    if (!std::isinf(opt.fit.fmax_hz)) CheckOptionRange("--fmax-hz", opt.fit.fmax_hz, opt.fit.fmin_hz, 1e7);
    if (!(opt.fit.fmax_hz > opt.fit.fmin_hz)) throw UsageError("--fmax-hz " + FormatDouble(opt.fit.fmax_hz) + ": expected a value above --fmin-hz " + FormatDouble(opt.fit.fmin_hz));
    CheckOptionRange("--max-order", opt.fit.max_order, 8, 400);
    std::vector<std::pair<std::string, std::string>> inputs;
    for (const auto& f : measured_files) inputs.push_back({"--measured", f});
    for (const auto& f : pose_files) inputs.push_back({"--pose", f.substr(f.find('=') + 1)});
    CheckDistinctPaths(inputs,
                       {{"--out", out_path}, {"--modal-constants", constants_path}, {"--mode-shapes", shapes_path},
                        {"--summary", summary_path}},
                       {{"--plot-dir", plot_dir}});
    // A UFF record that names no posture is posture P1 here (frf-modes
    // needs none; frf-calibrate's --pose P1=file.uff still works); a
    // posture the file names wins, and a CSV always names its own.
    const MeasuredData all =
        ReadMeasuredFiles(kTool, measured_files, pose_files, "measured FRF file", "--pose", true, "P1");
    const calibration::NoiseModels noise = EstimateNoiseModels(kTool, all, noise_opt);
    int power = 0;
    std::string quantity = "receptance";
    if (!all.file_power.empty()) {
      power = all.file_power.begin()->second;
      quantity = io::ToString(static_cast<io::FrfQuantity>(power));
      for (const auto& [key, p] : all.file_power) {
        if (p != power) {
          Warn(kTool, "the files hold different quantities; misfits are reported as " + quantity);
          break;
        }
      }
    }
    const int n_poses = static_cast<int>(all.frfs.pose_ids().size());
    ProgressLine progress(kTool, "postures", n_poses, 2);
    std::vector<calibration::PoseModes> poses;
    {
      int done = 0;
      for (const std::string& pose : all.frfs.pose_ids()) {
        auto one = calibration::AnalyseModes(all.frfs.ForPose(pose), noise, opt, power);
        for (auto& p : one) poses.push_back(std::move(p));
        progress.Update(++done);
      }
    }
    progress.Finish();
    bool flagged = !all.unit_findings.empty();
    for (const calibration::PoseModes& p : poses) {
      for (const std::string& w : p.warnings) {
        Warn(kTool, w);
        flagged = true;
      }
      for (const calibration::ModalGroup& g : p.groups) {
        std::ostringstream line;
        line << "posture " << p.pose_id << ": ";
        for (size_t i = 0; i < g.keys.size(); ++i) {
          line << (i ? ", " : "") << g.keys[i].Label();
        }
        line << ": " << g.fit.message;
        Note(kTool, line.str());
        for (size_t i = 0; i < g.keys.size(); ++i) {
          // Judged by the fit with the noise's weights: the model error's
          // refit gives up misfit in noise units for the peaks on purpose.
          const double ns = i < g.fit.misfit_in_noise_weights_alone.size() ? g.fit.misfit_in_noise_weights_alone[i] : NAN;
          const double tau = i < g.fit.model_error.size() ? g.fit.model_error[i] : 0.0;
          if (std::isfinite(ns) && ns > 3.0) {
            Warn(kTool, "posture " + p.pose_id + ", " + g.keys[i].Label() + ": the fit leaves " + FormatNumber(ns, 3) +
                            " x the noise (more than 3): a mode or a residual effect is missing, or the noise model is "
                            "too optimistic (see the picture)" +
                            (tau > 0.0 ? "; so the fit took in a model error of " + FormatNumber(tau, 3) + " " +
                                             io::QuantityUnit(static_cast<io::FrfQuantity>(power)) +
                                             " rms on every line (summary: model_error_rms), which fits the peaks "
                                             "rather than the lines of small |H| and leaves " +
                                             FormatNumber(g.fit.misfit_in_noise[i], 3) + " x the noise"
                                       : std::string()));
            flagged = true;
          }
        }
      }
      for (const calibration::TipMode& t : p.tip_modes) {
        std::fprintf(stderr, "%s: posture %s: %.6g Hz, zeta %.4g, modal mass %s kg (%s)\n", kTool, p.pose_id.c_str(),
                     t.freq_hz, t.damping_ratio,
                     std::isfinite(t.modal_mass_kg) ? FormatNumber(t.modal_mass_kg, 4).c_str() : "-",
                     t.directions.empty() ? "no driving-point FRF with a positive modal constant" : t.directions.c_str());
      }
    }
    io::WriteFileAtomically(out_path, io::ModalTableCsv(poses));
    if (!constants_path.empty()) io::WriteFileAtomically(constants_path, io::ModalConstantsCsv(poses));
    if (!shapes_path.empty()) {
      std::vector<std::string> why;
      const std::string csv = io::ModeShapesCsv(poses, calibration::ShapesOfRovingTests(poses, &why));
      for (const std::string& w : why) Note(kTool, w);
      io::WriteFileAtomically(shapes_path, csv);
    }
    if (!plot_dir.empty()) {
      io::EnsureDirectory(plot_dir);
      std::vector<std::string> ids;
      for (const calibration::PoseModes& p : poses) ids.push_back(p.pose_id);
      const std::map<std::string, std::string> stems = FileStemsForIds(kTool, "--plot-dir", ids);
      for (const calibration::PoseModes& p : poses) {
        report::WriteModalAnalysisPng(
            (std::filesystem::path(plot_dir) / ("modes_" + stems.at(p.pose_id) + ".png")).string(), p, all.frfs,
            noise);
      }
    }
    if (!summary_path.empty()) {
      nlohmann::json j = io::ModalAnalysisSummaryJson(poses, quantity);
      j["tool"] = kTool;
      j["warnings"] = WarningsGiven();
      j["flagged"] = flagged;
      j["exit_code"] = flagged ? kExitFlagged : kExitOk;
      io::WriteFileAtomically(summary_path, report::DumpJson(j));
    }
    return flagged ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
