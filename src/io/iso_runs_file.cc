#include "robomach/io/iso_runs_file.h"

#include <algorithm>
#include <cmath>

#include "robomach/common/errors.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

IsoRuns ReadIsoRuns(const std::string& path) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"axis", "run", "direction"}) t.RequireColumn(c, "iso");
  const bool mm = t.HasColumn("target_mm") || t.HasColumn("measured_mm");
  const bool deg = t.HasColumn("target_deg") || t.HasColumn("measured_deg");
  if (mm && deg) {
    throw InputError({path, t.header_line(), 0},
                     "a runs file holds one kind of axis: either target_mm,measured_mm or target_deg,measured_deg, not both");
  }
  if (!mm && !deg) throw InputError({path, t.header_line(), 0}, "missing required columns target_mm,measured_mm (or target_deg,measured_deg)");
  IsoRuns runs;
  runs.rotary = deg;
  const std::string u = deg ? "_deg" : "_mm";
  t.RequireColumn("target" + u, "iso");
  t.RequireColumn("measured" + u, "iso");
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string axis = t.Text(r, "axis");
    machine::Iso230Approach a;
    a.target = t.Number(r, "target" + u);
    const double run = t.Number(r, "run");
    if (run != std::floor(run) || run < 1 || run > 1e6) throw t.ErrorAt(r, "run", "expected a run number 1, 2, ...");
    a.run = static_cast<int>(run);
    const std::string dir = t.Text(r, "direction");
    if (dir != "+" && dir != "-") throw t.ErrorAt(r, "direction", "expected + or -, got \"" + dir + "\"");
    a.up = dir == "+";
    const double dev = t.Number(r, "measured" + u) - a.target;
    a.deviation = deg ? machine::WrapDeviationDeg(dev) : dev;
    if (!runs.approaches.count(axis)) runs.axis_order.push_back(axis);
    for (const auto& b : runs.approaches[axis]) {
      if (b.target == a.target && b.run == a.run && b.up == a.up) {
        throw t.ErrorAtRow(r, "axis " + axis + ", target " + FormatDouble(a.target) + ", run " + std::to_string(a.run) +
                                  ", direction " + dir + " appears twice");
      }
    }
    runs.approaches[axis].push_back(a);
  }
  if (runs.axis_order.empty()) throw InputError({path, t.header_line(), 0}, "no data rows");
  return runs;
}

}  // namespace robomach::io
