#include "robomach/workflows/iso_evaluation.h"

#include <algorithm>
#include <stdexcept>

#include "robomach/common/errors.h"

namespace robomach::workflows {

IsoEvaluation EvaluateIsoRunsFile(const std::string& path) {
  IsoEvaluation e;
  e.runs = io::ReadIsoRuns(path);
  e.min_runs = 1 << 30;
  for (const std::string& axis : e.runs.axis_order) {
    machine::Iso230Result r = AtLocation({path, 0, 0}, "axis " + axis + ": ",
                                         [&] { return machine::EvaluateIso230(e.runs.approaches.at(axis)); });
    for (const auto& t : r.targets) e.min_runs = std::min({e.min_runs, t.runs_up, t.runs_down});
    for (const std::string& f : machine::Iso230UnitFindings(axis, r, e.runs.rotary)) {
      e.unit_findings.push_back(f);
      e.verdict.Flag("implausible (unit mistake?): " + f);
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

}  // namespace robomach::workflows
