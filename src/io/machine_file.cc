#include "robomach/io/machine_file.h"

#include <cmath>

#include "machine_text.h"
#include "plausible.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"
#include "robomach/io/yaml_doc.h"
#include "robomach/machine/kinematics_kinds.h"

namespace robomach::io {

using machine::AxisKind;
using machine::AxisScale;
using machine_text::FromSi;
using machine_text::ToSi;
using machine_text::UnitSuffix;

namespace {

// Plausible ranges (docs/plausibility.md; sources at the constants in
// machine_file.h).
const PlausibleRange& LinearResolutionRange() {
  static const PlausibleRange r{kMinPlausibleLinearResolutionMm, kMaxPlausibleLinearResolutionMm, "mm",
                                "linear scales and encoders (1 nm to 10 um)",
                                "a resolution in m typed in the mm field?",
                                "a resolution in um typed in the mm field?"};
  return r;
}

const PlausibleRange& RotaryResolutionRange() {
  static const PlausibleRange r{kMinPlausibleRotaryResolutionDeg, kMaxPlausibleRotaryResolutionDeg, "deg",
                                "angle encoders of rotary axes (0.0000007 to 0.001 deg)",
                                "a resolution in turns or radians typed in the deg field?",
                                "a resolution in arc-seconds or millidegrees typed in the deg field?"};
  return r;
}

const PlausibleRange& MachineLengthRange() {
  static const PlausibleRange r{0.0, kMaxPlausibleMachineLengthMm, "mm",
                                "machine tool travels and geometry (the largest gantry mills travel 30 m)", "",
                                "a length in um typed in the mm field?"};
  return r;
}

const PlausibleRange& HeadLengthRange() {
  static const PlausibleRange r{kMinPlausibleHeadLengthMm, kMaxPlausibleMachineLengthMm, "mm",
                                "spindle heads and tools (pivot lengths 100 - 600 mm, tools 20 - 500 mm; 0 allowed)",
                                "a length in m typed in the mm field?", "a length in um typed in the mm field?"};
  return r;
}

const PlausibleRange& GeometricErrorRange() {
  static const PlausibleRange r{0.0, kMaxPlausibleGeometricErrorMm, "mm",
                                "geometric errors of accepted machines (a few um to tens of um, ISO 230-7)", "",
                                "an error in um typed in the mm field?"};
  return r;
}

// A length in mm: refused beyond kMaxMachineLengthMm (exit 65), flagged
// beyond the plausible range.
double MachineLengthMm(const YamlDoc& node, double v, const PlausibleRange& r, std::vector<std::string>* implausible) {
  if (std::abs(v) > kMaxMachineLengthMm) {
    throw node.Error("expected a length within +-" + FormatNumber(kMaxMachineLengthMm, 7) + " mm (1 km), got " +
                     node.String() + " mm: a length in um or nm typed in the mm field?");
  }
  CheckPlausible(node, std::abs(v), r, implausible);
  return v;
}

// Each element of a flow list of lengths in mm; one finding per list.
std::vector<double> MachineLengthsMm(const YamlDoc& node, int n, const PlausibleRange& r,
                                     std::vector<std::string>* implausible) {
  const std::vector<double> v = node.Numbers(n);
  std::vector<std::string> found;
  for (int i = 0; i < n; ++i) MachineLengthMm(node.at(i), v[i], r, &found);
  if (!found.empty()) implausible->push_back(found.front());
  return v;
}

// A head length (pivot, tool): >= 0; 0 is a head without offset, otherwise
// within HeadLengthRange.
double HeadLengthMm(const YamlDoc& node, std::vector<std::string>* implausible) {
  const double v = node.Number();
  if (v < 0.0) throw node.Error("expected a length >= 0 mm, got " + node.String());
  MachineLengthMm(node, v, MachineLengthRange(), nullptr);
  if (v != 0.0) CheckPlausible(node, v, HeadLengthRange(), implausible);
  return v;
}

}  // namespace

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
    const YamlDoc rn = a["resolution" + u];
    const double res = rn.Number();
    if (!(res > 0.0)) throw rn.Error("expected a resolution > 0, got " + FormatDouble(res));
    const double res_max = mm ? kMaxLinearResolutionMm : kMaxRotaryResolutionDeg;
    if (res > res_max) {
      throw rn.Error("expected a resolution of at most " + FormatDouble(res_max) + (mm ? " mm" : " deg (a turn)") +
                     ", got " + rn.String() + (mm ? ": a resolution in nm or um typed in the mm field?"
                                                  : ": a resolution in arc-seconds typed in the deg field?"));
    }
    CheckPlausible(rn, res, mm ? LinearResolutionRange() : RotaryResolutionRange(), &f.implausible);
    s.resolution = ToSi(s, res);
    const YamlDoc on = a["origin" + u];
    // Rotary origins are any angle (a C table counts turns); linear ones are
    // positions in machine coordinates.
    s.origin = ToSi(s, mm ? MachineLengthMm(on, on.Number(), MachineLengthRange(), &f.implausible) : on.Number());
    a.RejectUnknownKeys();
    f.machine.axes.push_back(s);
  }
  if (f.machine.axes.size() > static_cast<size_t>(8)) {
    throw axes.Error("at most 8 axes fit the 16-bit capture words of formats.md §8.2");
  }
  const YamlDoc k = doc["kinematics"];
  const std::string type = k["type"].String();
  // The registry's refusal ("unknown kinematics type 'x': expected a or b"),
  // at the type's file:line:col; checked before the geometry is read.
  const auto& kinds = machine::KinematicsKinds();
  k["type"].Checked([&] { kinds.Find(type); });
  machine::NutatingHeadGeometry& g = f.geometry;
  const double nutation_deg = DegreesInRange(k["nutation_deg"], 0.0, 90.0, false, true);
  if (nutation_deg < kMinPlausibleNutationDeg) {
    f.implausible.push_back("implausible (unit mistake?): " + k["nutation_deg"].location().ToString() +
                            ": " + k["nutation_deg"].key_path() + " " + k["nutation_deg"].String() + " deg is under the " +
                            FormatDouble(kMinPlausibleNutationDeg) + " deg of nutating heads (built at 30 - 50 deg): " +
                            k["nutation_deg"].String() + " rad is " + FormatNumber(RadToDeg(nutation_deg), 4) +
                            " deg; radians typed in a _deg field?");
  }
  g.nutation = DegToRad(nutation_deg);
  g.pivot_length = MmToM(HeadLengthMm(k["pivot_length_mm"], &f.implausible));
  g.tool_length = MmToM(HeadLengthMm(k["tool_length_mm"], &f.implausible));
  const auto cc = MachineLengthsMm(k["c_centre_mm"], 2, MachineLengthRange(), &f.implausible);
  g.c_centre = {MmToM(cc[0]), MmToM(cc[1])};
  const auto zo = MachineLengthsMm(k["zero_offset_mm"], 3, MachineLengthRange(), &f.implausible);
  g.zero_offset = {MmToM(zo[0]), MmToM(zo[1]), MmToM(zo[2])};
  if (k.Has("errors")) {
    const YamlDoc e = k["errors"];
    if (e.Has("b_eccentricity_mm")) {
      const auto v = MachineLengthsMm(e["b_eccentricity_mm"], 2, GeometricErrorRange(), &f.implausible);
      g.b_eccentricity = {MmToM(v[0]), MmToM(v[1])};
    }
    if (e.Has("pivot_length_error_mm")) {
      const YamlDoc n = e["pivot_length_error_mm"];
      g.pivot_length_error = MmToM(MachineLengthMm(n, n.Number(), GeometricErrorRange(), &f.implausible));
    }
    if (e.Has("c_eccentricity_mm")) {
      const auto v = MachineLengthsMm(e["c_eccentricity_mm"], 2, GeometricErrorRange(), &f.implausible);
      g.c_eccentricity = {MmToM(v[0]), MmToM(v[1])};
    }
    e.RejectUnknownKeys();
  } else {
    k.MarkUsed("errors");
  }
  k.RejectUnknownKeys();
  f.machine.kinematics = kinds.Find(type)(g);
  f.machine.kinematic_axis =
      axes.Checked([&] { return machine::MapKinematicAxes(f.machine.axes, *f.machine.kinematics); });
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
