// Shared by the binding files of the Python module (python/CMakeLists.txt).
#pragma once

#include <complex>
#include <cstdint>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Core>
#include <pybind11/complex.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "robomach/common/frames.h"
#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/uncertainty.h"

namespace robomach::python {

namespace py = pybind11;

void BindDynamics(py::module_& m);
void BindFrf(py::module_& m);
void BindCalibration(py::module_& m);
void BindAudit(py::module_& m);
void BindStability(py::module_& m);
void BindDrilling(py::module_& m);
void BindPolishing(py::module_& m);
void BindMachine(py::module_& m);
void BindUncertainty(py::module_& m);

/// Receptance matrices per line -> complex128 array of shape (lines, 3, 3).
py::array_t<std::complex<double>> ToArray(const std::vector<Eigen::Matrix3cd>& h);

/// The propagation options of the Python calls' keywords (confidence,
/// uncertainty_method, samples, seed), checked as the tools check theirs.
inline dynamics::PropagationOptions PropagationFrom(double confidence, const std::string& method, int samples,
                                                    std::uint64_t seed) {
  dynamics::PropagationOptions o;
  o.confidence = confidence;
  o.method = dynamics::ParsePropagationMethod(method);
  o.samples = samples;
  o.seed = seed;
  o.Validate();
  return o;
}

/// A workflow's findings as Python sees them: one sentence each.
inline std::vector<std::string> FindingMessages(const RunFindings& r) {
  std::vector<std::string> v;
  for (const Finding& f : r.findings) v.push_back(f.message);
  return v;
}

/// A library message as Python sees it: {'kind': 'info'|'note'|'warning', 'text': ...}.
inline py::dict MessageDict(const Message& m) {
  py::dict d;
  d["kind"] = m.kind == Message::Kind::kWarning ? "warning" : m.kind == Message::Kind::kNote ? "note" : "info";
  d["text"] = m.text;
  return d;
}

/// Messages gathered while the GIL is released (Sink()), handed to Python
/// afterwards as a list of MessageDict (List()).
struct CollectedMessages {
  std::vector<Message> messages;
  MessageSink Sink() {
    return [this](const Message& m) { messages.push_back(m); };
  }
  py::list List() const {
    py::list l;
    for (const Message& m : messages) l.append(MessageDict(m));
    return l;
  }
};

/// Python spells an FRF key as a tuple (pose_id, response, excitation), e.g.
/// ("P1", "x", "x") for the direct FRF Hxx of posture P1, and, when the file
/// numbers its points (a roving test read with keep_points=True), as
/// (pose_id, response, excitation, response_point, excitation_point), e.g.
/// ("P1", "z", "z", 1, 7). The type caster below converts both ways; a key
/// whose points are 0 is the 3-tuple.
using KeyTuple = dynamics::FrfKey;
inline const dynamics::FrfKey& ToKey(const KeyTuple& t) { return t; }
inline const KeyTuple& FromKey(const dynamics::FrfKey& k) { return k; }

/// Joint angles as the library takes them [rad], from the `q_rad` or the
/// `q_deg` of a Python call (exactly one of them; ValueError otherwise).
/// Names cross the API with their unit (issue #35: `evaluate` took degrees
/// silently). An angle that fits the other unit far better is a
/// robomach.UnitWarning (a UserWarning) naming the likely mistake, with the
/// posture files' rule (io::PostureUnitWarnings, exit 3 in the tools):
/// q_rad with an angle beyond one turn (2 pi) looks like degrees; q_deg whose
/// non-zero angles are all within 2 pi and not all whole numbers looks like
/// radians. `call` names the function in the message.
Eigen::VectorXd JointAnglesRad(const std::string& call, const std::optional<Eigen::VectorXd>& q_rad,
                               const std::optional<Eigen::VectorXd>& q_deg = std::nullopt);

/// Issues a robomach.UnitWarning (a UserWarning subclass) with `message`;
/// raises if the warnings filter turns it into an error.
void WarnUnit(const std::string& message);

/// Raises FileNotFoundError ("path: no such file", as the tools' exit 66)
/// unless `path` is a readable regular file.
void RequireReadableFile(const std::string& path);

}  // namespace robomach::python

namespace pybind11::detail {

// FrfKey <-> (pose_id, response, excitation[, response_point, excitation_point]).
template <>
struct type_caster<robomach::dynamics::FrfKey> {
  PYBIND11_TYPE_CASTER(robomach::dynamics::FrfKey,
                       const_name("tuple[str, str, str] | tuple[str, str, str, int, int]"));

  bool load(handle src, bool /*convert*/) {
    if (!isinstance<tuple>(src)) return false;
    const auto t = reinterpret_borrow<tuple>(src);
    if (t.size() != 3 && t.size() != 5) return false;
    if (!isinstance<str>(t[0]) || !isinstance<str>(t[1]) || !isinstance<str>(t[2])) return false;
    value.pose_id = t[0].cast<std::string>();
    // A direction other than x, y, z is a ValueError naming it.
    value.response = robomach::ParseAxis(t[1].cast<std::string>());
    value.excitation = robomach::ParseAxis(t[2].cast<std::string>());
    value.response_point = 0;
    value.excitation_point = 0;
    if (t.size() == 5) {
      if (!isinstance<int_>(t[3]) || !isinstance<int_>(t[4])) return false;
      value.response_point = t[3].cast<int>();
      value.excitation_point = t[4].cast<int>();
    }
    return true;
  }

  static handle cast(const robomach::dynamics::FrfKey& k, return_value_policy, handle) {
    const std::string r = robomach::ToString(k.response);
    const std::string e = robomach::ToString(k.excitation);
    if (k.response_point == 0 && k.excitation_point == 0) return pybind11::make_tuple(k.pose_id, r, e).release();
    return pybind11::make_tuple(k.pose_id, r, e, k.response_point, k.excitation_point).release();
  }
};

}  // namespace pybind11::detail
