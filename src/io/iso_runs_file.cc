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

IsoEvaluation EvaluateIsoRunsFile(const std::string& path) {
  IsoEvaluation e;
  e.runs = ReadIsoRuns(path);
  e.min_runs = 1 << 30;
  for (const std::string& axis : e.runs.axis_order) {
    machine::Iso230Result r;
    try {
      r = machine::EvaluateIso230(e.runs.approaches.at(axis));
    } catch (const std::invalid_argument& err) {
      throw InputError({path, 0, 0}, "axis " + axis + ": " + err.what());
    }
    for (const auto& t : r.targets) e.min_runs = std::min({e.min_runs, t.runs_up, t.runs_down});
    for (const std::string& f : machine::Iso230UnitFindings(axis, r, e.runs.rotary)) {
      e.unit_findings.push_back(f);
      e.Flag("implausible (unit mistake?): " + f);
    }
    e.results.emplace_back(axis, std::move(r));
  }
  return e;
}

nlohmann::json IsoSummaryJson(const IsoEvaluation& eval) {
  nlohmann::json j;
  j["standard"] = "ISO 230-2";
  j["unit"] = eval.runs.rotary ? "deg" : "mm";
  j["axes"] = nlohmann::json::object();
  for (const auto& [axis, r] : eval.results) {
    nlohmann::json a = {{"A", r.A},       {"A_up", r.A_up}, {"A_down", r.A_down}, {"E", r.E},
                        {"E_up", r.E_up}, {"E_down", r.E_down}, {"M", r.M},       {"R", r.R},
                        {"R_up", r.R_up}, {"R_down", r.R_down}, {"B", r.B},       {"B_mean", r.B_mean}};
    a["targets"] = nlohmann::json::array();
    for (const auto& t : r.targets) {
      a["targets"].push_back({{"target", t.target},   {"runs_up", t.runs_up},     {"runs_down", t.runs_down},
                              {"mean_up", t.mean_up}, {"mean_down", t.mean_down}, {"s_up", t.s_up},
                              {"s_down", t.s_down},   {"mean", t.mean},           {"B", t.reversal},
                              {"R_up", t.R_up},       {"R_down", t.R_down},       {"R", t.R}});
    }
    j["axes"][axis] = a;
  }
  return j;
}

}  // namespace robomach::io
