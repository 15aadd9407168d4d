#include "robomach/workflows/acquisition_inputs.h"

#include <algorithm>

#include "robomach/common/units.h"
#include "robomach/io/counts_file.h"
#include "robomach/io/parallel_rows.h"
#include "robomach/io/program_file.h"
#include "robomach/io/temperature_log.h"

namespace robomach::workflows {

AcquisitionInputs ReadAcquisitionInputs(const std::string& machine_path, const std::string& counts_path,
                                        const std::string& compensation_path, const std::string& temperature_path,
                                        const std::string& program_path, const std::string& compensation_option) {
  AcquisitionInputs in;
  in.machine = io::ReadMachineFile(machine_path);
  if (!compensation_path.empty()) in.tables = io::ReadCompensationFile(compensation_path, in.machine, compensation_option);
  if (!temperature_path.empty()) in.temperatures = io::ReadTemperatureLog(temperature_path, in.machine, &in.temperature_implausible);
  in.compensation = std::make_unique<machine::Compensation>(static_cast<int>(in.machine.machine.axes.size()),
                                                            in.tables.encoder, in.tables.cross_axis, in.temperatures);
  if (!program_path.empty()) in.program = io::ReadProgramFile(program_path);
  in.counts = io::ReadCountsFile(counts_path, in.machine, &in.counts_implausible);
  return in;
}

std::vector<machine::ContourError> WriteAcquiredPath(std::ostream& out, const machine::CountsRecord& record,
                                                     const std::vector<machine::AxisScale>& axes,
                                                     machine::Acquisition* acquisition,
                                                     machine::ContourTracker* tracker, int threads) {
  const io::AcquiredPathWriter w(out, axes, tracker != nullptr);
  const long rows = record.rows();
  const size_t n = axes.size();
  std::vector<machine::ContourError> contour(tracker != nullptr ? static_cast<size_t>(rows) : 0);
  // 4096 rows are ~1.1 MB of text: small enough for the pipeline to start
  // formatting early, large enough that the hand-offs cost nothing.
  constexpr long kChunk = 4096;
  const int slots = 2 * std::max(1, threads) + 2;
  std::vector<std::vector<machine::AcquiredSample>> samples(static_cast<size_t>(slots),
                                                             std::vector<machine::AcquiredSample>(kChunk));
  io::WritePipelined(
      out, rows, kChunk, slots,
      [&](long first, long last, int slot) {
        auto& s = samples[static_cast<size_t>(slot)];
        for (long r = first; r < last; ++r) {
          s[static_cast<size_t>(r - first)] = acquisition->Process(record.t_s[r], record.counts.data() + r * n);
          if (tracker != nullptr) contour[static_cast<size_t>(r)] = tracker->Next(s[static_cast<size_t>(r - first)].pose);
        }
      },
      [&](long first, long last, int slot, std::string* text) {
        const auto& s = samples[static_cast<size_t>(slot)];
        text->reserve(static_cast<size_t>(last - first) * 320);
        for (long r = first; r < last; ++r) {
          w.AppendRow(text, record.t_s[r], s[static_cast<size_t>(r - first)],
                      tracker != nullptr ? &contour[static_cast<size_t>(r)] : nullptr);
        }
      },
      threads);
  return contour;
}

io::ContourFigures ContourFiguresOf(const std::vector<machine::ContourError>& contour,
                                    const machine::ProgrammedPath& path) {
  std::vector<double> d_um(contour.size()), a_deg(contour.size()), s_mm(contour.size());
  for (size_t i = 0; i < contour.size(); ++i) {
    d_um[i] = contour[i].distance * 1e6;
    a_deg[i] = RadToDeg(contour[i].axis_angle);
    s_mm[i] = MToMm(contour[i].s);
  }
  io::ContourFigures f;
  f.contour_error_um = machine::Stats(d_um);
  f.axis_error_deg = machine::Stats(a_deg);
  f.path_length_mm = MToMm(path.length());
  f.covered_min_mm = s_mm.empty() ? 0.0 : *std::min_element(s_mm.begin(), s_mm.end());
  f.covered_max_mm = s_mm.empty() ? 0.0 : *std::max_element(s_mm.begin(), s_mm.end());
  return f;
}

}  // namespace robomach::workflows
