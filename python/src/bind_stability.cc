// Python bindings of chatter stability (docs/python.md): the cut file, the
// tool tips of stability-lobes' three sources, its lobes (ComputeLobes, the
// call the tool makes) and the lobes CSV; stability-map's per-point analysis
// (EvaluateStabilityMap) on targets the caller gives or a region file makes.
#include <cctype>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/lobes_file.h"
#include "robomach/io/region_file.h"
#include "robomach/io/tip_dynamics_files.h"
#include "robomach/workflows/stability_lobes.h"
#include "robomach/workflows/stability_map.h"
#include "robomach/workflows/tip_sources.h"
#include "robomach/stability/lobes_workflow.h"
#include "robomach/stability/stability_map.h"
#include "robomach/stability/tip_dynamics.h"

namespace robomach::python {
namespace {

using stability::TipDynamics;

std::string AxisText(const Eigen::Vector3d& a) {
  return "tool_axis " + FormatDouble(a(0)) + "," + FormatDouble(a(1)) + "," + FormatDouble(a(2));
}

// The cutting frame of a tool axis and the cut's feed, as stability-lobes
// makes it (an InputError naming the cut file's feed_direction).
Eigen::Matrix3d FrameOf(const io::CutSpec& cut, const Eigen::Vector3d& tool_axis) {
  if (!(tool_axis.norm() > 0.0)) throw std::invalid_argument("tool_axis: expected a non-zero vector");
  return workflows::CutFrame(cut, tool_axis, AxisText(tool_axis));
}

// An options struct's OptionError with its fields named as a call's keywords
// (`keywords`: field -> keyword, e.g. MapOptions' "rotation_min" ->
// "rotation_min_rad"), in field() and in the message, whole words only: the
// ValueError names what the caller typed.
OptionError WithKeywords(const OptionError& e, const std::map<std::string, std::string>& keywords) {
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  const std::string msg = e.what();
  std::string out;
  for (size_t i = 0; i < msg.size();) {
    size_t j = i;
    while (j < msg.size() && word(msg[j])) ++j;
    if (j == i) {
      out += msg[i++];
      continue;
    }
    const auto it = keywords.find(msg.substr(i, j - i));
    out += it == keywords.end() ? msg.substr(i, j - i) : it->second;
    i = j;
  }
  const auto f = keywords.find(e.field());
  return OptionError(f == keywords.end() ? e.field() : f->second, out);
}

py::array_t<std::complex<double>> ToArray2(const std::vector<Eigen::Matrix2cd>& phi) {
  py::array_t<std::complex<double>> a({static_cast<py::ssize_t>(phi.size()), py::ssize_t{2}, py::ssize_t{2}});
  auto r = a.mutable_unchecked<3>();
  for (size_t k = 0; k < phi.size(); ++k) {
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) r(static_cast<py::ssize_t>(k), i, j) = phi[k](i, j);
    }
  }
  return a;
}

}  // namespace

void BindStability(py::module_& m) {
  py::class_<io::CutSpec>(m, "Cut",
                          "A cut file (docs/formats.md, config/cut_demo.yaml): the milling process, the tool, the "
                          "feed direction and the spindle speed range. Read one with read_cut_file().")
      .def_property_readonly("path", [](const io::CutSpec& c) { return c.path; })
      .def_property_readonly("teeth", [](const io::CutSpec& c) { return c.process.teeth; })
      .def_property_readonly("radial_immersion", [](const io::CutSpec& c) { return c.process.radial_immersion; },
                             "a_e/D")
      .def_property_readonly("down_milling",
                             [](const io::CutSpec& c) { return c.process.direction == stability::MillingDirection::kDown; })
      .def_property_readonly("tool_diameter_m", [](const io::CutSpec& c) { return c.tool_diameter; })
      .def_property_readonly("feed_direction", [](const io::CutSpec& c) { return c.feed_direction_B; },
                             "unit vector in the base frame")
      .def_property_readonly("spindle_speed_min_rpm",
                             [](const io::CutSpec& c) { return RadPerSecToRpm(c.spindle_speed_min_rad_s); })
      .def_property_readonly("spindle_speed_max_rpm",
                             [](const io::CutSpec& c) { return RadPerSecToRpm(c.spindle_speed_max_rad_s); })
      .def_property_readonly("spindle_speed_count", [](const io::CutSpec& c) { return c.spindle_speed_count; })
      .def("__repr__", [](const io::CutSpec& c) {
        return "<Cut " + c.path + ": " + std::to_string(c.process.teeth) + " teeth, a_e/D " +
               FormatDouble(c.process.radial_immersion) + ">";
      });
  m.def("read_cut_file", [](const std::string& path) {
    RequireReadableFile(path);
    io::CutSpec cut = io::ReadCutFile(path);
    for (const std::string& w : cut.implausible) WarnUnit(w);
    return cut;
  }, py::arg("path"),
     "Reads a cut file (YAML). Raises InputError naming file, line and column; a UnitWarning per value outside "
     "its plausible range (docs/plausibility.md), where stability-lobes exits 3.");

  py::class_<TipDynamics>(m, "TipDynamics",
                          "The tool tip of one source, oriented into the cutting frame C (x along the feed, z "
                          "along the tool axis): what the lobes are computed from.")
      .def_readonly("id", &TipDynamics::id)
      .def_property_readonly("freq_hz", [](const TipDynamics& t) { return Eigen::VectorXd(t.freq_hz); },
                             "the lines of the in-plane FRF [Hz]")
      .def_property_readonly("phi_c", [](const TipDynamics& t) { return ToArray2(t.Phi_C); },
                             "in-plane oriented receptance, complex (lines, 2, 2) [m/N]")
      .def_property_readonly("num_modes", [](const TipDynamics& t) { return t.modes_C.num_modes(); })
      .def_property_readonly("mode_freq_hz",
                             [](const TipDynamics& t) { return Eigen::VectorXd(t.modes_C.omega_rad_s / (2.0 * kPi)); })
      .def_property_readonly("mode_damping_ratio", [](const TipDynamics& t) { return Eigen::VectorXd(t.modes_C.zeta); })
      .def_readonly("modes_fitted", &TipDynamics::modes_fitted)
      .def_readonly("unit_finding", &TipDynamics::unit_finding,
                    "the measured FRFs' receptance outside the plausible range (a unit mistake); stability_lobes "
                    "warns and flags it; empty when plausible")
      .def_property_readonly("R_BC", [](const TipDynamics& t) { return Eigen::Matrix3d(t.R_BC); },
                             "the cutting frame in the source's frame")
      .def_property_readonly("fit_labels", [](const TipDynamics& t) {
        std::vector<std::string> l;
        for (const auto& f : t.fits) l.push_back(f.label);
        return l;
      }, "the direct FRFs fitted (measured sources)")
      .def("__repr__", [](const TipDynamics& t) {
        return "<TipDynamics " + t.id + ": " + std::to_string(t.freq_hz.size()) + " lines, " +
               std::to_string(t.modes_C.num_modes()) + " modes>";
      });

  m.def("tip_from_posture", [](const std::shared_ptr<dynamics::RobotModel>& model, const Eigen::VectorXd& q, const io::CutSpec& cut,
                               const std::string& id) {
    py::gil_scoped_release release;
    const dynamics::PostureDynamics d = dynamics::EvaluatePosture(model, q, {.cartesian = true, .modes = true});
    try {
      return stability::TipFromPosture(id, d, cut.feed_direction_B, cut.process.teeth, cut.spindle_speed_max_rad_s);
    } catch (const std::invalid_argument& e) {
      throw InputError({cut.path, cut.feed_line, cut.feed_column}, std::string("feed_direction: ") + e.what());
    }
  }, py::arg("model").none(false), py::arg("q"), py::arg("cut"), py::arg("id") = "P",
     "The tool tip of the robot model at posture q [rad], as stability-lobes --robot makes it.");

  m.def("tips_from_modal_table", [](const std::string& path, const io::CutSpec& cut, const Eigen::Vector3d& tool_axis,
                                    const std::vector<std::string>& poses) {
    RequireReadableFile(path);
    return workflows::TipsFromModalTableFile(path, poses, FrameOf(cut, tool_axis), cut);
  }, py::arg("path"), py::arg("cut"), py::arg("tool_axis") = Eigen::Vector3d::UnitZ(),
     py::arg("poses") = std::vector<std::string>{},
     "The tool tips of a modal table (docs/formats.md §4), as stability-lobes --modal-table makes them.");

  m.def("tips_from_frf_file", [](const std::string& path, const io::CutSpec& cut, const Eigen::Vector3d& tool_axis,
                                 const std::optional<std::string>& frf_y, const std::vector<std::string>& poses,
                                 int sd_modes) {
    RequireReadableFile(path);
    if (frf_y) RequireReadableFile(*frf_y);
    stability::MeasuredTipOptions o;
    o.frf_path = path;
    o.frf_y_path = frf_y.value_or("");
    o.pose_ids = poses;
    o.cutting_frame = [&cut, tool_axis] { return FrameOf(cut, tool_axis); };
    o.tool_axis_source = AxisText(tool_axis);
    o.sd_modes = sd_modes;
    o.Validate();  // before the files are read (ValueError naming sd_modes)
    CollectedMessages said;
    std::vector<TipDynamics> tips;
    {
      py::gil_scoped_release release;
      tips = workflows::TipsFromFrfFiles(o, said.Sink());
    }
    return py::make_tuple(tips, said.List());
  }, py::arg("path"), py::arg("cut"), py::arg("tool_axis") = Eigen::Vector3d::UnitZ(), py::arg("frf_y") = py::none(),
     py::arg("poses") = std::vector<std::string>{}, py::arg("sd_modes") = 3,
     "The tool tips of a measured FRF file (CSV or UFF58), each direct FRF with a noise model and a modal fit, "
     "as stability-lobes --frf makes them. Returns (tips, messages): messages are dicts {kind: 'info' | 'note' | "
     "'warning', text} (the reader's warnings, the fits); a receptance outside the plausible range is each tip's "
     "unit_finding, and stability_lobes warns and flags it.");

  m.def("stability_lobes", [](const std::vector<TipDynamics>& tips, const io::CutSpec& cut, const std::string& method,
                              int speeds, int sd_speeds, int sd_steps, double sd_steps_per_mode_period, int sd_modes,
                              double sd_max_depth_mm, int max_lobe, int threads) {
    // The tool's options and their checks (workflows::StabilityLobesOptions).
    workflows::StabilityLobesOptions wo;
    wo.method = stability::ParseLobeMethod(method);
    wo.speeds = speeds;
    wo.sd_speeds = sd_speeds;
    wo.sd_steps = sd_steps;
    wo.sd_steps_per_mode_period = sd_steps_per_mode_period;
    wo.sd_modes = sd_modes;
    wo.sd_max_depth_mm = sd_max_depth_mm;
    wo.max_lobe = max_lobe;
    wo.threads = threads;
    wo.ValidateSettings();
    const stability::LobesOptions o = workflows::MakeLobesOptions(cut, wo);
    CollectedMessages said;
    stability::LobesResult r;
    {
      py::gil_scoped_release release;
      r = stability::ComputeLobes(tips, o, said.Sink());
    }
    return py::make_tuple(r, said.List());
  }, py::arg("tips"), py::arg("cut"), py::arg("method") = "zoa", py::arg("speeds") = 0, py::arg("sd_speeds") = 60,
     py::arg("sd_steps") = 0, py::arg("sd_steps_per_mode_period") = stability::SdOptions{}.steps_per_mode_period,
     py::arg("sd_modes") = 3, py::arg("sd_max_depth_mm") = 20.0, py::arg("max_lobe") = 30, py::arg("threads") = 0,
     "Stability lobes of the tool tips, as stability-lobes computes them (the same options, the same defaults): "
     "method 'zoa', 'sd' or 'both'; speeds = ZOA speeds in the cut's range (0: the cut's count). Returns "
     "(Lobes, messages). The GIL is released while it runs.");

  const workflows::StabilityLobesOptions kLobes;  // the tool's defaults
  m.def("run_stability_lobes",
        [](const std::string& cut, const std::optional<std::string>& robot, const std::optional<std::string>& postures,
           const std::optional<std::string>& frf, const std::optional<std::string>& frf_y,
           const std::optional<std::string>& modal_table, const std::vector<std::string>& poses,
           const Eigen::Vector3d& tool_axis, const std::string& method, int speeds, int max_lobe, int sd_speeds,
           int sd_steps, double sd_steps_per_mode_period, int sd_modes, double sd_max_depth_mm, int threads) {
          workflows::StabilityLobesOptions o;
          o.cut_path = cut;
          o.robot_path = robot.value_or("");
          o.postures_path = postures.value_or("");
          o.frf_path = frf.value_or("");
          o.frf_y_path = frf_y.value_or("");
          o.modal_table_path = modal_table.value_or("");
          o.pose_ids = poses;
          o.tool_axis = tool_axis;
          o.method = stability::ParseLobeMethod(method);
          o.speeds = speeds;
          o.max_lobe = max_lobe;
          o.sd_speeds = sd_speeds;
          o.sd_steps = sd_steps;
          o.sd_steps_per_mode_period = sd_steps_per_mode_period;
          o.sd_modes = sd_modes;
          o.sd_max_depth_mm = sd_max_depth_mm;
          o.threads = threads;
          o.Validate();
          for (const std::string* p : {&o.cut_path, &o.robot_path, &o.postures_path, &o.frf_path, &o.frf_y_path,
                                       &o.modal_table_path}) {
            if (!p->empty()) RequireReadableFile(*p);
          }
          CollectedMessages said;
          workflows::StabilityLobesRun run;
          {
            py::gil_scoped_release release;
            run = workflows::RunStabilityLobes(o, said.Sink());
          }
          for (const std::string& f : run.input_findings) WarnUnit(f);
          py::dict d;
          d["lobes"] = run.lobes;
          d["tips"] = run.tips;
          d["messages"] = said.List();
          d["input_findings"] = run.input_findings;
          d["flagged"] = run.flagged();
          d["summary"] = py::module_::import("json").attr("loads")(run.Summary(o).dump());
          return d;
        },
        py::arg("cut"), py::arg("robot") = py::none(), py::arg("postures") = py::none(), py::arg("frf") = py::none(),
        py::arg("frf_y") = py::none(), py::arg("modal_table") = py::none(),
        py::arg("poses") = std::vector<std::string>{}, py::arg("tool_axis") = Eigen::Vector3d::UnitZ(),
        py::arg("method") = "zoa", py::arg("speeds") = kLobes.speeds, py::arg("max_lobe") = kLobes.max_lobe,
        py::arg("sd_speeds") = kLobes.sd_speeds, py::arg("sd_steps") = kLobes.sd_steps,
        py::arg("sd_steps_per_mode_period") = kLobes.sd_steps_per_mode_period, py::arg("sd_modes") = kLobes.sd_modes,
        py::arg("sd_max_depth_mm") = kLobes.sd_max_depth_mm, py::arg("threads") = kLobes.threads,
        "stability-lobes as one call (workflows::RunStabilityLobes): the cut file and one tool-tip source (robot "
        "with postures, frf (and frf_y), or modal_table), the tool's options under their names without dashes. "
        "Returns a dict: lobes (Lobes), tips, messages (dicts {kind, text}, what the tool prints), input_findings "
        "(the cut's and robot config's unit findings, also as UnitWarning), flagged (the tool's exit 3) and "
        "summary (the tool's --summary JSON but for tool, lobes_csv and exit_code). ValueError naming the "
        "option for a bad value; FileNotFoundError, InputError for files. Releases the GIL.");

  py::class_<stability::LobesResult>(m, "Lobes", "The lobes of every tool tip: one row per speed, tip and method.")
      .def_property_readonly("flagged", [](const stability::LobesResult& r) { return r.verdict.flagged(); },
                             "stability-lobes' exit 3: a modal fit that does not describe a tool tip, ZOA and SD "
                             "more than 10 % apart, or speeds without a boundary")
      .def_property_readonly("run_status", [](const stability::LobesResult& r) { return robomach::ToString(r.status()); },
                             "'ok' or 'flagged' (`status` is each row's)")
      .def_property_readonly("findings", [](const stability::LobesResult& r) { return FindingMessages(r.verdict); },
                             "why it is flagged, one sentence each (also among the messages, as warnings)")
      .def_readonly("no_boundary", &stability::LobesResult::no_boundary, "some speeds have no stability boundary")
      .def_property_readonly("pose_id", [](const stability::LobesResult& r) {
        std::vector<std::string> v;
        for (const auto& row : r.rows) v.push_back(row.id);
        return v;
      })
      .def_property_readonly("method", [](const stability::LobesResult& r) {
        std::vector<std::string> v;
        for (const auto& row : r.rows) v.push_back(row.method);
        return v;
      })
      .def_property_readonly("status", [](const stability::LobesResult& r) {
        std::vector<std::string> v;
        for (const auto& row : r.rows) v.push_back(stability::ToString(row.point.status));
        return v;
      })
      .def_property_readonly("spindle_speed_rpm", [](const stability::LobesResult& r) {
        Eigen::VectorXd v(r.rows.size());
        for (size_t i = 0; i < r.rows.size(); ++i) v(i) = io::LobeSpeedRpm(r.rows[i].point.spindle_speed_rad_s);
        return v;
      })
      .def_property_readonly("critical_depth_mm", [](const stability::LobesResult& r) {
        Eigen::VectorXd v(r.rows.size());
        for (size_t i = 0; i < r.rows.size(); ++i) v(i) = MToMm(r.rows[i].point.critical_depth);
        return v;
      }, "NaN where a speed has no boundary")
      .def_property_readonly("chatter_freq_hz", [](const stability::LobesResult& r) {
        Eigen::VectorXd v(r.rows.size());
        for (size_t i = 0; i < r.rows.size(); ++i) v(i) = r.rows[i].point.chatter_freq_hz;
        return v;
      })
      .def_property_readonly("lobe_index", [](const stability::LobesResult& r) {
        std::vector<int> v;
        for (const auto& row : r.rows) v.push_back(row.point.lobe_index);
        return v;
      }, "-1 where none")
      .def("__len__", [](const stability::LobesResult& r) { return r.rows.size(); })
      .def("__repr__", [](const stability::LobesResult& r) {
        return "<Lobes " + std::to_string(r.rows.size()) + " rows" + (r.verdict.flagged() ? ", flagged" : "") + ">";
      });
  m.def("write_lobes_csv", [](const std::string& path, const stability::LobesResult& r) {
    io::WriteLobesCsv(path, r.rows);
  }, py::arg("path"), py::arg("lobes"), "Writes the lobes CSV of stability-lobes --out (atomic).");

  // ---- stability maps
  py::class_<stability::ToolPoseTarget>(m, "ToolPoseTarget",
                                        "A tool pose of a stability map: TCP position p_BT [m], tool axis z_T "
                                        "(spindle to tip), reference x_ref normal to it, feed direction (all in B).")
      .def(py::init([](const Eigen::Vector3d& p, const Eigen::Vector3d& z, const Eigen::Vector3d& x,
                       const Eigen::Vector3d& feed) {
             return stability::ToolPoseTarget{p, z, x, feed};
           }),
           py::arg("p_BT"), py::arg("z_T") = Eigen::Vector3d::UnitZ(), py::arg("x_ref") = Eigen::Vector3d::UnitX(),
           py::arg("feed") = Eigen::Vector3d::UnitX())
      .def_readwrite("p_BT", &stability::ToolPoseTarget::p_BT)
      .def_readwrite("z_T", &stability::ToolPoseTarget::z_T)
      .def_readwrite("x_ref", &stability::ToolPoseTarget::x_ref)
      .def_readwrite("feed", &stability::ToolPoseTarget::feed_B);

  m.def("region_targets", [](const std::string& path, int num_joints, const io::CutSpec& cut) {
    RequireReadableFile(path);
    const io::RegionSpec region = io::ReadRegionFile(path, num_joints);
    for (const std::string& w : region.implausible) WarnUnit(w);
    py::dict d;
    d["targets"] = region.Targets(cut.feed_direction_B);
    d["rows"] = region.num_v();
    d["cols"] = region.num_u();
    d["seed_q"] = region.seed_q;
    d["rotation_rad"] = region.rotation_fixed;
    d["rotation_free"] = region.rotation_free;
    d["rotation_min_rad"] = region.rotation_min;
    d["rotation_max_rad"] = region.rotation_max;
    return d;
  }, py::arg("path"), py::arg("num_joints"), py::arg("cut"),
     "A region file's grid of tool poses (stability-map --region): dict with targets (row-major), rows, cols, "
     "seed_q [rad], rotation_rad, rotation_free, rotation_min_rad, rotation_max_rad.");

  // One dict per map point (the CSV's columns that are the analysis').
  const auto PointDicts = [](const std::vector<stability::MapPoint>& pts) {
    py::list out;
    for (const auto& p : pts) {
      py::dict d;
      d["status"] = stability::ToString(p.status);
      d["q"] = p.q;
      d["rotation_rad"] = p.rotation;
      d["jacobian_condition"] = p.jacobian_condition;
      d["critical_depth_mm"] = MToMm(p.stability.critical_depth);
      d["limiting_mechanism"] = stability::ToString(p.stability.limiting);
      d["chatter_freq_hz"] = p.stability.chatter_freq_hz;
      d["regenerative_depth_mm"] = MToMm(p.stability.regenerative.critical_depth);
      d["mode_coupling_depth_mm"] = MToMm(p.stability.mode_coupling.critical_depth);
      d["optimiser_status"] = p.optimiser_status;
      out.append(d);
    }
    return out;
  };
  const workflows::StabilityMapOptions kMap;  // the tool's defaults
  m.def("run_stability_map",
        [PointDicts](const std::string& robot, const std::string& cut, const std::string& region,
                     const std::optional<std::string>& path, int threads, int speeds, double max_depth_mm,
                     int rotation_evaluations, const std::vector<std::string>& uncertainty, double confidence,
                     const std::string& uncertainty_method, int samples, std::uint64_t seed) {
          workflows::StabilityMapOptions o;
          o.robot_path = robot;
          o.cut_path = cut;
          o.region_path = region;
          o.path_path = path.value_or("");
          o.threads = threads;
          o.speeds = speeds;
          o.max_depth_mm = max_depth_mm;
          o.rotation_evaluations = rotation_evaluations;
          o.uncertainty_paths = uncertainty;
          o.uncertainty = PropagationFrom(confidence, uncertainty_method, samples, seed);
          o.Validate();
          for (const std::string* p : {&o.robot_path, &o.cut_path, &o.region_path, &o.path_path}) {
            if (!p->empty()) RequireReadableFile(*p);
          }
          CollectedMessages said;
          workflows::StabilityMapRun run;
          {
            py::gil_scoped_release release;
            run = workflows::RunStabilityMap(o, said.Sink());
          }
          for (const std::string& f : run.input_findings) WarnUnit(f);
          py::dict d;
          d["points"] = PointDicts(run.map.points);
          d["rows"] = run.points.rows;
          d["cols"] = run.points.cols;
          if (run.intervals) {
            py::list lower, upper;
            for (const auto& i : run.intervals->depth) {
              lower.append(MToMm(i.lower));
              upper.append(MToMm(i.upper));
            }
            d["critical_depth_mm_lower"] = lower;
            d["critical_depth_mm_upper"] = upper;
          }
          d["messages"] = said.List();
          d["input_findings"] = run.input_findings;
          d["flagged"] = run.status() == RunStatus::kFlagged;
          d["summary"] = py::module_::import("json").attr("loads")(run.Summary(o).dump());
          return d;
        },
        py::arg("robot"), py::arg("cut"), py::arg("region"), py::arg("path") = py::none(),
        py::arg("threads") = kMap.threads, py::arg("speeds") = kMap.speeds, py::arg("max_depth_mm") = kMap.max_depth_mm,
        py::arg("rotation_evaluations") = kMap.rotation_evaluations,
        py::arg("uncertainty") = std::vector<std::string>{}, py::arg("confidence") = dynamics::PropagationOptions{}.confidence,
        py::arg("uncertainty_method") = "auto", py::arg("samples") = dynamics::PropagationOptions{}.samples,
        py::arg("seed") = dynamics::PropagationOptions{}.seed,
        "stability-map as one call (workflows::RunStabilityMap): a robot config, a cut file and a region file "
        "(its grid, or with path a tool-path CSV whose seed posture the region gives), the tool's options under "
        "their names without dashes; parameter-uncertainty files (none: the config's) give each point's interval. "
        "Returns a dict: points (one dict per point, row-major), rows, cols, critical_depth_mm_lower/_upper with "
        "uncertainty, messages ({kind, text}), input_findings (also as UnitWarning), flagged (the tool's exit 3) "
        "and summary (the tool's --summary JSON but for tool, points_csv, warnings and exit_code). ValueError "
        "naming the option; FileNotFoundError, InputError for files. Releases the GIL.");

  m.def("stability_map", [PointDicts](const std::shared_ptr<dynamics::RobotModel>& model, const std::vector<stability::ToolPoseTarget>& targets,
                            int rows, int cols, const io::CutSpec& cut, const Eigen::VectorXd& seed_q, double rotation_rad,
                            bool optimise_rotation, double rotation_min_rad, double rotation_max_rad, int rotation_evaluations,
                            int speeds, double max_depth_mm, int threads) {
    if (const int bad = stability::FirstFeedAlongToolAxis(targets); bad >= 0) {
      throw InputError({cut.path, cut.feed_line, cut.feed_column},
                       "feed_direction is parallel to the tool axis of target " + std::to_string(bad) +
                           "; choose a feed in the work plane");
    }
    // The tool's checks of these settings (ValueError naming the keyword).
    workflows::StabilityMapOptions settings;
    settings.speeds = speeds;
    settings.max_depth_mm = max_depth_mm;
    settings.rotation_evaluations = rotation_evaluations;
    settings.threads = threads;
    settings.ValidateSettings();
    stability::MapOptions o;
    o.seed_q = seed_q;
    o.rotation = rotation_rad;
    o.optimise_rotation = optimise_rotation;
    o.rotation_min = rotation_min_rad;
    o.rotation_max = rotation_max_rad;
    o.rotation_evaluations = rotation_evaluations;
    o.threads = threads;
    o.analysis.spindle_speed_rad_s =
        cut.spindle_speed_rad_s ? cut.SpeedGrid() : cut.SpeedRange(speeds);
    o.analysis.mode_coupling.max_depth = MmToM(max_depth_mm);
    std::vector<stability::MapPoint> pts;
    try {
      py::gil_scoped_release release;
      pts = stability::EvaluateStabilityMap(model, targets, rows, cols, cut.process, o);
    } catch (const OptionError& e) {
      // MapOptions names its fields rotation...; the keywords carry the unit.
      throw WithKeywords(e, {{"rotation", "rotation_rad"}, {"rotation_min", "rotation_min_rad"},
                             {"rotation_max", "rotation_max_rad"}});
    }
    return PointDicts(pts);
  }, py::arg("model").none(false), py::arg("targets"), py::arg("rows"), py::arg("cols"), py::arg("cut"), py::arg("seed_q"),
     py::arg("rotation_rad") = 0.0, py::arg("optimise_rotation") = false,
     py::arg("rotation_min_rad") = -0.5 * kPi, py::arg("rotation_max_rad") = 0.5 * kPi, py::arg("rotation_evaluations") = 20, py::arg("speeds") = 0,
     py::arg("max_depth_mm") = 50.0, py::arg("threads") = 0,
     "stability-map's analysis of rows × cols tool poses (row-major; rows = 1: a path): IK from seed_q [rad] "
     "along the grid, then mode coupling and the regenerative ZOA at each point, as EvaluateStabilityMap. "
     "Returns one dict per point (status, q [rad], critical_depth_mm, limiting_mechanism, ...). Defaults as "
     "stability-map's (max_depth_mm: the mode coupling's search range). The GIL is "
     "released while it runs.");
}

}  // namespace robomach::python
