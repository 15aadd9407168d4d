// Python bindings of polishing (docs/python.md): surfaces (NURBS YAML or a
// STEP/IGES face), the process, polish-plan's call (PreparePlanning and
// PlanPolishing) and its path and removal files.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "robomach/common/units.h"
#include "robomach/io/cad_face.h"
#include "robomach/workflows/polish_plan.h"
#include "robomach/workflows/polish_simulation.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/face_check.h"
#include "robomach/polishing/path_patterns.h"
#include "robomach/polishing/plan_workflow.h"

namespace robomach::python {
namespace {

using polishing::NurbsSurface;
using polishing::PolishingProcess;
using SurfacePtr = std::shared_ptr<NurbsSurface>;  // pybind11 holders are not const

// A plan with what it was planned on (the context points at the surface).
struct PyPlan {
  SurfacePtr surface;
  polishing::PlanningContext context;
  polishing::PlanOutcome outcome;
};

py::dict StatsDict(const polishing::RemovalStats& s) {
  py::dict d;
  d["mean_um"] = 1e6 * s.mean;
  d["std_um"] = 1e6 * s.std;
  d["cv"] = s.cv;
  d["min_um"] = 1e6 * s.min;
  d["max_um"] = 1e6 * s.max;
  d["peak_to_valley_um"] = 1e6 * s.peak_to_valley;
  d["coverage"] = s.coverage;
  d["unpolished_area_mm2"] = 1e6 * s.unpolished_area;
  return d;
}

py::dict ParamsDict(const polishing::PathParameters& p) {
  py::dict d;
  d["pattern"] = polishing::PathPatternOf(p.pattern).name();
  d["guides"] = polishing::ToString(p.guides);
  d["offset_mm"] = 1e3 * p.offset;
  d["radius_mm"] = 1e3 * p.radius;
  d["pitch_mm"] = 1e3 * p.pitch;
  d["stagger_loops"] = p.stagger;
  d["line_angle_deg"] = p.line_angle * 180.0 / kPi;
  d["edge_overrun_mm"] = 1e3 * p.edge_overrun;
  return d;
}

}  // namespace

void BindPolishing(py::module_& m) {
  py::class_<NurbsSurface, SurfacePtr>(m, "Surface",
                                       "A NURBS patch, possibly trimmed (a CAD face): what polishing plans on.")
      .def_property_readonly("name", [](const NurbsSurface& s) { return polishing::SurfaceName(s); })
      .def_property_readonly("trimmed", [](const NurbsSurface& s) { return static_cast<bool>(s.trim()); })
      .def("__repr__", [](const NurbsSurface& s) { return "<Surface " + polishing::SurfaceName(s) + ">"; });
  m.def("load_surface", [](const std::string& path, int face, double cad_unit_scale) -> SurfacePtr {
    RequireReadableFile(path);
    if (!io::IsCadFile(path)) {
      if (face != 0 || cad_unit_scale != 1.0) {
        throw std::invalid_argument(path + " is a NURBS YAML (one patch, lengths in mm): face and cad_unit_scale "
                                           "apply to STEP/IGES files");
      }
      return std::make_shared<NurbsSurface>(io::ReadNurbsYaml(path));
    }
    // The GIL stays held: OpenCASCADE's readers keep global state
    // (Interface_Static), so two Python threads must not read at once.
    io::CadReadOptions o;
    o.unit_scale = cad_unit_scale;
    io::CadPartInfo info;
    auto surface = std::make_shared<NurbsSurface>(io::ReadCadFace(path, face, o, &info));
    // A part whose size says its unit is wrong (polish-plan warns the same).
    if (!info.unit_warning.empty()) {
      py::module_::import("warnings").attr("warn")(path + ": " + info.unit_warning,
                                                   py::module_::import("builtins").attr("UserWarning"));
    }
    return surface;
  }, py::arg("path"), py::arg("face") = 0, py::arg("cad_unit_scale") = 1.0,
     "A surface: NURBS YAML (docs/formats.md §5) or a face of a STEP/IGES file (1-based; 0: the largest by area), "
     "as polish-plan --surface/--face/--cad-unit-scale. A part whose size suggests another unit gives a "
     "UserWarning, as polish-plan warns.");

  py::class_<PolishingProcess>(m, "PolishingProcess", "The belt-grinding process (docs/formats.md §7).")
      .def_property_readonly("force_N", [](const PolishingProcess& p) { return p.force; })
      .def_property_readonly("margin_mm", [](const PolishingProcess& p) { return 1e3 * p.margin; })
      .def_property_readonly("max_speed_mm_per_s", [](const PolishingProcess& p) { return 1e3 * p.max_speed; })
      .def_property_readonly("belt_speed_m_per_s", [](const PolishingProcess& p) { return p.belt_speed; });
  m.def("read_polishing_process", [](const std::string& path) {
    RequireReadableFile(path);
    std::vector<std::string> implausible;
    PolishingProcess p = io::ReadPolishingProcess(path, &implausible);
    for (const std::string& w : implausible) WarnUnit(w);
    return p;
  }, py::arg("path"),
     "Reads a process YAML. Raises InputError naming file, line and column; a UnitWarning per value outside its "
     "plausible range (docs/plausibility.md), where polish-plan exits 3.");

  m.def("path_patterns", [] {
    std::vector<std::string> n;
    for (const auto* p : polishing::PathPatterns()) n.push_back(p->name());
    return n;
  }, "The path patterns plan_polishing accepts.");

  py::class_<PyPlan>(m, "PolishPlan", "A planned, simulated polishing path (polish-plan's result).")
      .def_property_readonly("parameters", [](const PyPlan& p) { return ParamsDict(p.outcome.params); },
                             "what was planned (the optimum with optimise)")
      .def_property_readonly("contact_width_mm", [](const PyPlan& p) { return 1e3 * p.context.contact_width; })
      .def_property_readonly("t_s", [](const PyPlan& p) {
        std::vector<double> t;
        for (const auto& r : p.outcome.plan.path.rows) t.push_back(r.t);
        return t;
      })
      .def_property_readonly("p_m", [](const PyPlan& p) {
        Eigen::MatrixX3d x(p.outcome.plan.path.rows.size(), 3);
        for (size_t i = 0; i < p.outcome.plan.path.rows.size(); ++i) x.row(i) = p.outcome.plan.path.rows[i].p;
        return x;
      }, "contact points (rows, 3) [m] in the part frame")
      .def_property_readonly("length_m", [](const PyPlan& p) { return p.outcome.plan.path.length; })
      .def_property_readonly("removal_m", [](const PyPlan& p) { return p.outcome.plan.removal; },
                             "removal at every grid point [m]")
      .def_property_readonly("stats", [](const PyPlan& p) { return StatsDict(p.outcome.plan.stats); },
                             "area-weighted over the region")
      .def_property_readonly("target_reached", [](const PyPlan& p) -> py::object {
        return p.outcome.target_given ? py::object(py::bool_(p.outcome.target.reached)) : py::none();
      }, "None without a target")
      .def_property_readonly("target_message", [](const PyPlan& p) { return p.outcome.target.message; })
      .def_property_readonly("infeasible_message", [](const PyPlan& p) { return p.outcome.infeasible_message; })
      .def_property_readonly("rows_off_face", [](const PyPlan& p) { return p.outcome.rows_off_face; })
      .def_property_readonly("flagged", [](const PyPlan& p) { return p.outcome.verdict.flagged(); },
                             "polish-plan exits 3: a target out of reach, no feasible plan, a better zig-zag, rows off the face")
      .def_property_readonly("status", [](const PyPlan& p) { return robomach::ToString(p.outcome.status()); },
                             "'ok' or 'flagged'")
      .def_property_readonly("findings", [](const PyPlan& p) { return FindingMessages(p.outcome.verdict); },
                             "why it is flagged, one sentence each (polish-plan's warnings)")
      .def_property_readonly("optimisation", [](const PyPlan& p) -> py::object {
        if (!p.outcome.optimisation) return py::none();
        const auto& o = *p.outcome.optimisation;
        py::dict d;
        d["method"] = o.method;
        d["status"] = robomach::ToString(o.status);
        d["stop_reason"] = o.stop_reason;
        d["evaluations"] = o.evaluations;
        d["best_cv"] = o.best.cv;
        d["feasible"] = o.best.feasible;
        d["history_cv"] = p.outcome.history_cv;
        return d;
      })
      .def_property_readonly("comparison", [](const PyPlan& p) -> py::object {
        if (!p.outcome.comparison) return py::none();
        const auto& c = *p.outcome.comparison;
        py::dict d;
        d["parallel"] = ParamsDict(c.parallel);
        d["parallel_cv"] = c.parallel_stats.cv;
        d["parallel_reaches_target"] = c.parallel_reaches_target;
        d["zigzag_better"] = c.zigzag_better;
        return d;
      }, "the optimised cycloid against the optimised zig-zag (None unless both were optimised)")
      .def("__repr__", [](const PyPlan& p) {
        return "<PolishPlan " + polishing::PathPatternOf(p.outcome.params.pattern).name() + ", " +
               std::to_string(p.outcome.plan.path.rows.size()) + " rows>";
      });

  const polishing::PlanOptions kDefaults;
  m.def("plan_polishing", [](const SurfacePtr& surface, const PolishingProcess& process, const std::string& pattern,
                             const std::optional<std::string>& guides, std::optional<double> offset_mm, double radius_mm, double pitch_mm,
                             double row_step_mm, double sample_mm, double edge_inset_mm, double stagger_loops,
                             double edge_overrun_mm, double line_angle_deg, double target_removal_um,
                             const std::string& optimise, double opt_sample_mm,
                             double opt_offset_max_mm, double opt_offset_min_contact_widths, double max_time_s,
                             int threads, unsigned seed, const std::string& surface_source,
                             const std::string& process_source) {
    polishing::PlanOptions o;
    o.pattern = pattern;
    o.guides = guides.value_or("offsets");
    o.guides_given = guides.has_value();  // the optimiser keeps a family the caller chose
    o.sample_mm = sample_mm;
    o.offset_mm = offset_mm;
    o.radius_mm = radius_mm;
    o.pitch_mm = pitch_mm;
    o.row_step_mm = row_step_mm;
    o.edge_inset_mm = edge_inset_mm;
    o.stagger_loops = stagger_loops;
    o.edge_overrun_mm = edge_overrun_mm;
    o.line_angle_deg = line_angle_deg;
    o.target_removal_um = target_removal_um;
    o.optimise = optimise;
    o.opt_sample_mm = opt_sample_mm;
    o.opt_offset_max_mm = opt_offset_max_mm;
    o.opt_offset_min_contact_widths = opt_offset_min_contact_widths;
    o.max_time_s = max_time_s;
    o.threads = threads;
    o.seed = seed;
    auto plan = std::make_unique<PyPlan>();
    plan->surface = surface;
    polishing::CheckRanges(o);
    for (const std::string& w : polishing::ImplausiblePlanOptions(o)) WarnUnit(w);
    {
      py::gil_scoped_release release;
      // A face too large to plan within polish-plan's limits is refused before the work.
      const polishing::PlanSize size = polishing::EstimatePlanSize(*surface, MmToM(sample_mm), {});
      if (size.too_large) {
        throw std::invalid_argument(size.too_large_message +
                                    " (check the file's unit: cad_unit_scale; or choose a smaller face)");
      }
      plan->context = polishing::PreparePlanning(*surface, process, MmToM(sample_mm), surface_source, process_source);
      plan->outcome = polishing::PlanPolishing(plan->context, polishing::ToPlanRequest(o, plan->context));
    }
    return plan;
  }, py::arg("surface").none(false), py::arg("process"), py::arg("pattern") = "cycloid", py::arg("guides") = py::none(),
     py::arg("offset_mm") = py::none(), py::arg("radius_mm") = kDefaults.radius_mm,
     py::arg("pitch_mm") = kDefaults.pitch_mm, py::arg("row_step_mm") = kDefaults.row_step_mm, py::arg("sample_mm") = 0.5,
     py::arg("edge_inset_mm") = kDefaults.edge_inset_mm, py::arg("stagger_loops") = kDefaults.stagger_loops,
     py::arg("edge_overrun_mm") = kDefaults.edge_overrun_mm, py::arg("line_angle_deg") = kDefaults.line_angle_deg,
     py::arg("target_removal_um") = kDefaults.target_removal_um, py::arg("optimise") = kDefaults.optimise,
     py::arg("opt_sample_mm") = kDefaults.opt_sample_mm,
     py::arg("opt_offset_max_mm") = kDefaults.opt_offset_max_mm,
     py::arg("opt_offset_min_contact_widths") = kDefaults.opt_offset_min_contact_widths,
     py::arg("max_time_s") = kDefaults.max_time_s, py::arg("threads") = kDefaults.threads, py::arg("seed") = kDefaults.seed,
     py::arg("surface_source") = "surface", py::arg("process_source") = "process",
     "polish-plan's call with its defaults and ranges (the same names, units in them): the region sampled, the "
     "path planned (optimised with optimise='nlopt' or 'pso'), simulated and timed for target_removal_um. "
     "guides None: boundary offsets, and the optimiser chooses the family; given, it keeps it. offset_mm None: 8 mm "
     "for the cycloid, one contact width for the zig-zag. surface_source and process_source name the files in "
     "errors. The GIL is released while it runs.");

  py::class_<workflows::PolishSimulation>(m, "PolishSimulation", "A path file simulated on a surface (polish-sim's result).")
      .def_property_readonly("removal_m", [](const workflows::PolishSimulation& r) { return r.removal; },
                             "removal at every grid point [m]")
      .def_property_readonly("stats", [](const workflows::PolishSimulation& r) { return StatsDict(r.stats); })
      .def_readonly("max_speed_m_per_s", &workflows::PolishSimulation::max_speed)
      .def_readonly("speed_limit_exceeded", &workflows::PolishSimulation::speed_limit_exceeded,
                    "polish-sim exits 3: a segment faster than the process's max_speed beyond the file's rounding")
      .def_property_readonly("status", [](const workflows::PolishSimulation& r) { return robomach::ToString(r.status()); },
                             "'ok' or 'flagged'")
      .def_property_readonly("findings", [](const workflows::PolishSimulation& r) { return FindingMessages(r.verdict); },
                             "why it is flagged (polish-sim's warnings)")
      .def_property_readonly("rows", [](const workflows::PolishSimulation& r) { return r.file.rows.size(); })
      .def("__repr__", [](const workflows::PolishSimulation& r) {
        return "<PolishSimulation " + std::to_string(r.file.rows.size()) + " rows>";
      });
  m.def("simulate_polish_path", [](const SurfacePtr& surface, const PolishingProcess& process, const std::string& path,
                                   double sample_mm, const std::string& surface_source, const std::string& process_source) {
    RequireReadableFile(path);
    if (!(sample_mm > 0.0 && sample_mm <= 0.5)) throw std::invalid_argument("sample_mm: expected in (0, 0.5]");
    py::gil_scoped_release release;
    return workflows::SimulatePolishPathFile(*surface, process, path, MmToM(sample_mm), surface_source, process_source);
  }, py::arg("surface").none(false), py::arg("process"), py::arg("path"), py::arg("sample_mm") = 0.5,
     py::arg("surface_source") = "surface", py::arg("process_source") = "process",
     "polish-sim's call: the tool path file (docs/formats.md §6) attached to the surface and simulated "
     "(Hertz contact, Preston removal) on the region sampled every sample_mm.");
  m.def("write_simulated_removal_map", [](const std::string& path, const workflows::PolishSimulation& r) {
    io::WriteRemovalMap(path, *r.grid, r.removal);
  }, py::arg("path"), py::arg("simulation"), "polish-sim's --removal, atomic.");

  m.def("write_polish_path", [](const std::string& path, const PyPlan& plan) {
    io::WritePolishPath(path, plan.outcome.plan.path.rows, workflows::PlannedPathMetadata(plan.outcome.params, plan.context.process));
  }, py::arg("path"), py::arg("plan"), "polish-plan's --path (docs/formats.md §6), atomic.");
  m.def("write_removal_map", [](const std::string& path, const PyPlan& plan) {
    io::WriteRemovalMap(path, *plan.context.grid, plan.outcome.plan.removal);
  }, py::arg("path"), py::arg("plan"), "polish-plan's --removal, atomic.");

  const workflows::PolishPlanOptions kPlan;  // polish-plan's defaults
  m.def("run_polish_plan",
        [](const std::string& surface, const std::string& process, std::optional<int> face, double cad_unit_scale,
           const std::string& pattern, const std::optional<std::string>& guides, std::optional<double> offset_mm,
           double radius_mm, double pitch_mm, double edge_inset_mm, double sample_mm, double row_step_mm,
           double opt_sample_mm, double opt_offset_max_mm, double opt_offset_min_contact_widths,
           double stagger_loops, double line_angle_deg, double edge_overrun_mm, double target_removal_um,
           const std::string& optimise, double max_time_s, int threads, unsigned seed) {
          workflows::PolishPlanOptions o;
          o.surface_path = surface;
          o.process_path = process;
          o.surface_choice.cad_face = face.value_or(0);
          o.surface_choice.cad_face_given = face.has_value();
          o.surface_choice.cad_unit_scale = cad_unit_scale;
          o.pattern = pattern;
          if (guides) o.guides = *guides;
          o.guides_given = guides.has_value();  // the optimiser keeps a family the caller chose
          o.offset_mm = offset_mm;
          o.radius_mm = radius_mm;
          o.pitch_mm = pitch_mm;
          o.edge_inset_mm = edge_inset_mm;
          o.sample_mm = sample_mm;
          o.row_step_mm = row_step_mm;
          o.opt_sample_mm = opt_sample_mm;
          o.opt_offset_max_mm = opt_offset_max_mm;
          o.opt_offset_min_contact_widths = opt_offset_min_contact_widths;
          o.stagger_loops = stagger_loops;
          o.line_angle_deg = line_angle_deg;
          o.edge_overrun_mm = edge_overrun_mm;
          o.target_removal_um = target_removal_um;
          o.optimise = optimise;
          o.max_time_s = max_time_s;
          o.threads = threads;
          o.seed = seed;
          o.Validate();
          RequireReadableFile(surface);
          RequireReadableFile(process);
          CollectedMessages said;
          workflows::PolishPlanRun run;
          {
            // The GIL stays held for a STEP/IGES file: OpenCASCADE's readers
            // keep global state (see load_surface).
            std::optional<py::gil_scoped_release> release;
            if (!io::IsCadFile(surface)) release.emplace();
            run = workflows::RunPolishPlan(o, said.Sink());
          }
          for (const std::string& f : run.input_findings) WarnUnit(f);
          py::dict d;
          d["stats"] = StatsDict(run.outcome.plan.stats);
          d["parameters"] = ParamsDict(run.outcome.params);
          d["messages"] = said.List();
          d["input_findings"] = run.input_findings;
          d["findings"] = FindingMessages(run.outcome.verdict);
          d["status"] = robomach::ToString(run.status());
          d["flagged"] = run.flagged();
          d["summary"] = py::module_::import("json").attr("loads")(run.Summary(o).dump());
          auto plan = std::make_unique<PyPlan>();
          plan->surface = std::const_pointer_cast<NurbsSurface>(run.surface);
          plan->context = std::move(run.context);  // points at *run.surface, which plan->surface keeps
          plan->outcome = std::move(run.outcome);
          d["plan"] = py::cast(plan.release(), py::return_value_policy::take_ownership);
          return d;
        },
        py::arg("surface"), py::arg("process"), py::arg("face") = py::none(),
        py::arg("cad_unit_scale") = kPlan.surface_choice.cad_unit_scale, py::arg("pattern") = kPlan.pattern,
        py::arg("guides") = py::none(), py::arg("offset_mm") = py::none(), py::arg("radius_mm") = kPlan.radius_mm,
        py::arg("pitch_mm") = kPlan.pitch_mm, py::arg("edge_inset_mm") = kPlan.edge_inset_mm,
        py::arg("sample_mm") = kPlan.sample_mm, py::arg("row_step_mm") = kPlan.row_step_mm,
        py::arg("opt_sample_mm") = kPlan.opt_sample_mm, py::arg("opt_offset_max_mm") = kPlan.opt_offset_max_mm,
        py::arg("opt_offset_min_contact_widths") = kPlan.opt_offset_min_contact_widths,
        py::arg("stagger_loops") = kPlan.stagger_loops, py::arg("line_angle_deg") = kPlan.line_angle_deg,
        py::arg("edge_overrun_mm") = kPlan.edge_overrun_mm, py::arg("target_removal_um") = kPlan.target_removal_um,
        py::arg("optimise") = kPlan.optimise, py::arg("max_time_s") = kPlan.max_time_s,
        py::arg("threads") = kPlan.threads, py::arg("seed") = kPlan.seed,
        "polish-plan as one call (workflows::RunPolishPlan): a surface file (NURBS YAML, or a STEP/IGES file with "
        "face: 1-based, None: the largest; cad_unit_scale) and a process file, the tool's options under their names "
        "without dashes (guides None: offsets, the optimiser chooses the family; offset_mm None: 8 mm for the "
        "cycloid, one contact width for the zig-zag). Returns a dict: plan (PolishPlan, for write_polish_path and "
        "write_removal_map), stats, parameters, messages ({kind, text}), input_findings (the process file's and the "
        "options' unit findings, also as UnitWarning), findings (the plan's), status, flagged (the tool's exit 3 "
        "without --robot) and summary (the tool's --summary JSON but for warnings and the robot block). ValueError "
        "naming the option; FileNotFoundError, InputError for files. Releases the GIL (not while a STEP/IGES file "
        "is read).");
}

}  // namespace robomach::python
