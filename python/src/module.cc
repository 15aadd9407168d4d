// The Python module `robomach`: exceptions and the module definition.
// docs/python.md lists the bindings.
#include <cerrno>
#include <filesystem>
#include <fstream>

#include "bindings.h"
#include "robomach/common/errors.h"
#include "robomach/common/version.h"

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

Axis ParseAxis(const std::string& name) {
  if (name == "x" || name == "X") return Axis::kX;
  if (name == "y" || name == "Y") return Axis::kY;
  if (name == "z" || name == "Z") return Axis::kZ;
  throw std::invalid_argument("direction '" + name + "': expected x, y or z");
}

std::string AxisString(Axis a) { return std::string(1, AxisName(a)); }

dynamics::FrfKey ToKey(const KeyTuple& t) {
  return {std::get<0>(t), ParseAxis(std::get<1>(t)), ParseAxis(std::get<2>(t))};
}

KeyTuple FromKey(const dynamics::FrfKey& k) { return {k.pose_id, AxisString(k.response), AxisString(k.excitation)}; }

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
}
