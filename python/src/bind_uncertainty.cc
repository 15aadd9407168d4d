// Python bindings of parameter uncertainty (issue #37, docs/uncertainty.md):
// the uncertainty file, kq-identify's covariance as one, and its propagation
// to any function, to a posture's modes and to a tool tip's ZOA lobes.
#include <cmath>
#include <string>
#include <vector>

#include "bindings.h"
#include "robomach/common/units.h"
#include "robomach/identification/joint_stiffness.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/stability/lobe_uncertainty.h"
#include "robomach/workflows/stability_lobes.h"

namespace robomach::python {
namespace {

using dynamics::ParameterUncertainty;

py::dict IntervalDict(const dynamics::OutputInterval& i) {
  py::dict d;
  d["value"] = i.value;
  d["std_dev"] = i.std_dev;
  d["lower"] = i.lower;
  d["upper"] = i.upper;
  return d;
}

void AddHow(const dynamics::PropagationResult& r, py::dict* d) {
  (*d)["method"] = dynamics::ToString(r.method_used);
  (*d)["reason"] = r.reason;
  (*d)["evaluations"] = r.evaluations;
  (*d)["failed_samples"] = r.failed_samples;
  (*d)["linearised"] = r.linearised;
}

}  // namespace

void BindUncertainty(py::module_& m) {
  py::class_<ParameterUncertainty>(
      m, "ParameterUncertainty",
      "Estimates of fitted parameters and the covariance of their coordinates theta = value ('linear'), "
      "log(value) ('log') or 1/value ('inverse'): docs/formats.md §12.")
      .def(py::init([](const std::vector<std::tuple<std::string, double, std::string>>& parameters,
                       const Eigen::MatrixXd& covariance, const std::string& source) {
             ParameterUncertainty u;
             for (const auto& [name, value, scale] : parameters) {
               u.parameters.push_back({name, value, dynamics::ParseUncertainScale(scale)});
             }
             u.covariance = covariance;
             u.source = source;
             dynamics::CheckValid(u);
             return u;
           }),
           py::arg("parameters"), py::arg("covariance"), py::arg("source") = "",
           "parameters: [(name, value, scale)], covariance: n x n of theta. ValueError naming what is wrong.")
      .def_property_readonly("names", [](const ParameterUncertainty& u) {
        std::vector<std::string> n;
        for (const auto& p : u.parameters) n.push_back(p.name);
        return n;
      })
      .def_property_readonly("values", [](const ParameterUncertainty& u) {
        Eigen::VectorXd v(static_cast<Eigen::Index>(u.parameters.size()));
        for (size_t i = 0; i < u.parameters.size(); ++i) v(static_cast<Eigen::Index>(i)) = u.parameters[i].value;
        return v;
      }, "the estimates, each in its parameter's unit")
      .def_property_readonly("scales", [](const ParameterUncertainty& u) {
        std::vector<std::string> s;
        for (const auto& p : u.parameters) s.push_back(dynamics::ToString(p.scale));
        return s;
      })
      .def_readonly("covariance", &ParameterUncertainty::covariance)
      .def_readonly("source", &ParameterUncertainty::source)
      .def("__repr__", [](const ParameterUncertainty& u) {
        return "<ParameterUncertainty " + std::to_string(u.parameters.size()) + " parameters from " + u.source + ">";
      });
  m.def("read_parameter_uncertainty", [](const std::vector<std::string>& paths) {
    for (const std::string& p : paths) RequireReadableFile(p);
    return io::ReadParameterUncertainties(paths);
  }, py::arg("paths"),
     "Reads one or several uncertainty files (docs/formats.md §12); several are independent campaigns. "
     "InputError at file:line:col.");
  m.def("write_parameter_uncertainty", &io::WriteParameterUncertainty, py::arg("path"), py::arg("uncertainty"),
        "Writes the file kq-identify --uncertainty-out writes (atomically).");
  m.def("stiffness_uncertainty", &identification::StiffnessUncertainty, py::arg("result"), py::arg("source") = "",
        "The determined joints' stiffnesses of an identify_joint_stiffness() result, on the inverse scale "
        "(compliances), as kq-identify --uncertainty-out writes them.");

  m.def("propagate", [](const ParameterUncertainty& u, const py::function& f, double confidence,
                        const std::string& method, int samples, std::uint64_t seed,
                        const std::optional<py::function>& linearisation) {
    dynamics::OutputFunction lin;
    if (linearisation) {
      lin = [&](const Eigen::VectorXd& v) { return (*linearisation)(v).cast<Eigen::VectorXd>(); };
    }
    const dynamics::PropagationResult r = dynamics::Propagate(
        u, [&](const Eigen::VectorXd& v) { return f(v).cast<Eigen::VectorXd>(); },
        PropagationFrom(confidence, method, samples, seed), {}, lin);
    py::dict d;
    py::list outs;
    for (const auto& o : r.outputs) outs.append(IntervalDict(o));
    d["outputs"] = outs;
    AddHow(r, &d);
    return d;
  }, py::arg("uncertainty"), py::arg("f"), py::arg("confidence") = 0.95, py::arg("method") = "auto",
     py::arg("samples") = 2000, py::arg("seed") = 1, py::arg("linearisation") = py::none(),
     "Intervals of f(values) -> 1-D array (values in the parameters' units, in the uncertainty's order): "
     "first order, Monte Carlo, or auto (first order unless the sigma-point check finds f bending). "
     "linearisation: a local model of f (equal to first order at the estimates, smooth at 1e-3 sigma) whose "
     "differences give the first-order derivatives instead of f's. "
     "Returns {outputs: [{value, std_dev, lower, upper}], method, reason, evaluations, failed_samples, "
     "linearised}.");

  m.def("modal_intervals", [](const io::RobotConfig& config, const ParameterUncertainty& u,
                              const std::optional<Eigen::VectorXd>& q_rad, const std::optional<Eigen::VectorXd>& q_deg,
                              double confidence, const std::string& method, int samples, std::uint64_t seed) {
    const Eigen::VectorXd q = JointAnglesRad("modal_intervals", q_rad, q_deg);
    dynamics::ParameterSet params = config.parameters;
    dynamics::UseEstimates(u, &params);
    dynamics::PostureModeIntervals r;
    {
      py::gil_scoped_release release;
      r = dynamics::ModalIntervals(config.description, params, q, u, PropagationFrom(confidence, method, samples, seed));
    }
    py::dict d;
    py::list modes;
    for (const dynamics::ModeIntervals& mi : r.modes) {
      py::dict md;
      md["freq_hz"] = IntervalDict(mi.freq_hz);
      md["damping_ratio"] = IntervalDict(mi.damping_ratio);
      md["peak_receptance_m_per_N"] = IntervalDict(mi.peak_receptance_m_per_N);
      modes.append(md);
    }
    d["modes"] = modes;
    AddHow(r.propagation, &d);
    return d;
  }, py::arg("config"), py::arg("uncertainty"), py::arg("q_rad") = py::none(), py::kw_only(),
     py::arg("q_deg") = py::none(), py::arg("confidence") = 0.95, py::arg("method") = "auto",
     py::arg("samples") = 2000, py::arg("seed") = 1,
     "Each mode's interval of frequency, damping ratio and peak receptance at posture q (the uncertainty's "
     "estimates replace the config's values), as frf-predict --uncertainty. Returns {modes: [{freq_hz: "
     "{value, std_dev, lower, upper}, damping_ratio: ..., peak_receptance_m_per_N: ...}], method, reason, ...}.");

  m.def("zoa_lobe_band", [](const io::RobotConfig& config, const io::CutSpec& cut, const ParameterUncertainty& u,
                            const std::optional<Eigen::VectorXd>& q_rad, const std::optional<Eigen::VectorXd>& q_deg,
                            int speeds, double confidence, const std::string& method, int samples, std::uint64_t seed,
                            const std::string& id) {
    const Eigen::VectorXd q = JointAnglesRad("zoa_lobe_band", q_rad, q_deg);
    dynamics::ParameterSet params = config.parameters;
    dynamics::UseEstimates(u, &params);
    workflows::StabilityLobesOptions so;
    so.speeds = speeds;
    so.ValidateSettings();
    const stability::LobesOptions lo = workflows::MakeLobesOptions(cut, so);
    stability::ZoaBand b;
    {
      py::gil_scoped_release release;
      b = stability::ZoaLobeBand(config.description, params, id, q, cut.feed_direction_B, lo, u,
                                 PropagationFrom(confidence, method, samples, seed));
    }
    py::dict d;
    Eigen::VectorXd rpm(b.speed_rad_s.size()), depth(b.speed_rad_s.size()), lower(b.speed_rad_s.size()),
        upper(b.speed_rad_s.size());
    for (Eigen::Index i = 0; i < b.speed_rad_s.size(); ++i) {
      rpm(i) = RadPerSecToRpm(b.speed_rad_s(i));
      depth(i) = MToMm(b.depth[static_cast<size_t>(i)].value);
      lower(i) = MToMm(b.depth[static_cast<size_t>(i)].lower);
      upper(i) = MToMm(b.depth[static_cast<size_t>(i)].upper);
    }
    d["spindle_speed_rpm"] = rpm;
    d["critical_depth_mm"] = depth;
    d["critical_depth_mm_lower"] = lower;
    d["critical_depth_mm_upper"] = upper;
    d["min_critical_depth_mm"] = MToMm(b.min_depth.value);
    d["min_critical_depth_mm_lower"] = MToMm(b.min_depth.lower);
    d["min_critical_depth_mm_upper"] = MToMm(b.min_depth.upper);
    AddHow(b.propagation, &d);
    return d;
  }, py::arg("config"), py::arg("cut"), py::arg("uncertainty"), py::arg("q_rad") = py::none(), py::kw_only(),
     py::arg("q_deg") = py::none(), py::arg("speeds") = 0, py::arg("confidence") = 0.95, py::arg("method") = "auto",
     py::arg("samples") = 2000, py::arg("seed") = 1, py::arg("id") = "P",
     "The ZOA lobes of the robot's tool tip at posture q with each speed's interval [mm] and the smallest "
     "critical depth's (its lower end: the safe depth), as stability-lobes --robot --uncertainty. speeds: "
     "0 = the cut file's count.");
}

}  // namespace robomach::python
