#include "robomach/io/drill_series_file.h"

#include <sstream>

#include "robomach/common/solver_status.h"
#include "robomach/common/units.h"
#include "robomach/drilling/controller_kinds.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

namespace {

std::vector<double> Deg(const Eigen::VectorXd& v) {
  std::vector<double> out;
  for (int i = 0; i < v.size(); ++i) out.push_back(RadToDeg(v(i)));
  return out;
}

}  // namespace

nlohmann::json DrillRunSummaryJson(const drilling::ControllerRun& run, const drilling::DrillingScenario& sc,
                                   const Eigen::VectorXd& limit) {
  const drilling::SimResult& r = run.result;
  nlohmann::json j;
  j["controller"] = run.parameters.kind;
  nlohmann::json gains;
  for (const auto& [name, v] : r.gains) gains[name] = std::vector<double>(v.data(), v.data() + v.size());
  j["gains"] = gains;
  nlohmann::json par{{"omega_rad_s", run.parameters.omega}, {"zeta", run.parameters.zeta}};
  const drilling::ControllerKind& kind = drilling::FindControllerKind(run.parameters.kind);
  if (!kind.third_parameter().empty()) par[kind.third_parameter()] = run.parameters.third;
  par["filter_time_constant_s"] = run.parameters.filter_time_constant;
  j["gain_parameters"] = par;
  j["gains_source"] = run.tuned ? "tuned" : "defaults";
  if (run.tuned) {
    j["tuning"] = {{"cost_rad_s2", run.tune.cost},
                   {"evaluations", run.tune.evaluations},
                   {"status", robomach::ToString(run.tune.status)},
                   {"stop_reason", run.tune.message}};
  }
  j["band_deg"] = RadToDeg(sc.process().error_band);
  j["settling_time_s"] = std::isnan(r.settling_time) ? nlohmann::json(nullptr) : nlohmann::json(r.settling_time);
  j["max_abs_error_deg"] = Deg(r.max_abs_error);
  j["max_abs_error_last_10pc_deg"] = Deg(r.max_abs_error_last_10pc);
  if (r.thrust.available) {
    j["thrust_N"] = {{"min", r.thrust.min}, {"max", r.thrust.max}, {"mean", r.thrust.mean},
                     {"range", r.thrust.max - r.thrust.min}};
  } else {
    j["thrust_N"] = nullptr;
  }
  j["full_engagement_time_s"] = sc.full_engagement_time();
  const Eigen::VectorXd& f = sc.plant_modes_hz();
  j["plant_modes_hz"] = std::vector<double>(f.data(), f.data() + f.size());
  j["motor_torque_limit_Nm"] = std::vector<double>(limit.data(), limit.data() + limit.size());
  j["cost_rad_s2"] = r.cost;
  j["diverged"] = r.diverged;
  j["plant_substeps_per_period"] = r.substeps;
  if (kind.uses_time_delay_estimation()) j["tde_stability_measure"] = run.tde_measure;
  return j;
}

std::string DrillSeriesCsv(const drilling::SimResult& r) {
  const drilling::SimSeries& s = r.series;
  const int n = static_cast<int>(s.q.rows());
  std::ostringstream o;
  o << "t_s";
  for (int i = 1; i <= n; ++i) o << ",q" << i << "_deg";
  for (int i = 1; i <= n; ++i) o << ",e" << i << "_deg";
  for (int i = 1; i <= n; ++i) o << ",tau_m" << i << "_Nm";
  o << ",thrust_N,torque_Nm,offset_deg\n";
  for (size_t k = 0; k < s.t.size(); ++k) {
    o << FormatDouble(s.t[k]);
    for (int i = 0; i < n; ++i) o << "," << FormatDouble(RadToDeg(s.q(i, k)));
    for (int i = 0; i < n; ++i) o << "," << FormatDouble(RadToDeg(s.e(i, k)));
    for (int i = 0; i < n; ++i) o << "," << FormatDouble(s.tau_m(i, k));
    o << "," << FormatDouble(s.thrust[k]) << "," << FormatDouble(s.torque[k]) << "," << FormatDouble(RadToDeg(s.offset[k]))
      << "\n";
  }
  return o.str();
}

}  // namespace robomach::io
