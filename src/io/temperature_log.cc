#include "robomach/io/temperature_log.h"

#include <cmath>
#include <map>

#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

using machine::AxisKind;

namespace {

// The largest |value| of a column, for one finding per column.
struct Largest {
  double value{0.0};
  int row{-1};
  void See(double v, int r) {
    if (row < 0 || std::abs(v) > std::abs(value)) {
      value = v;
      row = r;
    }
  }
};

}  // namespace

std::vector<machine::TemperatureCompensation> ReadTemperatureLog(const std::string& path, const MachineFile& mf,
                                                                 std::vector<std::string>* implausible) {
  // An MPF (the compensation tables given as the log), a PNG, a YAML is
  // named as what it is (file_kind.h) before any cell is read.
  const CsvTable t = CsvTable::ReadFile(path, kTemperatureLogFormat);
  for (const char* c : {"t_s", "axis", "K0_mm", "tan_beta", "P0_mm"}) t.RequireColumn(c);
  std::map<int, machine::TemperatureCompensation> by_axis;
  std::map<int, int> last_line;
  Largest k0, slope, p0, time;
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string name = t.Text(r, "axis");
    const int axis = machine::FindAxis(mf.machine.axes, name);
    if (axis < 0) throw t.ErrorAt(r, "axis", "unknown axis '" + name + "'; the machine file " + mf.path + " has no such axis");
    if (mf.machine.axes[axis].kind != AxisKind::kLinear) {
      throw t.ErrorAt(r, "axis", "axis " + name + " is rotary; the log's K0_mm and P0_mm are for linear axes");
    }
    const double t_s = t.Number(r, "t_s"), k0_mm = t.Number(r, "K0_mm"), tan_beta = t.Number(r, "tan_beta"),
                 p0_mm = t.Number(r, "P0_mm");
    // Values no machine has (exit 65), each with the likely mistake.
    if (std::abs(k0_mm) > kMaxThermalOffsetMm) {
      throw t.ErrorAt(r, "K0_mm", "expected a thermal offset within +-" + FormatNumber(kMaxThermalOffsetMm, 7) +
                                      " mm, got " + t.Text(r, "K0_mm") + " mm: an offset in um or nm typed in the mm column?");
    }
    if (std::abs(tan_beta) > kMaxThermalSlope) {
      throw t.ErrorAt(r, "tan_beta", "expected a thermal slope within +-" + FormatNumber(kMaxThermalSlope, 7) +
                                         " (a growth of 10 % of the position), got " + t.Text(r, "tan_beta") +
                                         ": a slope in um/m (ppm) or mm/m typed for tan(beta)?");
    }
    if (std::abs(p0_mm) > kMaxMachineLengthMm) {
      throw t.ErrorAt(r, "P0_mm", "expected a position within +-" + FormatNumber(kMaxMachineLengthMm, 7) +
                                      " mm (1 km), got " + t.Text(r, "P0_mm") + " mm: a position in um or nm typed in the mm column?");
    }
    k0.See(k0_mm, r);
    slope.See(tan_beta, r);
    p0.See(p0_mm, r);
    time.See(t_s, r);
    machine::TemperatureRow row;
    row.t_s = t_s;
    row.k0 = MmToM(k0_mm);
    row.tan_beta = tan_beta;
    row.p0 = MmToM(p0_mm);
    auto& tc = by_axis[axis];
    tc.axis = axis;
    if (!tc.rows.empty() && !(row.t_s > tc.rows.back().t_s)) {
      throw t.ErrorAt(r, "t_s", "time must increase for axis " + name + ": " + FormatDouble(row.t_s) +
                                    " s after " + FormatDouble(tc.rows.back().t_s) + " s (line " +
                                    std::to_string(last_line[axis]) + ")");
    }
    last_line[axis] = t.line(r);
    tc.rows.push_back(row);
  }
  // Plausible ranges (temperature_log.h): one finding per column, naming
  // its largest value.
  if (implausible) {
    auto flag = [&](const Largest& l, const char* column, double hi, const std::string& unit, const std::string& practice,
                    const std::string& hint) {
      if (l.row < 0 || std::abs(l.value) <= hi) return;
      const std::string u = unit.empty() ? "" : " " + unit;
      implausible->push_back("implausible (unit mistake?): " + path + ":" + std::to_string(t.line(l.row)) + ": column " +
                             column + ": " + t.Text(l.row, column) + u + " is outside the +-" + FormatNumber(hi, 7) + u +
                             " of " + practice + ": " + hint);
    };
    flag(k0, "K0_mm", kMaxPlausibleThermalOffsetMm, "mm", "thermal offsets of machine axes (tens of um)",
         "an offset in um typed in the mm column?");
    flag(slope, "tan_beta", kMaxPlausibleThermalSlope, "",
         "thermal slopes (expansion 1e-5 /K times the warming: 1e-6 to 1e-4)",
         "a slope in um/m (ppm), mm/m or percent typed for tan(beta)?");
    flag(p0, "P0_mm", kMaxPlausibleMachineLengthMm, "mm", "machine tool travels (the largest gantry mills travel 30 m)",
         "a position in um typed in the mm column?");
    if (time.row >= 0 && time.value > kMaxPlausibleLogTimeS) {
      implausible->push_back("implausible (unit mistake?): " + path + ":" + std::to_string(t.line(time.row)) +
                             ": column t_s: " + t.Text(time.row, "t_s") + " s is after the " +
                             FormatNumber(kMaxPlausibleLogTimeS, 7) +
                             " s (a day) of counts records (seconds to hours): a time in ms typed in the s column?");
    }
  }
  std::vector<machine::TemperatureCompensation> out;
  for (auto& [a, tc] : by_axis) out.push_back(std::move(tc));
  return out;
}

}  // namespace robomach::io
