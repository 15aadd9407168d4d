// drill-force-fit: fits the drilling force model (K_TH, K_TQ, Kienzle
// exponent) to a measured thrust/torque table (docs/formats.md §9.1) and writes
// the material file (docs/formats.md §9.2); optionally predicts other rows.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/drilling/force_fit.h"
#include "robomach/drilling/plausibility.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/drilling_files.h"
#include "robomach/workflows/drilling_setup.h"
#include "robomach/io/number_format.h"
#include "robomach/report/plot.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "drill-force-fit";

std::string PredictionsCsv(const io::ForceTableFile& rows, const drilling::DrillGeometry& drill,
                           const drilling::DrillingMaterial& material) {
  const bool rpm = std::any_of(rows.speed_rpm.begin(), rows.speed_rpm.end(),
                               [](const auto& v) { return v.has_value(); });
  std::ostringstream s;
  s << "diameter_mm,feed_mm_per_rev,thrust_N,torque_Nm" << (rpm ? ",speed_rpm" : "") << "\n";
  for (size_t k = 0; k < rows.rows.size(); ++k) {
    const auto& r = rows.rows[k];
    const drilling::DrillForces f = drilling::PredictRow(drill, material, r);
    s << std::setprecision(12) << MToMm(r.diameter) << "," << MToMm(r.feed_per_rev) << ","
      << io::FormatDouble(f.thrust) << "," << io::FormatDouble(f.torque);
    if (rpm) s << "," << (rows.speed_rpm[k] ? io::FormatDouble(*rows.speed_rpm[k]) : "");
    s << "\n";
  }
  return s.str();
}

void Plot(const std::string& path, const io::ForceTableFile& table,
          const drilling::DrillGeometry& drill, const drilling::DrillingMaterial& material) {
  report::Figure fig(1, 2, 700, 460);
  fig.title = "drill-force-fit: measured (markers) and model (lines) against feed";
  report::Axes& th = fig.at(0, 0);
  report::Axes& tq = fig.at(0, 1);
  th.x_label = tq.x_label = "feed [mm/rev]";
  th.y_label = "thrust [N]";
  tq.y_label = "torque [N m]";
  th.legend = tq.legend = report::Axes::LegendPosition::kTopLeft;
  std::map<double, std::vector<size_t>> by_d;
  double fmin = 1e300, fmax = 0.0;
  for (size_t k = 0; k < table.rows.size(); ++k) {
    by_d[table.rows[k].diameter].push_back(k);
    fmin = std::min(fmin, table.rows[k].feed_per_rev);
    fmax = std::max(fmax, table.rows[k].feed_per_rev);
  }
  const double lo = 0.8 * fmin, hi = 1.2 * fmax;
  int c = 0;
  for (const auto& [D, idx] : by_d) {
    const std::string name = "D = " + io::FormatDouble(MToMm(D)) + " mm";
    report::Series mt{.label = name + " measured", .color = report::PaletteColor(c), .markers = true};
    report::Series mq = mt;
    for (size_t k : idx) {
      mt.x.push_back(MToMm(table.rows[k].feed_per_rev));
      mt.y.push_back(table.rows[k].thrust);
      mq.x.push_back(MToMm(table.rows[k].feed_per_rev));
      mq.y.push_back(table.rows[k].torque);
    }
    report::Series lt{.label = name + " model", .color = report::PaletteColor(c)};
    report::Series lq = lt;
    for (int i = 0; i <= 40; ++i) {
      const double f = lo + (hi - lo) * i / 40.0;
      const drilling::DrillForces F = drilling::PredictRow(drill, material, {D, f, 0, 0});
      lt.x.push_back(MToMm(f));
      lt.y.push_back(F.thrust);
      lq.x.push_back(MToMm(f));
      lq.y.push_back(F.torque);
    }
    th.series.push_back(mt);
    th.series.push_back(lt);
    tq.series.push_back(mq);
    tq.series.push_back(lq);
    ++c;
  }
  fig.SavePng(path);
}

}  // namespace

int RunDrillForceFit(int argc, char** argv) {
  CLI::App app{"drill-force-fit: fit the twist-drill force model (oblique-cutting lips, dynamic "
               "rake, Kienzle size effect; seed 003) to a thrust/torque table"};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             "\n3 here also: a torque/(thrust x diameter) ratio or fitted coefficient outside the range of "
             "metals (a unit mistake, e.g. torque in N·mm). 65 also: a diameter or feed outside drilling practice "
             "(docs/plausibility.md).");
  std::string table_path, drill_path, out_path, plot_path, predict_path, predictions_path;
  std::string chisel = "seed_scaling";
  bool verbose = false;
  app.add_option("--table", table_path,
                 "measured force table CSV (docs/formats.md 9.1): diameter_mm, feed_mm_per_rev, thrust_N, "
                 "torque_Nm[, speed_rpm]")->required();
  app.add_option("--drill", drill_path,
                 "drill YAML (docs/formats.md 9.2); a row's diameter_mm overrides the drill's")->required();
  app.add_option("--out", out_path, "material YAML with the fitted coefficients; stdout if omitted");
  app.add_option("--plot", plot_path, "PNG: measured and model thrust and torque against feed, one curve per diameter")->check(PngFileName());
  app.add_option("--predict", predict_path, "CSV of rows to predict (diameter_mm, feed_mm_per_rev[, speed_rpm])");
  app.add_option("--predictions", predictions_path, "CSV written for --predict: diameter_mm, feed_mm_per_rev, thrust_N, torque_Nm[, speed_rpm]");
  app.add_option("--chisel", chisel, "chisel-edge model: seed_scaling (F_A = 2.5 F_L, T_A = 1.67 T), orthogonal, none")
      ->check(OneOf({"seed_scaling", "orthogonal", "none"}))->capture_default_str();
  app.add_flag("--verbose", verbose, "list ignored (unknown) table columns on stderr");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    if (predict_path.empty() != predictions_path.empty()) {
      throw UsageError("--predict and --predictions go together");
    }
    CheckDistinctPaths({{"--table", table_path}, {"--drill", drill_path}, {"--predict", predict_path}},
                       {{"--out", out_path}, {"--plot", plot_path}, {"--predictions", predictions_path}});
    RequireReadableFile(table_path, "force table");
    RequireReadableFile(drill_path, "drill file");
    if (!predict_path.empty()) RequireReadableFile(predict_path, "rows to predict");
    drilling::ForceFitOptions options;
    options.chisel = FromOption("--chisel", [&] { return drilling::ParseChiselModel(chisel); });
    const workflows::ForceFitRun run = workflows::FitForceTableFiles(table_path, drill_path, options);
    const io::ForceTableFile& table = run.table;
    const io::DrillFile& drill = run.drill;
    const drilling::ForceFitResult& fit = run.fit;
    if (verbose) {
      for (const auto& c : table.unknown_columns) Warn(kTool, table_path + ": ignored column '" + c + "'");
    }
    std::optional<io::ForceTableFile> predict;
    if (!predict_path.empty()) predict = io::ReadForceTable(predict_path, false);
    if (fit.status == drilling::FitStatus::kFailed) {
      std::cerr << kTool << ": the fit failed: " << fit.solver_message << "\n";
      return kExitSoftware;
    }
    // Everything computed: now write (each file atomically).
    io::WriteFileAtomically(out_path.empty() ? "-" : out_path, run.material_yaml);
    if (!plot_path.empty()) Plot(plot_path, table, drill.drill, fit.material);
    if (predict) io::WriteFileAtomically(predictions_path, PredictionsCsv(*predict, drill.drill, fit.material));

    std::cerr << kTool << ": " << table.rows.size() << " rows; K_TH "
              << io::FormatDouble(std::round(fit.material.shear_stress_thrust * 1e-5) / 10) << " MPa, K_TQ "
              << io::FormatDouble(std::round(fit.material.shear_stress_torque * 1e-5) / 10) << " MPa, m "
              << io::FormatDouble(std::round(fit.material.kienzle_exponent * 1e4) / 1e4)
              << "; largest error thrust " << io::FormatDouble(std::round(fit.max_rel_error_thrust * 1e3) / 10)
              << " %, torque " << io::FormatDouble(std::round(fit.max_rel_error_torque * 1e3) / 10) << " %\n";
    for (const Finding& f : run.verdict.findings) Warn(kTool, f.message);
    return ExitCodeFor(run.status());
  });
}

}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::RunDrillForceFit(argc, argv); }
