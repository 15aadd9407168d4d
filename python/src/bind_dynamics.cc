// Robot configs, models, posture evaluation, tool-tip receptance and
// posture files (include/robomach/dynamics, io/robot_config.h,
// io/posture_file.h, io/prediction_files.h).
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <tuple>

#include "bindings.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/frf_prediction.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/robot_config.h"
#include "robomach/common/number_format.h"
#include "robomach/workflows/frf_predict.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::python {
namespace {

using dynamics::Mode;
using dynamics::ParameterSet;
using dynamics::ParameterSpec;
using dynamics::PostureDynamics;
using dynamics::PostureEvaluator;
using dynamics::RobotModel;
using io::RobotConfig;

// RobotModel is immutable and shared as shared_ptr<const RobotModel> in the
// library; Python holds it through a shared_ptr to the non-const type
// (pybind11 needs one) and only const members are bound.
using ModelPtr = std::shared_ptr<RobotModel>;
ModelPtr Mutable(std::shared_ptr<const RobotModel> p) { return std::const_pointer_cast<RobotModel>(std::move(p)); }

std::map<std::string, double> ParameterDict(const ParameterSet& p) {
  std::map<std::string, double> out;
  for (const auto& s : p.specs()) out[s.name] = p.Get(s.name);
  return out;
}

// The equivalent of the tools' `--add EFFECT`: dynamics::WithEffect, which
// leaves the config as it was when it throws (an unknown effect).
void AddEffect(RobotConfig* cfg, const std::string& name) {
  std::tie(cfg->description, cfg->parameters) = dynamics::WithEffect(cfg->description, cfg->parameters, name);
}

// `--add` for each of `add`, then `--set` for each of `set`, as the tools do.
RobotConfig LoadConfig(const std::string& path, const std::vector<std::string>& add,
                       const std::map<std::string, double>& set) {
  RequireReadableFile(path);
  RobotConfig cfg;
  {
    py::gil_scoped_release release;
    cfg = workflows::LoadRobotConfigChecked(path);
  }
  // The tools' exit 3 (docs/plausibility.md): a UnitWarning per finding.
  for (const std::string& w : cfg.implausible) WarnUnit(w);
  for (const auto& a : add) AddEffect(&cfg, a);
  for (const auto& [k, v] : set) cfg.parameters.Set(k, v);
  return cfg;
}

std::vector<Eigen::Matrix3cd> ReceptanceByMethod(const PostureDynamics& d, const Eigen::VectorXd& freq_hz,
                                                 const std::string& method) {
  return dynamics::ReceptanceBy(dynamics::ParseReceptanceMethod(method), d, freq_hz);
}

void CheckFrequencies(const Eigen::VectorXd& f) {
  for (Eigen::Index i = 0; i < f.size(); ++i) {
    if (!std::isfinite(f(i))) {
      throw std::invalid_argument("freq_hz[" + std::to_string(i) + "] is not finite");
    }
  }
}

constexpr char kReceptanceDoc[] =
    "Tool-tip receptance H(f) [m/N] in the robot base frame B, a complex array of shape "
    "(len(freq_hz), 3, 3), H[i, r, e] = response r (x, y, z) per excitation e at line i.\n"
    "freq_hz: frequency lines [Hz], finite (0 gives the static compliance).\n"
    "method: 'modal' (superposition of real modes for proportional damping, of complex modes "
    "otherwise; frf-predict's default) or 'direct' (solve (K - w^2 M + i w C) per line).\n"
    "Without the real modes (evaluate(..., modes=False)) 'modal' computes the complex modes here. "
    "Releases the GIL.";

}  // namespace

void BindDynamics(py::module_& m) {
  py::class_<ParameterSpec>(m, "ParameterSpec",
                            "One named model parameter; the name carries the SI unit (m6_kg, d6_m, "
                            "kq3_Nm_per_rad, tip_mass.mass_kg).")
      .def_readonly("name", &ParameterSpec::name)
      .def_readonly("unit", &ParameterSpec::unit)
      .def_readonly("default_value", &ParameterSpec::default_value, "default, in `unit`")
      .def_readonly("lower", &ParameterSpec::lower, "inclusive lower bound, in `unit`")
      .def_readonly("upper", &ParameterSpec::upper, "inclusive upper bound, in `unit`")
      .def_readonly("fittable", &ParameterSpec::fittable)
      .def_readonly("description", &ParameterSpec::description)
      .def("__repr__", [](const ParameterSpec& s) {
        return "<ParameterSpec " + s.name + " [" + s.unit + "]>";
      });

  py::class_<RobotModel, ModelPtr>(
      m, "RobotModel",
      "An evaluable robot model (immutable): the chain with end effector and TCP for given m6, d6, "
      "joint stiffness, damping and effects. Make one with RobotConfig.build().")
      .def_property_readonly("num_joints", &RobotModel::num_joints)
      .def_property_readonly("num_dofs", &RobotModel::num_dofs, "joints plus the extra DOFs of effects")
      .def_property_readonly("joint_stiffness", [](const RobotModel& r) { return Eigen::VectorXd(r.joint_stiffness()); },
                             "diagonal joint stiffness [N·m/rad]")
      .def_property_readonly("alpha_s", &RobotModel::alpha, "Rayleigh damping C = alpha K + beta M: alpha [s]")
      .def_property_readonly("beta_per_s", &RobotModel::beta, "Rayleigh damping: beta [1/s]")
      .def_property_readonly("parameters", [](const RobotModel& r) { return ParameterDict(r.parameters()); },
                             "{name: value} in each parameter's unit (SI)")
      .def_property_readonly("effects", [](const RobotModel& r) {
        std::vector<std::string> n;
        for (const auto& e : r.effects()) n.push_back(e.effect->name());
        return n;
      }, "the bound effects, in the order they are applied")
      .def_property_readonly("joint_names", [](const RobotModel& r) { return r.chain().joint_names(); })
      .def_property_readonly("joint_limits", [](const RobotModel& r) {
        Eigen::MatrixXd l(r.num_joints(), 2);
        for (int j = 0; j < r.num_joints(); ++j) {
          const auto& lim = r.chain().limits()[j];
          l(j, 0) = lim.bounded ? lim.lower : -INFINITY;
          l(j, 1) = lim.bounded ? lim.upper : INFINITY;
        }
        return l;
      }, "(num_joints, 2) array of [lower, upper] joint limits [rad]; ±inf for continuous joints")
      .def("joints_outside_limits", [](const RobotModel& r, const std::optional<Eigen::VectorXd>& q_rad,
                                       const std::optional<Eigen::VectorXd>& q_deg) {
        return r.chain().JointsOutsideLimits(JointAnglesRad("joints_outside_limits", q_rad, q_deg));
      }, py::arg("q_rad") = py::none(), py::kw_only(), py::arg("q_deg") = py::none(),
         "0-based indices of the joints outside their limits (1e-9 rad tolerance), at q_rad [rad] or "
         "q_deg=[deg] (UnitWarning if the angles look like the other unit)")
      .def("evaluate", [](const ModelPtr& r, const std::optional<Eigen::VectorXd>& q_rad, bool cartesian, bool modes,
                          const std::optional<Eigen::VectorXd>& q_deg) {
        const Eigen::VectorXd q = JointAnglesRad("evaluate", q_rad, q_deg);
        return dynamics::EvaluatePosture(r, q, {.cartesian = cartesian, .modes = modes});
      }, py::arg("q_rad") = py::none(), py::arg("cartesian") = true, py::arg("modes") = true, py::kw_only(),
         py::arg("q_deg") = py::none(),
         "One-off posture evaluation (PostureEvaluator(model).evaluate) at joint angles q_rad [rad], or "
         "q_deg=[deg]; a UnitWarning names angles that look like the other unit.")
      .def("predict_frf", [](const ModelPtr& r, const Eigen::VectorXd& q_rad, const Eigen::VectorXd& freq_hz,
                             const std::string& method) {
        const Eigen::VectorXd q = JointAnglesRad("predict_frf", q_rad);
        CheckFrequencies(freq_hz);
        std::vector<Eigen::Matrix3cd> h;
        {
          py::gil_scoped_release release;
          const PostureDynamics d = dynamics::EvaluatePosture(r, q, {.cartesian = false, .modes = method == "modal"});
          h = ReceptanceByMethod(d, freq_hz, method);
        }
        return ToArray(h);
      }, py::arg("q_rad"), py::arg("freq_hz"), py::arg("method") = "modal",
         "Tool-tip receptance at posture q_rad [rad] (a UnitWarning if it looks like degrees), as frf-predict "
         "computes it: evaluate, then "
         "PostureDynamics.receptance(freq_hz, method). Returns complex (lines, 3, 3) [m/N].");

  py::class_<RobotConfig>(
      m, "RobotConfig",
      "A robot config YAML (config/kr210.yaml documents the schema) read into a description and "
      "its parameter values; add_effect and set are the tools' --add and --set.")
      .def(py::init(&LoadConfig), py::arg("path"), py::arg("add") = std::vector<std::string>{},
           py::arg("set") = std::map<std::string, double>{},
           "Reads the config at `path`, then adds the effects `add` (as --add EFFECT) and sets the "
           "parameters `set` ({name: value}, as --set NAME=VALUE). Raises FileNotFoundError, "
           "InputError (path:line:col), ValueError (unknown effect or parameter, value out of bounds).")
      .def_readonly("path", &RobotConfig::path)
      .def("add_effect", &AddEffect, py::arg("name"),
           "Switches on an effect by name with its default parameters (as --add); values already "
           "set are kept. ValueError for an unknown effect (the message lists the available ones).")
      .def("set", [](RobotConfig& c, const std::string& name, double value) { c.parameters.Set(name, value); },
           py::arg("name"), py::arg("value"),
           "Sets a parameter in its unit, e.g. set('m6_kg', 30.2) (as --set m6_kg=30.2). ValueError "
           "for an unknown name or a value outside the bounds.")
      .def("get", [](const RobotConfig& c, const std::string& name) { return c.parameters.Get(name); },
           py::arg("name"), "A parameter's value in its unit.")
      .def_property_readonly("parameters", [](const RobotConfig& c) { return ParameterDict(c.parameters); },
                             "{name: value}, each in its unit (SI)")
      .def_property_readonly("parameter_specs", [](const RobotConfig& c) { return c.parameters.specs(); })
      .def_property_readonly("effects", [](const RobotConfig& c) {
        std::vector<std::string> n;
        for (const auto& e : c.description.effects) n.push_back(e.name);
        return n;
      }, "the enabled effects' names, in the config's order")
      .def_property_readonly("num_joints", [](const RobotConfig& c) { return c.description.arm.num_joints(); })
      .def("parameters_yaml", [](const RobotConfig& c, bool all) {
        return io::ParametersYaml(c.parameters, dynamics::DefaultParameters(c.description), all);
      }, py::arg("all") = false,
         "The `parameters:` YAML block that reproduces these values where they differ from the "
         "defaults (all of them if all=True), as frf-calibrate writes it.")
      .def("build", [](const RobotConfig& c) { return Mutable(c.Build()); },
           "The evaluable RobotModel. ValueError if a parameter is out of its bounds.")
      .def("copy", [](const RobotConfig& c) { return RobotConfig(c); })
      .def("__repr__", [](const RobotConfig& c) {
        return "<RobotConfig " + c.path + ", " + std::to_string(c.parameters.size()) + " parameters>";
      });
  m.def("load_robot_config", &LoadConfig, py::arg("path"), py::arg("add") = std::vector<std::string>{},
        py::arg("set") = std::map<std::string, double>{}, "Same as RobotConfig(path, add, set).");
  m.def("available_effects", [] { return dynamics::EffectRegistry::Instance().Names(); },
        "Names of the effects that add_effect accepts.");

  py::class_<Mode>(m, "Mode", "One undamped vibration mode of the assembled system.")
      .def_readonly("freq_hz", &Mode::freq_hz, "natural frequency [Hz]")
      .def_readonly("damping_ratio", &Mode::damping_ratio, "[-]")
      .def_readonly("modal_mass_kg", &Mode::modal_mass_kg,
                    "effective mass at the tool tip along shape_T [kg] (inf if the tip does not move)")
      .def_property_readonly("shape_T", [](const Mode& x) { return Eigen::Vector3d(x.shape_T); },
                             "unit tool-tip translation in B, largest entry > 0")
      .def_property_readonly("p_T", [](const Mode& x) { return Eigen::Vector3d(x.p_T); },
                             "tool-tip translation of the mass-normalised mode [1/sqrt(kg)]")
      .def_property_readonly("phi", [](const Mode& x) { return Eigen::VectorXd(x.phi); },
                             "mass-normalised mode shape (phi^T M phi = 1), joints [rad] then effect DOFs")
      .def("__repr__", [](const Mode& x) {
        return "<Mode " + std::to_string(x.freq_hz) + " Hz, zeta " + std::to_string(x.damping_ratio) + ">";
      });

  py::class_<PostureDynamics>(
      m, "PostureDynamics",
      "Everything that depends on the posture q; matrices are NumPy arrays (copies). Generalised "
      "coordinates: the n joints [rad], then the effects' extra DOFs.")
      .def_property_readonly("q", [](const PostureDynamics& d) { return Eigen::VectorXd(d.q); }, "[rad]")
      .def_property_readonly("X_BT", [](const PostureDynamics& d) { return Eigen::Matrix4d(d.X_BT.matrix()); },
                             "TCP pose in the base frame B, 4x4 homogeneous [m]")
      .def_property_readonly("J", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.J_BT); },
                             "TCP Jacobian J_BT (6 x n), rows [v; w]: [m/rad] then [rad/rad]")
      .def_property_readonly("jacobian_condition", [](const PostureDynamics& d) { return d.jacobian_condition; },
                             "sigma_max/sigma_min of J (metres and radians mixed, as is)")
      .def_property_readonly("near_singular", [](const PostureDynamics& d) { return d.near_singular; },
                             "jacobian_condition > 1e5: the Cartesian M_X, K_X, C_X are NaN")
      .def_property_readonly("proportional_damping", [](const PostureDynamics& d) { return d.proportional_damping; })
      .def_property_readonly("num_joints", [](const PostureDynamics& d) { return d.system.num_joints; })
      .def_property_readonly("M_q", &PostureDynamics::M_q, "joint-space mass matrix (n x n) [kg·m²]")
      .def_property_readonly("K_q", &PostureDynamics::K_q, "joint-space stiffness (n x n) [N·m/rad]")
      .def_property_readonly("C_q", &PostureDynamics::C_q, "joint-space damping (n x n) [N·m·s/rad]")
      .def_property_readonly("M", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.system.M); },
                             "assembled mass matrix (N x N), joints then effect DOFs [kg, kg·m, kg·m²]")
      .def_property_readonly("K", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.system.K); },
                             "assembled stiffness (N x N) [N/m, N, N·m/rad]")
      .def_property_readonly("C", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.system.C); },
                             "assembled damping alpha K + beta M + C_extra (N x N)")
      .def_property_readonly("C_extra", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.system.C_extra); },
                             "non-proportional damping added by effects (N x N)")
      .def_property_readonly("B", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.system.B); },
                             "tool-tip translation per generalised coordinate (3 x N) [m/rad, m/m]")
      .def_property_readonly("M_X", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.M_X); },
                             "Cartesian mass at T in B, [v; w] (6x6); NaN when near singular or n != 6 or "
                             "cartesian=False")
      .def_property_readonly("K_X", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.K_X); },
                             "Cartesian stiffness at T in B (6x6) [N/m, N/rad, N·m/rad]")
      .def_property_readonly("C_X", [](const PostureDynamics& d) { return Eigen::MatrixXd(d.C_X); },
                             "Cartesian damping at T in B (6x6)")
      .def_property_readonly("static_compliance", [](const PostureDynamics& d) { return Eigen::Matrix3d(d.static_compliance); },
                             "H_T(0) = B K^-1 B^T (3x3) [m/N]")
      .def_readonly("modes", &PostureDynamics::modes, "list of Mode, ascending frequency")
      .def_property_readonly("freq_hz", [](const PostureDynamics& d) {
        Eigen::VectorXd f(d.modes.size());
        for (size_t k = 0; k < d.modes.size(); ++k) f(k) = d.modes[k].freq_hz;
        return f;
      }, "natural frequencies of the modes [Hz], ascending")
      .def_property_readonly("damping_ratio", [](const PostureDynamics& d) {
        Eigen::VectorXd f(d.modes.size());
        for (size_t k = 0; k < d.modes.size(); ++k) f(k) = d.modes[k].damping_ratio;
        return f;
      }, "damping ratio of each mode [-]")
      .def_property_readonly("modal_mass_kg", [](const PostureDynamics& d) {
        Eigen::VectorXd f(d.modes.size());
        for (size_t k = 0; k < d.modes.size(); ++k) f(k) = d.modes[k].modal_mass_kg;
        return f;
      }, "effective tool-tip mass of each mode [kg]")
      .def_property_readonly("shapes_T", [](const PostureDynamics& d) {
        Eigen::MatrixXd s(d.modes.size(), 3);
        for (size_t k = 0; k < d.modes.size(); ++k) s.row(k) = d.modes[k].shape_T.transpose();
        return s;
      }, "(modes, 3): unit tool-tip translation of each mode in B")
      .def_property_readonly("phi", [](const PostureDynamics& d) {
        const Eigen::Index n = d.system.M.rows();
        Eigen::MatrixXd s(n, static_cast<Eigen::Index>(d.modes.size()));
        for (size_t k = 0; k < d.modes.size(); ++k) s.col(k) = d.modes[k].phi;
        return s;
      }, "(N, modes): mass-normalised mode shapes as columns (phi^T M phi = I)")
      .def_property_readonly("poles", [](const PostureDynamics& d) { return Eigen::VectorXcd(d.complex_modes.poles); },
                             "state-space poles [rad/s] when the damping is not proportional (else empty)")
      .def("receptance", [](const PostureDynamics& d, const Eigen::VectorXd& freq_hz, const std::string& method) {
        CheckFrequencies(freq_hz);
        std::vector<Eigen::Matrix3cd> h;
        {
          py::gil_scoped_release release;
          h = ReceptanceByMethod(d, freq_hz, method);
        }
        return ToArray(h);
      }, py::arg("freq_hz"), py::arg("method") = "modal", kReceptanceDoc)
      .def("__repr__", [](const PostureDynamics& d) {
        return "<PostureDynamics " + std::to_string(d.system.M.rows()) + " DOFs, " + std::to_string(d.modes.size()) +
               " modes" + (d.near_singular ? ", near singular" : "") + ">";
      });

  py::class_<PostureEvaluator>(
      m, "PostureEvaluator",
      "Evaluates postures of one model with reusable solvers and buffers. Not thread-safe: one "
      "evaluator per thread.")
      .def(py::init([](const ModelPtr& model) { return std::make_unique<PostureEvaluator>(model); }),
           py::arg("model"))
      .def("evaluate", [](PostureEvaluator& ev, const std::optional<Eigen::VectorXd>& q_rad, bool cartesian,
                          bool modes, const std::optional<Eigen::VectorXd>& q_deg) {
        const Eigen::VectorXd q = JointAnglesRad("evaluate", q_rad, q_deg);
        return ev.Evaluate(q, {.cartesian = cartesian, .modes = modes});
      }, py::arg("q_rad") = py::none(), py::arg("cartesian") = true, py::arg("modes") = true, py::kw_only(),
         py::arg("q_deg") = py::none(),
         "PostureDynamics at joint angles q_rad [rad], or q_deg=[deg] (length num_joints; a UnitWarning names "
         "angles that look like the other unit: more than a turn in q_rad, all within 2 pi with fractions in "
         "q_deg). cartesian: form M_X, K_X, "
         "C_X; modes: undamped modes and damping ratios. ValueError if q has the wrong size or is "
         "not finite; NumericalError if the assembled mass matrix is not positive definite (a bad model, not a bad "
         "posture).");

  m.def("receptance", [](const PostureDynamics& d, const Eigen::VectorXd& freq_hz, const std::string& method) {
    CheckFrequencies(freq_hz);
    std::vector<Eigen::Matrix3cd> h;
    {
      py::gil_scoped_release release;
      h = ReceptanceByMethod(d, freq_hz, method);
    }
    return ToArray(h);
  }, py::arg("dynamics"), py::arg("freq_hz"), py::arg("method") = "modal", kReceptanceDoc);

  py::class_<io::Posture>(m, "Posture", "One row of a posture file.")
      .def(py::init([](std::string id, const std::optional<Eigen::VectorXd>& q_rad,
                       const std::optional<Eigen::VectorXd>& q_deg) {
             return io::Posture{std::move(id), JointAnglesRad("Posture", q_rad, q_deg), 0};
           }),
           py::arg("id"), py::arg("q_rad") = py::none(), py::kw_only(), py::arg("q_deg") = py::none(),
           "A posture from joint angles q_rad [rad] or q_deg=[deg] (a UnitWarning if they look like the other "
           "unit).")
      .def_readonly("id", &io::Posture::id)
      .def_property_readonly("q", [](const io::Posture& p) { return Eigen::VectorXd(p.q); }, "joint angles [rad]")
      .def_readonly("line", &io::Posture::line, "line in the file (0 if not read from one)")
      .def("__repr__", [](const io::Posture& p) { return "<Posture " + p.id + ">"; });
  m.def("read_posture_file", [](const std::string& path, std::optional<int> num_joints) {
    RequireReadableFile(path);
    if (num_joints && *num_joints < 1) {
      throw py::value_error("read_posture_file: num_joints: expected the robot's joint count >= 1 (or None: from "
                            "the file), got " + std::to_string(*num_joints));
    }
    std::vector<std::string> units;  // radians under _deg headers, degrees under _rad
    std::vector<io::Posture> postures;
    {
      py::gil_scoped_release release;
      postures = io::ReadPostureFile(path, num_joints.value_or(0), &units);
    }
    for (const std::string& w : units) WarnUnit(w);
    return postures;
  }, py::arg("path"), py::arg("num_joints") = py::none(),
     "Reads a posture file (pose_id,q1_deg..qn_deg or _rad; docs/formats.md §1) into a list of "
     "Posture with q in radians; num_joints is the robot's (a file with other joint columns is an error), "
     "None takes it from the file. InputError with file:line:col; a robomach.UnitWarning when the angles look "
     "like the other unit (the tools' exit 3).");
  m.def("write_posture_file", [](const std::string& path, const std::vector<io::Posture>& postures) {
    py::gil_scoped_release release;
    io::WritePostureFile(path, postures);
  }, py::arg("path"), py::arg("postures"), "Writes a posture file in degrees (atomic).");

  m.def("predict_frfs", [](const ModelPtr& model, const std::vector<io::Posture>& postures,
                           const Eigen::VectorXd& freq_hz, const std::string& method) {
    CheckFrequencies(freq_hz);
    std::vector<dynamics::NamedPosture> named;
    for (const io::Posture& p : postures) named.push_back({p.id, p.q});
    dynamics::PredictOptions o;
    o.method = dynamics::ParseReceptanceMethod(method);
    dynamics::FrfPredictionResult r;
    {
      py::gil_scoped_release release;
      r = dynamics::PredictFrfs(model, named, freq_hz, o);
    }
    py::dict out;
    out["status"] = robomach::ToString(r.status());
    py::list findings, results;
    for (const Finding& f : r.verdict.findings) {
      // The posture file's line in front, as frf-predict prints it.
      const int line = f.input_index >= 0 ? postures[f.input_index].line : 0;
      findings.append(line > 0 ? "line " + std::to_string(line) + ": " + f.message : f.message);
    }
    for (dynamics::PosturePredictionResult& p : r.postures) {
      py::dict d;
      d["id"] = p.id;
      d["H_m_per_N"] = ToArray(p.H);
      d["joints_outside_limits"] = p.joints_outside_limits;
      d["dynamics"] = std::move(p.dynamics);
      results.append(d);
    }
    out["findings"] = findings;
    out["postures"] = results;
    return out;
  }, py::arg("model"), py::arg("postures"), py::arg("freq_hz"), py::arg("method") = "modal",
     "frf-predict's workflow: the model evaluated at each Posture and its tool-tip receptance at freq_hz [Hz]. "
     "Returns {'status': 'ok' or 'flagged', 'findings': [str] (a joint outside its limits, a posture near a "
     "singularity; 'line N: ' in front for postures read from a file), 'postures': [{'id', 'H_m_per_N' (complex (lines, 3, "
     "3) [m/N] in B), 'joints_outside_limits' (0-based), 'dynamics' (PostureDynamics)}]}. frf-predict exits 3 when "
     "the status is 'flagged'. Releases the GIL.");

  m.def("write_predicted_frf_csv", [](const std::string& path, const std::vector<py::tuple>& predictions,
                                       const std::string& directions) {
    std::vector<io::PosturePrediction> preds;
    for (const py::tuple& t : predictions) {
      if (t.size() != 3) throw std::invalid_argument("expected (pose_id, freq_hz, H) tuples");
      io::PosturePrediction p;
      p.pose_id = t[0].cast<std::string>();
      p.freq_hz = t[1].cast<Eigen::VectorXd>();
      auto h = t[2].cast<py::array_t<std::complex<double>, py::array::c_style | py::array::forcecast>>();
      if (h.ndim() != 3 || h.shape(0) != p.freq_hz.size() || h.shape(1) != 3 || h.shape(2) != 3) {
        throw std::invalid_argument("posture " + p.pose_id + ": H must have shape (len(freq_hz), 3, 3)");
      }
      auto a = h.unchecked<3>();
      p.H.resize(p.freq_hz.size());
      for (Eigen::Index i = 0; i < p.freq_hz.size(); ++i) {
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) p.H[i](r, c) = a(i, r, c);
        }
      }
      preds.push_back(std::move(p));
    }
    const io::DirectionPairs pairs = io::ParseDirectionPairs(directions);
    py::gil_scoped_release release;
    io::WritePredictedFrfCsv(path, preds, pairs);
  }, py::arg("path"), py::arg("predictions"), py::arg("directions") = "all",
     "Writes predicted FRFs as frf-predict's --out (docs/formats.md §3, receptance [m/N]): "
     "predictions is a list of (pose_id, freq_hz [Hz], H complex (lines, 3, 3) [m/N]); "
     "directions e.g. 'xx,yy,xy' or 'all'. Atomic; OutputError if it cannot be written.");

  m.def("run_frf_predict",
        [](const std::string& robot, const std::string& postures, double fmin_hz, double fmax_hz, double df_hz,
           const std::optional<Eigen::VectorXd>& freq_hz, const std::string& method, const std::vector<std::string>& adds,
           const std::map<std::string, double>& sets, const std::vector<std::string>& uncertainty, bool intervals,
           size_t band_postures, double confidence, const std::string& uncertainty_method, int samples,
           std::uint64_t seed) {
          workflows::FrfPredictOptions o;
          o.robot_path = robot;
          o.postures_path = postures;
          o.freq_hz = freq_hz ? *freq_hz : workflows::FrequencyGrid(fmin_hz, fmax_hz, df_hz);
          o.method = method;
          o.adds = adds;
          for (const auto& [name, value] : sets) o.sets.push_back(name + "=" + FormatNumber(value, 17));
          o.uncertainty_paths = uncertainty;
          o.intervals = intervals;
          o.band_postures = band_postures;
          o.uncertainty = PropagationFrom(confidence, uncertainty_method, samples, seed);
          o.Validate();
          if (!uncertainty.empty() && !intervals && band_postures == 0) {
            throw std::invalid_argument("run_frf_predict: uncertainty gives the modes' intervals (intervals=True) "
                                        "and the |H| bands (band_postures=N): ask for one of them");
          }
          RequireReadableFile(robot);
          RequireReadableFile(postures);
          CollectedMessages said;
          workflows::FrfPredictRun run;
          {
            py::gil_scoped_release release;
            run = workflows::RunFrfPredict(o, said.Sink());
          }
          for (const std::string& f : run.unit_findings) WarnUnit(f);
          py::list predictions;
          for (size_t p = 0; p < run.predictions.size(); ++p) {
            py::dict d;
            d["pose_id"] = run.predictions[p].pose_id;
            d["freq_hz"] = run.predictions[p].freq_hz;
            d["receptance"] = ToArray(run.predictions[p].H);
            predictions.append(d);
          }
          py::dict d;
          d["predictions"] = predictions;
          d["messages"] = said.List();
          d["warnings"] = run.warnings;
          d["unit_findings"] = run.unit_findings;
          d["flagged"] = run.flagged();
          d["summary"] = py::module_::import("json").attr("loads")(run.Summary(o, uncertainty_method).dump());
          return d;
        },
        py::arg("robot"), py::arg("postures"), py::arg("fmin_hz") = 0.625, py::arg("fmax_hz") = 500.0,
        py::arg("df_hz") = 0.625, py::arg("freq_hz") = py::none(), py::arg("method") = "modal",
        py::arg("adds") = std::vector<std::string>{}, py::arg("sets") = std::map<std::string, double>{},
        py::arg("uncertainty") = std::vector<std::string>{}, py::arg("intervals") = false,
        py::arg("band_postures") = 0, py::arg("confidence") = dynamics::PropagationOptions{}.confidence,
        py::arg("uncertainty_method") = "auto", py::arg("samples") = dynamics::PropagationOptions{}.samples,
        py::arg("seed") = dynamics::PropagationOptions{}.seed,
        "frf-predict as one call (workflows::RunFrfPredict): a robot config, a posture file, the frequency grid "
        "(fmin_hz..fmax_hz step df_hz, or freq_hz), method 'modal' or 'direct', effects to add, parameters to set "
        "({name: value} in their units), parameter-uncertainty files (intervals=True: each mode's interval, as "
        "with --modes/--summary; band_postures=N: the |H| band of the first N postures; with either, no files "
        "take the config's). Returns a dict: predictions (pose_id, freq_hz, receptance (lines, 3, 3) [m/N]), "
        "messages ({kind, text}), warnings (the prediction's, with file:line), unit_findings (also as "
        "UnitWarning), flagged (the tool's exit 3) and summary (frf-predict --summary's JSON but for "
        "robomach_version). ValueError naming the option; FileNotFoundError, InputError for files. Releases the GIL.");
}

}  // namespace robomach::python
