// The Python module `robomach`: exceptions and the module definition.
// docs/python.md lists the bindings.
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <glog/logging.h>

#include "bindings.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/common/version.h"
#include "robomach/common/number_format.h"
#include "robomach/io/posture_file.h"

namespace robomach::python {

py::array_t<std::complex<double>> ToArray(const std::vector<Eigen::Matrix3cd>& h) {
  py::array_t<std::complex<double>> out({static_cast<py::ssize_t>(h.size()), py::ssize_t{3}, py::ssize_t{3}});
  auto a = out.mutable_unchecked<3>();
  for (size_t i = 0; i < h.size(); ++i) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) a(static_cast<py::ssize_t>(i), r, c) = h[i](r, c);
    }
  }
  return out;
}

namespace {
PyObject* g_unit_warning = nullptr;  // robomach.UnitWarning, made at import
}  // namespace

void WarnUnit(const std::string& message) {
  if (PyErr_WarnEx(g_unit_warning ? g_unit_warning : PyExc_UserWarning, message.c_str(), 1) != 0) {
    throw py::error_already_set();
  }
}

Eigen::VectorXd JointAnglesRad(const std::string& call, const std::optional<Eigen::VectorXd>& q_rad,
                               const std::optional<Eigen::VectorXd>& q_deg) {
  if (q_rad.has_value() == q_deg.has_value()) {
    throw std::invalid_argument(call + ": give the joint angles once, as q_rad [rad] or as q_deg=[deg]" +
                                (q_rad ? std::string(", not both") : std::string()));
  }
  if (q_rad) {
    const double largest = q_rad->size() > 0 ? q_rad->cwiseAbs().maxCoeff() : 0.0;
    if (largest > io::kOneTurnRad) {
      WarnUnit("implausible (unit mistake?): " + call + ": q_rad has an angle of " + FormatNumber(largest) +
               " rad = " + FormatNumber(RadToDeg(largest)) +
               " deg, more than a turn: these look like degrees; pass q_deg=... or numpy.radians(q)");
    }
    return *q_rad;
  }
  const Eigen::VectorXd& d = *q_deg;
  bool fraction = false;
  int nonzero = 0;
  double largest = 0.0;
  for (Eigen::Index j = 0; j < d.size(); ++j) {
    const double a = std::abs(d(j));
    largest = std::max(largest, a);
    if (a > 0.0) ++nonzero;
    if (a > 0.0 && a != std::floor(a)) fraction = true;
  }
  if (nonzero > 0 && fraction && largest <= io::kOneTurnRad) {
    WarnUnit("implausible (unit mistake?): " + call + ": every angle of q_deg is within 2 pi = 6.28 (largest " +
             FormatNumber(largest) + "), as radians are: these look like radians; pass q_rad=... or "
             "numpy.degrees(q)");
  }
  return d * DegToRad(1.0);
}

void RequireReadableFile(const std::string& path) {
  std::error_code ec;
  const bool regular = std::filesystem::is_regular_file(path, ec);
  if (!regular || !std::ifstream(path)) {
    const std::string msg = path + (regular ? ": cannot be read" : ": no such file");
    py::object err = py::module_::import("builtins").attr("FileNotFoundError")(ENOENT, msg, path);
    PyErr_SetObject(PyExc_FileNotFoundError, err.ptr());
    throw py::error_already_set();
  }
}

}  // namespace robomach::python

using namespace robomach;
using namespace robomach::python;

PYBIND11_MODULE(robomach, m) {
  m.doc() =
      "robomach: pose-dependent dynamics of machining robots (tool-tip FRF, joint stiffness, "
      "calibration). SI units throughout, angles in radians; receptance in m/N. See docs/python.md.";
  m.attr("__version__") = robomach::Version();

  // Ceres logs through glog on stderr: "Covariance matrix is near rank
  // deficient", "Terminating: ..." (issue #35: they reached Python's
  // stderr). The library reports the same conditions in its results
  // (StageSummary.covariance_ok, std_dev NaN, solver_message, the status),
  // so glog's lines below FATAL are silenced, as the tools do
  // (apps/cli_support RunGuarded). GLOG_minloglevel in the environment (0
  // shows them all) is respected.
  if (std::getenv("GLOG_minloglevel") == nullptr) FLAGS_minloglevel = google::GLOG_FATAL;

  // Library exceptions keep their messages (what()). InputError carries the
  // location as attributes path, line, column (0 = unknown) and message
  // (without the location prefix).
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<OutputError> output_error(m, "OutputError", PyExc_OSError);
  static py::exception<NumericalError> numerical_error(m, "NumericalError", PyExc_ArithmeticError);
  input_error.doc() =
      "Malformed or out-of-range data in a user's file (robomach::InputError); str() is "
      "'path:line[:col]: message'; attributes path, line, column (1-based, 0 = unknown), message.";
  output_error.doc() = "An output file could not be created, written or renamed into place (robomach::OutputError).";
  numerical_error.doc() =
      "A numerical method failed at the values it was given (robomach::NumericalError): a "
      "factorisation or eigensolver did not succeed, a result is not finite.";
  // Implausible units (an angle that fits the other unit far better): a
  // warning, as the tools' exit 3 is a flag and not a refusal.
  g_unit_warning = PyErr_NewExceptionWithDoc(
      "robomach.UnitWarning",
      "A value that fits another unit far better than the one its name says (degrees passed as q_rad, say): the "
      "call went ahead with the value as given; the message names the likely mistake.",
      PyExc_UserWarning, nullptr);
  if (!g_unit_warning) throw py::error_already_set();
  m.attr("UnitWarning") = py::reinterpret_borrow<py::object>(g_unit_warning);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      py::object err = py::reinterpret_borrow<py::object>(input_error.ptr())(e.what());
      err.attr("path") = e.where().path;
      err.attr("line") = e.where().line;
      err.attr("column") = e.where().column;
      err.attr("message") = e.message();
      PyErr_SetObject(input_error.ptr(), err.ptr());
    } catch (const OutputError& e) {
      PyErr_SetString(output_error.ptr(), e.what());
    } catch (const NumericalError& e) {
      PyErr_SetString(numerical_error.ptr(), e.what());
    }
    // std::invalid_argument -> ValueError, std::out_of_range -> IndexError,
    // std::runtime_error -> RuntimeError: pybind11's own translation.
  });

  BindDynamics(m);
  BindFrf(m);
  BindCalibration(m);
  BindAudit(m);
  BindStability(m);
  BindDrilling(m);
  BindPolishing(m);
  BindMachine(m);
  BindUncertainty(m);
}
