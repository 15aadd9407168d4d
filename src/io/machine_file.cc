#include "robomach/io/machine_file.h"

#include "machine_text.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {

using machine::AxisKind;
using machine::AxisScale;
using machine_text::FromSi;
using machine_text::ToSi;
using machine_text::UnitSuffix;

MachineFile ReadMachineFile(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path);
  MachineFile f;
  f.path = path;
  const YamlDoc axes = doc["axes"];
  if (!axes.IsMap() || axes.Keys().empty()) throw axes.Error("expected a map of axis names to {resolution_*, origin_*}");
  for (const std::string& name : axes.Keys()) {
    const YamlDoc a = axes[name];
    AxisScale s;
    s.name = name;
    const bool mm = a.Has("resolution_mm") || a.Has("origin_mm");
    const bool deg = a.Has("resolution_deg") || a.Has("origin_deg");
    if (mm == deg) {
      throw a.Error("expected either resolution_mm and origin_mm (linear axis) or resolution_deg and origin_deg "
                    "(rotary axis)");
    }
    s.kind = mm ? AxisKind::kLinear : AxisKind::kRotary;
    const std::string u = mm ? "_mm" : "_deg";
    const double res = a["resolution" + u].Number();
    if (!(res > 0.0)) throw a["resolution" + u].Error("expected a resolution > 0, got " + FormatDouble(res));
    s.resolution = ToSi(s, res);
    s.origin = ToSi(s, a["origin" + u].Number());
    a.RejectUnknownKeys();
    f.machine.axes.push_back(s);
  }
  if (f.machine.axes.size() > static_cast<size_t>(8)) {
    throw axes.Error("at most 8 axes fit the 16-bit capture words of formats.md §8.2");
  }
  const YamlDoc k = doc["kinematics"];
  const std::string type = k["type"].String();
  if (type != "nutating_head_rotary_table") {
    throw k["type"].Error("unknown kinematics type '" + type + "'; known: nutating_head_rotary_table");
  }
  machine::NutatingHeadGeometry& g = f.geometry;
  g.nutation = DegToRad(k["nutation_deg"].NumberInRange(0.0, 90.0, false, true));
  g.pivot_length = MmToM(k["pivot_length_mm"].Number());
  g.tool_length = MmToM(k["tool_length_mm"].Number());
  const auto cc = k["c_centre_mm"].Numbers(2);
  g.c_centre = {MmToM(cc[0]), MmToM(cc[1])};
  const auto zo = k["zero_offset_mm"].Numbers(3);
  g.zero_offset = {MmToM(zo[0]), MmToM(zo[1]), MmToM(zo[2])};
  if (k.Has("errors")) {
    const YamlDoc e = k["errors"];
    if (e.Has("b_eccentricity_mm")) {
      const auto v = e["b_eccentricity_mm"].Numbers(2);
      g.b_eccentricity = {MmToM(v[0]), MmToM(v[1])};
    }
    if (e.Has("pivot_length_error_mm")) g.pivot_length_error = MmToM(e["pivot_length_error_mm"].Number());
    if (e.Has("c_eccentricity_mm")) {
      const auto v = e["c_eccentricity_mm"].Numbers(2);
      g.c_eccentricity = {MmToM(v[0]), MmToM(v[1])};
    }
    e.RejectUnknownKeys();
  } else {
    k.MarkUsed("errors");
  }
  k.RejectUnknownKeys();
  f.machine.kinematics = std::make_shared<machine::NutatingHeadRotaryTable>(g);
  try {
    f.machine.kinematic_axis = machine::MapKinematicAxes(f.machine.axes, *f.machine.kinematics);
  } catch (const std::invalid_argument& e) {
    throw axes.Error(e.what());
  }
  if (doc.Has("controller_axes")) {
    const YamlDoc ca = doc["controller_axes"];
    for (const std::string& name : ca.Keys()) {
      const std::string axis = ca[name].String();
      const int i = machine::FindAxis(f.machine.axes, axis);
      if (i < 0) throw ca[name].Error("axis '" + axis + "' is not under axes:");
      f.controller_axes[name] = i;
    }
  } else {
    doc.MarkUsed("controller_axes");
  }
  doc.RejectUnknownKeys();
  return f;
}

void WriteMachineFile(const std::string& path, const MachineFile& f) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "# machine file (formats.md §8.3)\naxes:\n";
    for (const AxisScale& a : f.machine.axes) {
      const std::string u = UnitSuffix(a);
      out << "  " << a.name << ": {resolution" << u << ": " << FormatDouble(FromSi(a, a.resolution)) << ", origin" << u
          << ": " << FormatDouble(FromSi(a, a.origin)) << "}\n";
    }
    const auto& g = f.geometry;
    out << "kinematics:\n  type: nutating_head_rotary_table\n"
        << "  nutation_deg: " << FormatDouble(RadToDeg(g.nutation)) << "\n"
        << "  pivot_length_mm: " << FormatDouble(MToMm(g.pivot_length)) << "\n"
        << "  tool_length_mm: " << FormatDouble(MToMm(g.tool_length)) << "\n"
        << "  c_centre_mm: [" << FormatDouble(MToMm(g.c_centre[0])) << ", " << FormatDouble(MToMm(g.c_centre[1]))
        << "]\n"
        << "  zero_offset_mm: [" << FormatDouble(MToMm(g.zero_offset[0])) << ", "
        << FormatDouble(MToMm(g.zero_offset[1])) << ", " << FormatDouble(MToMm(g.zero_offset[2])) << "]\n"
        << "  errors:\n"
        << "    b_eccentricity_mm: [" << FormatDouble(MToMm(g.b_eccentricity[0])) << ", "
        << FormatDouble(MToMm(g.b_eccentricity[1])) << "]\n"
        << "    pivot_length_error_mm: " << FormatDouble(MToMm(g.pivot_length_error)) << "\n"
        << "    c_eccentricity_mm: [" << FormatDouble(MToMm(g.c_eccentricity[0])) << ", "
        << FormatDouble(MToMm(g.c_eccentricity[1])) << "]\n";
    if (!f.controller_axes.empty()) {
      out << "controller_axes: {";
      bool first = true;
      for (const auto& [name, i] : f.controller_axes) {
        out << (first ? "" : ", ") << name << ": " << f.machine.axes[i].name;
        first = false;
      }
      out << "}\n";
    }
  });
}

}  // namespace robomach::io
