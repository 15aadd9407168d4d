// axis-acquire: encoder counts (docs/formats.md §8.1) + machine file + the
// controller's compensation -> the tool tip and axis in workpiece coordinates
// at the card's rate (docs/formats.md §8.5), with the contour error against a
// programmed path.
#include <CLI/CLI.hpp>

#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/acquired_path_file.h"
#include "robomach/workflows/acquisition_inputs.h"
#include "robomach/machine/acquisition.h"
#include "robomach/report/plot.h"
#include "robomach/report/json.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "axis-acquire";

// Keeps the plot readable and fast: at most `bins` points, each bin's
// largest value (peaks must stay visible).
void BinnedMax(const std::vector<double>& x, const std::vector<double>& y, size_t bins, std::vector<double>* bx,
               std::vector<double>* by) {
  if (x.size() <= bins) {
    *bx = x;
    *by = y;
    return;
  }
  const size_t per = (x.size() + bins - 1) / bins;
  for (size_t i = 0; i < x.size(); i += per) {
    size_t best = i;
    for (size_t k = i; k < std::min(x.size(), i + per); ++k) {
      if (std::abs(y[k]) > std::abs(y[best])) best = k;
    }
    bx->push_back(x[best]);
    by->push_back(y[best]);
  }
}

int Run(int argc, char** argv) {
  CLI::App app{
      "axis-acquire: the tool tip and tool axis in workpiece coordinates from encoder counts (seed 002):\n"
      "measured = origin + count x resolution (eq. 1); real = measured + the controller's compensation\n"
      "($AA_ENC_COMP, $AN_CEC, temperature; eqs. 2-5); then the machine's kinematics with its rotary errors\n"
      "(docs/formats.md §8.3). With --program, the contour error of every sample against the programmed polyline."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() + "\n3 here: with --program, a contour error over 1 mm or a tool axis error over "
                              "1 deg (swapped count columns or a unit mistake; docs/plausibility.md).");
  std::string machine_path, counts_path, comp_path, temp_path, program_path, out_path, summary_path, plot_path;
  app.add_option("--machine", machine_path, "machine file YAML (docs/formats.md §8.3)")->required();
  app.add_option("--counts", counts_path, "encoder counts CSV (docs/formats.md §8.1)")->required();
  app.add_option("--compensation", comp_path, "Siemens 840D sl compensation tables (docs/formats.md §8.4)");
  app.add_option("--temperature", temp_path, "temperature log t_s,axis,K0_mm,tan_beta,P0_mm (docs/formats.md §8.4)");
  app.add_option("--program", program_path, "programmed path CSV x_mm,y_mm,z_mm,i,j,k (workpiece coordinates)");
  app.add_option("--out", out_path, "acquired path CSV (docs/formats.md §8.5); '-' = stdout")->required();
  app.add_option("--summary", summary_path, "summary JSON (rows, duration, contour error statistics)");
  app.add_option("--plot", plot_path, "PNG of the contour error along the path (needs --program)")->check(PngFileName());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return RunGuarded(kTool, [&]() -> int {
    if (!plot_path.empty() && program_path.empty()) throw UsageError("--plot needs --program");
    RequireReadableFile(machine_path, "machine file");
    RequireReadableFile(counts_path, "counts file");
    if (!comp_path.empty()) {
      RequireInputFile("--compensation", comp_path, "compensation file", {io::FileKind::kMpf}, io::kCompensationFileFormat);
    }
    if (!temp_path.empty()) {
      RequireInputFile("--temperature", temp_path, "temperature log", {io::FileKind::kCsv}, io::kTemperatureLogFormat);
    }
    if (!program_path.empty()) RequireReadableFile(program_path, "programmed path");
    CheckDistinctPaths({{"--machine", machine_path}, {"--counts", counts_path}, {"--compensation", comp_path},
                        {"--temperature", temp_path}, {"--program", program_path}},
                       {{"--out", out_path}, {"--summary", summary_path}, {"--plot", plot_path}});
    // Read and check every input before writing anything.
    const workflows::AcquisitionInputs in =
        workflows::ReadAcquisitionInputs(machine_path, counts_path, comp_path, temp_path, program_path, "--compensation");
    const io::MachineFile& mf = in.machine;
    const io::CompensationTables& tables = in.tables;
    const std::vector<machine::TemperatureCompensation>& temps = in.temperatures;
    const std::optional<machine::ProgrammedPath>& path = in.program;
    const machine::CountsRecord& rec = in.counts;
    const std::vector<std::string> implausible = in.implausible();
    for (const std::string& w : implausible) Warn(kTool, w);

    machine::Acquisition acq(mf.machine, in.applied());
    std::optional<machine::ContourTracker> tracker;
    if (path) tracker.emplace(*path);
    // Rows are computed in order (the contour tracker follows the path)
    // while earlier chunks are formatted and written on two threads
    // (formatting 17-digit numbers is most of the work).
    std::vector<machine::ContourError> contour;
    io::WriteFileAtomically(out_path, [&](std::ostream& out) {
      contour = workflows::WriteAcquiredPath(out, rec, mf.machine.axes, &acq, tracker ? &*tracker : nullptr);
    });
    nlohmann::json j;
    j["rows"] = rec.rows();
    j["duration_s"] = rec.t_s.back() - rec.t_s.front();
    j["sample_rate_hz"] = rec.rows() > 1 ? (rec.rows() - 1) / (rec.t_s.back() - rec.t_s.front()) : 0.0;
    j["compensation"] = {{"encoder_tables", tables.encoder.size()},
                         {"cross_axis_tables", tables.cross_axis.size()},
                         {"temperature_axes", temps.size()}};
    if (path) {
      j.update(io::ContourSummaryJson(workflows::ContourFiguresOf(contour, *path)));
      if (!plot_path.empty()) {
        std::vector<double> d_um, a_deg, s_mm;
        for (const machine::ContourError& c : contour) {
          d_um.push_back(c.distance * 1e6);
          a_deg.push_back(RadToDeg(c.axis_angle));
          s_mm.push_back(MToMm(c.s));
        }
        report::Figure fig(2, 1);
        fig.title = "axis-acquire: contour error along the programmed path";
        std::vector<double> bx, by;
        BinnedMax(s_mm, d_um, 4000, &bx, &by);
        auto& a0 = fig.at(0, 0);
        a0.title = "tool tip distance to the programmed path (max of bins)";
        a0.x_label = "path length [mm]";
        a0.y_label = "contour error [um]";
        a0.series.push_back({bx, by, "", report::PaletteColor(0), 1, false, false});
        bx.clear();
        by.clear();
        BinnedMax(s_mm, a_deg, 4000, &bx, &by);
        auto& a1 = fig.at(1, 0);
        a1.title = "tool axis angle to the programmed axis (max of bins)";
        a1.x_label = "path length [mm]";
        a1.y_label = "axis error [deg]";
        a1.series.push_back({bx, by, "", report::PaletteColor(1), 1, false, false});
        fig.SavePng(plot_path);
      }
    }
    if (!summary_path.empty()) io::WriteFileAtomically(summary_path, SummaryText(j));
    if (path) {
      std::cerr << kTool << ": " << rec.rows() << " samples; contour error max " << j["contour_error_um"]["max"].get<double>()
                << " um, rms " << j["contour_error_um"]["rms"].get<double>() << " um; axis error max "
                << j["axis_error_deg"]["max"].get<double>() << " deg\n";
      const RunFindings verdict = machine::JudgeContour(contour, *path);
      for (const Finding& f : verdict.findings) Warn(kTool, f.message);
      return implausible.empty() ? ExitCodeFor(verdict.status()) : kExitFlagged;
    }
    return implausible.empty() ? kExitOk : kExitFlagged;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
