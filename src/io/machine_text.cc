#include "machine_text.h"

#include <fstream>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"

namespace robomach::io::machine_text {

using machine::AxisKind;
using machine::AxisScale;

std::string ReadWholeFile(const std::string& path) {
  // One read into a string of the file's size.
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError({path, 0, 0}, "cannot open file for reading");
  const std::streamoff size = in.tellg();
  std::string text;
  if (size > 0) {
    text.resize(static_cast<size_t>(size));
    in.seekg(0);
    in.read(text.data(), size);
    text.resize(static_cast<size_t>(in.gcount()));
  }
  // Whatever a size-less file (a pipe) still has.
  in.clear();
  std::ostringstream rest;
  rest << in.rdbuf();
  text += rest.str();
  return text;
}

double ToSi(const AxisScale& a, double file_value) {
  return a.kind == AxisKind::kLinear ? MmToM(file_value) : DegToRad(file_value);
}
double FromSi(const AxisScale& a, double si) { return a.kind == AxisKind::kLinear ? MToMm(si) : RadToDeg(si); }
std::string UnitSuffix(const AxisScale& a) { return a.kind == AxisKind::kLinear ? "_mm" : "_deg"; }

}  // namespace robomach::io::machine_text
