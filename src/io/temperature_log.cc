#include "robomach/io/temperature_log.h"

#include <map>

#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

using machine::AxisKind;

std::vector<machine::TemperatureCompensation> ReadTemperatureLog(const std::string& path, const MachineFile& mf) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"t_s", "axis", "K0_mm", "tan_beta", "P0_mm"}) t.RequireColumn(c);
  std::map<int, machine::TemperatureCompensation> by_axis;
  std::map<int, int> last_line;
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string name = t.Text(r, "axis");
    const int axis = machine::FindAxis(mf.machine.axes, name);
    if (axis < 0) throw t.ErrorAt(r, "axis", "unknown axis '" + name + "'; the machine file " + mf.path + " has no such axis");
    if (mf.machine.axes[axis].kind != AxisKind::kLinear) {
      throw t.ErrorAt(r, "axis", "axis " + name + " is rotary; the log's K0_mm and P0_mm are for linear axes");
    }
    machine::TemperatureRow row;
    row.t_s = t.Number(r, "t_s");
    row.k0 = MmToM(t.Number(r, "K0_mm"));
    row.tan_beta = t.Number(r, "tan_beta");
    row.p0 = MmToM(t.Number(r, "P0_mm"));
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
  std::vector<machine::TemperatureCompensation> out;
  for (auto& [a, tc] : by_axis) out.push_back(std::move(tc));
  return out;
}

}  // namespace robomach::io
