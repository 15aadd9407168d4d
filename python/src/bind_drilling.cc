// Python bindings of the drilling robot (docs/python.md): drill-sim's call
// (workflows::LoadDrillingSetup, then drilling::RunControllers) and its series CSV.
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "bindings.h"
#include "robomach/drilling/controller_kinds.h"
#include "robomach/common/solver_status.h"
#include "robomach/drilling/controller_runs.h"
#include "robomach/drilling/force_fit.h"
#include "robomach/io/drill_series_file.h"
#include "robomach/io/atomic_file.h"
#include "robomach/common/number_format.h"
#include "robomach/workflows/drilling_setup.h"

namespace robomach::python {

void BindDrilling(py::module_& m) {
  using drilling::ControllerRun;
  py::class_<ControllerRun>(m, "ControllerRun", "One controller's drilling run (drill-sim).")
      .def_property_readonly("controller", [](const ControllerRun& r) { return r.parameters.kind; })
      .def_property_readonly("parameters", [](const ControllerRun& r) {
        py::dict d;
        d["omega_rad_s"] = r.parameters.omega;
        d["zeta"] = r.parameters.zeta;
        d["third"] = r.parameters.third;
        d["filter_time_constant_s"] = r.parameters.filter_time_constant;
        return d;
      }, "the gain parameters simulated (given, default or tuned); `third` is r (pid) or the Mbar ratio (pd-tdc)")
      .def_readonly("tuned", &ControllerRun::tuned)
      .def_property_readonly("tuning_status",
                             [](const ControllerRun& r) { return r.tuned ? robomach::ToString(r.tune.status) : ""; },
                             "how the tuning ended: converged, not_converged, failed or not_improved ('' untuned)")
      .def_property_readonly("tuning_stop_reason", [](const ControllerRun& r) { return r.tune.message; },
                             "NLopt's reason for stopping: converged, max_evaluations or roundoff_limited ('' untuned)")
      .def_property_readonly("settling_time_s", [](const ControllerRun& r) { return r.result.settling_time; },
                             "NaN: still outside the band at the end")
      .def_property_readonly("max_abs_error_rad", [](const ControllerRun& r) { return r.result.max_abs_error; })
      .def_property_readonly("max_abs_error_last_10pc_rad",
                             [](const ControllerRun& r) { return r.result.max_abs_error_last_10pc; })
      .def_property_readonly("cost_rad_s2", [](const ControllerRun& r) { return r.result.cost; })
      .def_property_readonly("diverged", [](const ControllerRun& r) { return r.result.diverged; })
      .def_readonly("tde_measure", &ControllerRun::tde_measure,
                    "||I - M^-1 Mbar|| for pd-tdc (the condition holds below 1); NaN for the others")
      .def_property_readonly("t_s", [](const ControllerRun& r) { return r.result.series.t; })
      .def_property_readonly("q_rad", [](const ControllerRun& r) { return r.result.series.q; }, "(joints, samples)")
      .def_property_readonly("e_rad", [](const ControllerRun& r) { return r.result.series.e; }, "q_d - q (joints, samples)")
      .def_property_readonly("tau_m_Nm", [](const ControllerRun& r) { return r.result.series.tau_m; })
      .def_property_readonly("thrust_N", [](const ControllerRun& r) { return r.result.series.thrust; })
      .def_property_readonly("torque_Nm", [](const ControllerRun& r) { return r.result.series.torque; })
      .def_property_readonly("offset_rad", [](const ControllerRun& r) { return r.result.series.offset; },
                             "angle between the drill axis and the hole axis")
      .def("__repr__", [](const ControllerRun& r) {
        return "<ControllerRun " + r.parameters.kind + (r.result.diverged ? ", diverged" : "") + ">";
      });

  m.def("controller_kinds", [] {
    std::vector<std::string> n;
    for (const auto* k : drilling::ControllerKinds()) n.push_back(k->name());
    return n;
  }, "The drilling controller kinds: names drill_sim accepts.");

  m.def("drill_sim", [](const std::string& robot, const std::string& drill, const std::string& material,
                        const std::vector<std::string>& controllers, bool tune, int tune_evaluations,
                        double motor_torque_limit_Nm, const std::map<std::string, std::vector<double>>& gains) {
    for (const std::string& p : {robot, drill, material}) RequireReadableFile(p);
    if (!(motor_torque_limit_Nm > 0.0)) throw std::invalid_argument("motor_torque_limit_Nm: expected > 0");
    if (tune_evaluations < 5 || tune_evaluations > 1000) throw std::invalid_argument("tune_evaluations: expected 5 to 1000");
    drilling::ControllerRunOptions o;
    o.kinds = controllers;
    o.tune = tune;
    o.tune_evaluations = tune_evaluations;
    if (controllers.empty()) throw std::invalid_argument("controllers: expected at least one kind");
    for (size_t i = 0; i < controllers.size(); ++i) {
      drilling::FindControllerKind(controllers[i]);
      for (size_t k = 0; k < i; ++k) {
        if (controllers[k] == controllers[i]) throw std::invalid_argument("controllers: " + controllers[i] + " given twice");
      }
    }
    for (const auto& [kind, v] : gains) {
      try {
        o.given[kind] = drilling::ParametersFromGains(kind, v);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("gains[" + kind + "]: " + e.what());
      }
    }
    std::vector<ControllerRun> runs;
    std::vector<std::string> findings;
    {
      py::gil_scoped_release release;
      workflows::DrillingSetup setup = workflows::LoadDrillingSetup(robot, drill, material, motor_torque_limit_Nm);
      o.motor_torque_limit = setup.motor_torque_limit;
      runs = drilling::RunControllers(*setup.scenario, o);
      findings = setup.unit_findings;
    }
    return py::make_tuple(runs, findings);
  }, py::arg("robot"), py::arg("drill"), py::arg("material"), py::arg("controllers") = std::vector<std::string>{"pd-tdc"},
     py::arg("tune") = false, py::arg("tune_evaluations") = 30, py::arg("motor_torque_limit_Nm") = 10.0,
     py::arg("gains") = std::map<std::string, std::vector<double>>{},
     "drill-sim's call with its defaults: the robot, drill-and-process and material files (docs/formats.md §9), "
     "each controller kind simulated (tuned first with tune=True). gains: {kind: (omega_rad_s, zeta[, third[, "
     "filter_s]])}. Returns (runs, unit_findings): a list of ControllerRun, and the unit plausibility findings "
     "(drill-sim exits 3 on any). The GIL is released while it runs.");

  const workflows::DrillSimOptions kDrill;  // drill-sim's defaults
  m.def("run_drill_sim",
        [](const std::string& robot, const std::string& drill, const std::string& material,
           const std::vector<std::string>& controllers, const std::map<std::string, std::vector<double>>& gains,
           bool tune, int tune_evaluations, double motor_torque_limit_Nm) {
          workflows::DrillSimOptions o;
          o.robot_path = robot;
          o.drill_path = drill;
          o.material_path = material;
          o.controllers = controllers;
          // --gains KIND=OMEGA,ZETA[,THIRD[,FILTER_S]]
          for (const auto& [kind, values] : gains) {
            std::string text = kind + "=";
            for (size_t i = 0; i < values.size(); ++i) text += (i ? "," : "") + FormatNumber(values[i], 17);
            o.gains.push_back(text);
          }
          o.tune = tune;
          o.tune_evaluations = tune_evaluations;
          o.motor_torque_limit_Nm = motor_torque_limit_Nm;
          o.Validate();
          for (const std::string& p : {robot, drill, material}) RequireReadableFile(p);
          CollectedMessages said;
          workflows::DrillSimRun run;
          {
            py::gil_scoped_release release;
            run = workflows::RunDrillSim(o, said.Sink());
          }
          for (const std::string& f : run.setup.unit_findings) WarnUnit(f);
          const py::object loads = py::module_::import("json").attr("loads");
          py::dict summaries;
          for (const ControllerRun& r : run.runs) summaries[py::str(r.parameters.kind)] = loads(run.Summary(r).dump());
          py::dict d;
          d["runs"] = run.runs;
          d["unit_findings"] = run.setup.unit_findings;
          d["messages"] = said.List();
          d["findings"] = FindingMessages(run.verdict);
          d["status"] = robomach::ToString(run.status());
          d["flagged"] = run.status() == RunStatus::kFlagged;
          d["summaries"] = summaries;
          return d;
        },
        py::arg("robot"), py::arg("drill"), py::arg("material"), py::arg("controllers") = kDrill.controllers,
        py::arg("gains") = std::map<std::string, std::vector<double>>{}, py::arg("tune") = kDrill.tune,
        py::arg("tune_evaluations") = kDrill.tune_evaluations,
        py::arg("motor_torque_limit_Nm") = kDrill.motor_torque_limit_Nm,
        "drill-sim as one call (workflows::RunDrillSim): the robot, drill-and-process and material files "
        "(docs/formats.md §9), the tool's options under their names without dashes (controllers: --controller's "
        "kinds, in order; gains: {kind: (omega_rad_s, zeta[, third[, filter_s]])} for --gains). Returns a dict: runs "
        "(ControllerRun per kind), unit_findings (also as UnitWarning), messages ({kind, text}), findings (the "
        "verdict's), status, flagged (the tool's exit 3) and summaries ({kind: the tool's --summary JSON of that "
        "run but for warnings}). ValueError naming the option; FileNotFoundError, InputError for files. Releases "
        "the GIL.");

  m.def("fit_drill_forces", [](const std::string& table, const std::string& drill, const std::string& chisel) {
    RequireReadableFile(table);
    RequireReadableFile(drill);
    drilling::ForceFitOptions o;
    o.chisel = drilling::ParseChiselModel(chisel);
    workflows::ForceFitRun run;
    {
      py::gil_scoped_release release;
      run = workflows::FitForceTableFiles(table, drill, o);
    }
    const drilling::ForceFitResult& f = run.fit;
    py::dict d;
    d["status"] = robomach::ToString(f.status);
    d["solver_message"] = f.solver_message;
    d["shear_stress_thrust_Pa"] = f.material.shear_stress_thrust;
    d["shear_stress_torque_Pa"] = f.material.shear_stress_torque;
    d["kienzle_exponent"] = f.material.kienzle_exponent;
    d["std_dev_shear_stress_thrust_Pa"] = f.std_dev_shear_stress_thrust;
    d["std_dev_shear_stress_torque_Pa"] = f.std_dev_shear_stress_torque;
    d["std_dev_kienzle_exponent"] = f.std_dev_kienzle_exponent;
    d["thrust_model_N"] = f.thrust_model;
    d["torque_model_Nm"] = f.torque_model;
    d["max_rel_error_thrust"] = f.max_rel_error_thrust;
    d["max_rel_error_torque"] = f.max_rel_error_torque;
    d["kienzle_exponent_at_bound"] = f.kienzle_exponent_at_bound;
    d["material_yaml"] = run.material_yaml;
    d["unit_findings"] = run.unit_findings;
    d["flagged"] = run.verdict.flagged();
    d["findings"] = FindingMessages(run.verdict);
    return d;
  }, py::arg("table"), py::arg("drill"), py::arg("chisel") = "seed_scaling",
     "drill-force-fit's call: K_TH, K_TQ [Pa] and the Kienzle exponent fitted to a measured force table "
     "(docs/formats.md §9.1) for a drill (§9.2). Returns a dict: the coefficients and their 1-sigma standard "
     "deviations, the model per row, the largest relative errors, status (the library's solver status), "
     "material_yaml (drill-force-fit's --out, byte for byte; empty when the fit failed), unit_findings, "
     "flagged (drill-force-fit's exit 3) and findings (why, its warnings).");

  m.def("write_drill_series_csv", [](const std::string& path, const ControllerRun& run) {
    io::WriteFileAtomically(path, io::DrillSeriesCsv(run.result));
  }, py::arg("path"), py::arg("run"), "drill-sim's --out time series of one run (atomic).");
}

}  // namespace robomach::python
