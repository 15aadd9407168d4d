#include "robomach/io/drilling_files.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "plausible.h"
#include "robomach/common/solver_status.h"
#include "robomach/common/units.h"
#include "robomach/drilling/plausibility.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {
namespace {

std::string User(double v);

double PositiveCell(const CsvTable& t, int row, const std::string& column) {
  const double v = t.Number(row, column);
  if (!(v > 0.0)) {
    throw t.ErrorAt(row, column, "expected a positive number, got " + t.Text(row, column));
  }
  return v;
}

// A table row is a measurement of twist drilling: a diameter or feed outside
// the practice of drilling::plausibility.h cannot be one, and is almost
// always a unit mistake (m or um in the mm column, mm/min in mm/rev).
double PracticeCell(const CsvTable& t, int row, const std::string& column, double lo_mm, double hi_mm,
                    const std::string& unit, const std::string& too_high, const std::string& too_low) {
  const double v = PositiveCell(t, row, column);
  if (v < lo_mm || v > hi_mm) {
    throw t.ErrorAt(row, column, "expected " + User(lo_mm) + " to " + User(hi_mm) + " " + unit +
                                     " (twist-drilling practice), got " + t.Text(row, column) + ": " +
                                     (v > hi_mm ? too_high : too_low));
  }
  return v;
}

std::string ChiselName(drilling::ChiselModel c) {
  switch (c) {
    case drilling::ChiselModel::kSeedScaling: return "seed_scaling";
    case drilling::ChiselModel::kOrthogonal: return "orthogonal";
    case drilling::ChiselModel::kNone: return "none";
  }
  return "seed_scaling";
}

std::string Quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// A value converted back to the user's unit (mm, deg): 12 significant digits
// hide the conversion's last-bit residue (0.12000000000000001).
std::string User(double v) {
  std::ostringstream s;
  s << std::setprecision(12) << v;
  return s.str();
}

// Four significant digits for derived numbers (model values, errors).
std::string Sig(double v, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

}  // namespace

ForceTableFile ReadForceTable(const std::string& path, bool require_forces) {
  const CsvTable t = CsvTable::ReadFile(path);
  ForceTableFile out;
  out.path = path;
  if (auto it = t.metadata().find("source"); it != t.metadata().end()) out.source = it->second;
  t.RequireColumn("diameter_mm");
  t.RequireColumn("feed_mm_per_rev");
  const bool forces = require_forces || (t.HasColumn("thrust_N") && t.HasColumn("torque_Nm"));
  if (require_forces) {
    t.RequireColumn("thrust_N");
    t.RequireColumn("torque_Nm");
  }
  if (t.num_rows() == 0) {
    throw InputError({path, t.header_line(), 0}, "expected at least one data row after the header");
  }
  out.unknown_columns =
      t.UnknownColumns({"diameter_mm", "feed_mm_per_rev", "thrust_N", "torque_Nm", "speed_rpm"});
  for (int r = 0; r < t.num_rows(); ++r) {
    drilling::ForceTableRow row;
    row.diameter = MmToM(PracticeCell(t, r, "diameter_mm", MToMm(drilling::kMinPlausibleDrillDiameter),
                                      MToMm(drilling::kMaxPlausibleDrillDiameter), "mm",
                                      "a diameter in um in the mm column?", "a diameter in m in the mm column?"));
    row.feed_per_rev = MmToM(PracticeCell(t, r, "feed_mm_per_rev", MToMm(drilling::kMinPlausibleFeedPerRev),
                                          MToMm(drilling::kMaxPlausibleFeedPerRev), "mm/rev",
                                          "a feed in mm/min (feed per rev x rpm) in the mm/rev column?",
                                          "a feed in m/rev in the mm/rev column?"));
    if (forces) {
      row.thrust = PositiveCell(t, r, "thrust_N");
      row.torque = PositiveCell(t, r, "torque_Nm");
    }
    std::optional<double> rpm;
    if (t.HasColumn("speed_rpm") && !t.IsEmpty(r, "speed_rpm")) rpm = PositiveCell(t, r, "speed_rpm");
    out.rows.push_back(row);
    out.speed_rpm.push_back(rpm);
    out.lines.push_back(t.line(r));
  }
  return out;
}

DrillFile ReadDrillFile(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path);
  if (!doc.IsMap()) throw doc.Error("expected a drill file (a YAML map with 'drill:')");
  DrillFile out;
  out.path = path;
  drilling::DrillGeometry& g = out.drill;
  const YamlDoc d = doc["drill"];
  g.diameter = MmToM(d["diameter_mm"].PositiveNumber());
  g.lips = d["lips"].IntInRange(1, 8);
  // A refused angle says when it is an angle of the range in radians.
  g.point_angle = DegToRad(DegreesInRange(d["point_angle_deg"], 60.0, 180.0, false, false));
  g.helix_angle = DegToRad(DegreesInRange(d["helix_angle_deg"], 0.0, 60.0, true, false));
  g.web_thickness_ratio = d["web_thickness_ratio"].NumberInRange(0.0, 0.5, true, false);
  g.chisel_edge_angle = DegToRad(DegreesInRange(d["chisel_edge_angle_deg"], 90.0, 180.0, false, false));
  g.lip_relief_angle = DegToRad(DegreesInRange(d["lip_relief_angle_deg"], 0.0, 45.0, true, false));
  d.RejectUnknownKeys();
  d.Checked([&] { drilling::CheckValid(g); });

  drilling::DrillingProcess& p = out.process;
  if (doc.Has("process")) {
    out.has_process = true;
    const YamlDoc pr = doc["process"];
    p.feed_per_rev = MmToM(pr["feed_mm_per_rev"].PositiveNumber());
    p.spindle_speed_rad_s = RpmToRadPerSec(pr["speed_rpm"].PositiveNumber());
    const YamlDoc q0 = pr["initial_posture_deg"];
    const auto q = q0.Numbers();
    if (q.empty()) throw q0.Error("expected one angle per joint");
    std::vector<TypedAngle> angles;
    for (size_t j = 0; j < q.size(); ++j) angles.push_back({q0.at(static_cast<int>(j)), q[j]});
    CheckDegreesNotRadians(angles, &out.implausible);
    p.initial_posture.resize(static_cast<int>(q.size()));
    for (size_t j = 0; j < q.size(); ++j) p.initial_posture(j) = DegToRad(q[j]);
    out.initial_posture_at = q0.location();
    const YamlDoc axis = pr["hole_axis"];
    const std::string a = axis.String();
    p.hole_axis = axis.Checked([&] { return drilling::ParseHoleAxis(a); });
    out.hole_axis_at = axis.location();
    pr.RejectUnknownKeys();
  }
  doc.MarkUsed("process");
  if (doc.Has("offset")) {
    const YamlDoc o = doc["offset"];
    if (o.Has("initial_tilt_deg")) p.initial_tilt = DegToRad(o["initial_tilt_deg"].NumberInRange(-10.0, 10.0));
    o.MarkUsed("initial_tilt_deg");
    o.RejectUnknownKeys();
  }
  doc.MarkUsed("offset");
  if (doc.Has("simulation")) {
    const YamlDoc s = doc["simulation"];
    if (s.Has("duration_s")) p.duration = s["duration_s"].NumberInRange(0.0, 600.0, false, true);
    if (s.Has("control_period_s")) {
      p.control_period = s["control_period_s"].NumberInRange(1e-5, 0.1);
    }
    if (s.Has("error_band_deg")) p.error_band = DegToRad(s["error_band_deg"].PositiveNumber());
    for (const char* k : {"duration_s", "control_period_s", "error_band_deg"}) s.MarkUsed(k);
    s.RejectUnknownKeys();
    if (p.control_period > p.duration) {
      throw s["control_period_s"].Error("expected a control period shorter than duration_s");
    }
  }
  doc.MarkUsed("simulation");
  doc.RejectUnknownKeys();
  return out;
}

std::string MaterialYaml(const drilling::ForceFitResult& fit, const drilling::DrillGeometry& drill,
                         const ForceTableFile& table) {
  const drilling::DrillingMaterial& m = fit.material;
  std::ostringstream s;
  s << "# Drilling force coefficients fitted by drill-force-fit (formats.md 9.2).\n"
    << "# Model: oblique-cutting lip elements with the dynamic rake angle (seed 003,\n"
    << "# Minukhin 2013); shear stress tau = K (h / h_ref)^(-m) on the uncut chip thickness h.\n"
    << "material:\n"
    << "  shear_stress_thrust_MPa: " << FormatDouble(m.shear_stress_thrust * 1e-6) << "   # K_TH at h_ref\n"
    << "  shear_stress_torque_MPa: " << FormatDouble(m.shear_stress_torque * 1e-6) << "   # K_TQ at h_ref\n"
    << "  kienzle_exponent: " << FormatDouble(m.kienzle_exponent) << "   # m: forces go as f^(1 - m)\n"
    << "  reference_chip_thickness_mm: " << User(MToMm(m.reference_chip_thickness)) << "\n"
    << "  chisel: " << ChiselName(m.chisel) << "   # seed_scaling | orthogonal | none\n"
    << "  chisel_thrust_factor: " << FormatDouble(m.chisel_thrust_factor) << "\n"
    << "  chisel_torque_factor: " << FormatDouble(m.chisel_torque_factor) << "\n"
    << "  chisel_rake_deg: " << User(RadToDeg(m.chisel_rake_angle)) << "\n"
    << "std_dev:   # 1 sigma from the covariance, scaled by the residual variance\n"
    << "  shear_stress_thrust_MPa: " << Sig(fit.std_dev_shear_stress_thrust * 1e-6, 3) << "\n"
    << "  shear_stress_torque_MPa: " << Sig(fit.std_dev_shear_stress_torque * 1e-6, 3) << "\n"
    << "  kienzle_exponent: " << Sig(fit.std_dev_kienzle_exponent, 3) << "\n"
    << "fit:\n"
    << "  status: "
    << robomach::ToString(fit.status)
    << "\n"
    << "  solver: " << Quoted(fit.solver_message) << "\n"
    << "  max_rel_error_thrust: " << Sig(fit.max_rel_error_thrust) << "\n"
    << "  max_rel_error_torque: " << Sig(fit.max_rel_error_torque) << "\n"
    << "  rms_rel_error: " << Sig(fit.rms_rel_error) << "\n"
    << "  drill:   # the geometry the coefficients belong to (diameter from each row)\n"
    << "    lips: " << drill.lips << "\n"
    << "    point_angle_deg: " << User(RadToDeg(drill.point_angle)) << "\n"
    << "    helix_angle_deg: " << User(RadToDeg(drill.helix_angle)) << "\n"
    << "    web_thickness_ratio: " << FormatDouble(drill.web_thickness_ratio) << "\n"
    << "    chisel_edge_angle_deg: " << User(RadToDeg(drill.chisel_edge_angle)) << "\n"
    << "  table:\n"
    << "    path: " << Quoted(table.path) << "\n"
    << "    source: " << Quoted(table.source) << "\n"
    << "    rows:\n";
  for (size_t k = 0; k < table.rows.size(); ++k) {
    const auto& r = table.rows[k];
    s << "      - {diameter_mm: " << User(MToMm(r.diameter))
      << ", feed_mm_per_rev: " << User(MToMm(r.feed_per_rev)) << ", thrust_N: " << FormatDouble(r.thrust)
      << ", torque_Nm: " << FormatDouble(r.torque);
    if (k < fit.thrust_model.size()) {
      s << ", thrust_model_N: " << Sig(fit.thrust_model[k], 5)
        << ", torque_model_Nm: " << Sig(fit.torque_model[k], 5);
    }
    s << "}\n";
  }
  return s.str();
}

drilling::DrillingMaterial ReadMaterialFile(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path);
  if (!doc.IsMap()) throw doc.Error("expected a material file (a YAML map with 'material:')");
  const YamlDoc m = doc["material"];
  drilling::DrillingMaterial out;
  out.shear_stress_thrust = 1e6 * m["shear_stress_thrust_MPa"].PositiveNumber();
  out.shear_stress_torque = 1e6 * m["shear_stress_torque_MPa"].PositiveNumber();
  out.kienzle_exponent = m["kienzle_exponent"].NumberInRange(0.0, 1.0, true, false);
  out.reference_chip_thickness = MmToM(m["reference_chip_thickness_mm"].PositiveNumber());
  const YamlDoc ch = m["chisel"];
  const std::string c = ch.String();
  if (c == "seed_scaling") out.chisel = drilling::ChiselModel::kSeedScaling;
  else if (c == "orthogonal") out.chisel = drilling::ChiselModel::kOrthogonal;
  else if (c == "none") out.chisel = drilling::ChiselModel::kNone;
  else throw ch.Error("expected seed_scaling, orthogonal or none, got \"" + c + "\"");
  if (m.Has("chisel_thrust_factor")) out.chisel_thrust_factor = m["chisel_thrust_factor"].NumberInRange(1.0, 10.0);
  if (m.Has("chisel_torque_factor")) out.chisel_torque_factor = m["chisel_torque_factor"].NumberInRange(1.0, 10.0);
  if (m.Has("chisel_rake_deg")) {
    out.chisel_rake_angle = DegToRad(m["chisel_rake_deg"].NumberInRange(-90.0, 0.0, false, false));
  }
  for (const char* k : {"chisel_thrust_factor", "chisel_torque_factor", "chisel_rake_deg"}) m.MarkUsed(k);
  m.RejectUnknownKeys();
  doc.MarkUsed("std_dev");
  doc.MarkUsed("fit");
  doc.RejectUnknownKeys();
  return out;
}

FlexibleRobotFile ReadFlexibleRobotFile(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path);
  if (!doc.IsMap()) throw doc.Error("expected a robot config (a YAML map)");
  FlexibleRobotFile out;
  out.path = path;
  out.chain = ReadRobotChain(doc["robot"], path, &out.implausible);
  const int n = out.chain.num_joints();
  const auto& names = out.chain.joint_names();
  const YamlDoc list = doc["flexible_joints"];
  if (!list.IsSequence()) throw list.Error("expected a list with one entry per joint");
  std::vector<int> seen_at(n, -1);
  out.drives.resize(n);
  for (int i = 0; i < list.size(); ++i) {
    const YamlDoc e = list.at(i);
    const YamlDoc jn = e["joint"];
    const std::string name = jn.String();
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      std::string have;
      for (const auto& s : names) have += (have.empty() ? "" : ", ") + s;
      throw jn.Error("unknown joint '" + name + "'; the robot's joints are " + have);
    }
    const int j = static_cast<int>(it - names.begin());
    if (seen_at[j] >= 0) {
      throw jn.Error("joint '" + name + "' appears twice (first on line " +
                     std::to_string(seen_at[j]) + ")");
    }
    seen_at[j] = jn.location().line;
    drilling::JointDrive& d = out.drives[j];
    const YamlDoc k = e["stiffness_Nm_per_rad"];
    d.stiffness = k.Number();
    if (!(d.stiffness > 0.0)) throw k.Error("expected a joint stiffness > 0, got " + FormatDouble(d.stiffness));
    CheckPlausible(k, d.stiffness,
                   {kMinPlausibleJointStiffnessNmPerRad, kMaxPlausibleJointStiffnessNmPerRad, "N·m/rad",
                    "robot joints (1e3 for a small wrist to 1e7 for a heavy robot's base)",
                    "a stiffness in kN·m/rad typed in the N·m/rad field?",
                    "a stiffness in N·mm/rad typed in the N·m/rad field?"},
                   &out.implausible);
    const YamlDoc g = e["gear_ratio"];
    d.gear_ratio = g.Number();
    if (!(d.gear_ratio > 0.0)) throw g.Error("expected a gear ratio > 0, got " + FormatDouble(d.gear_ratio));
    CheckPlausible(g, d.gear_ratio,
                   {kMinPlausibleGearRatio, kMaxPlausibleGearRatio, "", "robot gearboxes (30 to 300)",
                    "the inverse ratio (output/input) typed?", "a typo (an extra zero)?"},
                   &out.implausible);
    const YamlDoc jm = e["rotor_inertia_kgm2"];
    d.rotor_inertia = jm.Number();
    if (!(d.rotor_inertia > 0.0)) {
      throw jm.Error("expected a rotor inertia > 0, got " + FormatDouble(d.rotor_inertia));
    }
    CheckPlausible(jm, d.rotor_inertia,
                   {kMinPlausibleRotorInertiaKgM2, kMaxPlausibleRotorInertiaKgM2, "kg·m²",
                    "servo motor rotors (1e-6 to 1e-2 kg·m²)", "a value in t·m² or kg·km²? (x1e-3)",
                    "a value in kg·cm² (x1e4) or g·cm² (x1e7) typed in the kg·m² field?"},
                   &out.implausible);
    if (e.Has("damping_Nms_per_rad")) {
      const YamlDoc c = e["damping_Nms_per_rad"];
      d.damping = c.Number();
      if (!(d.damping >= 0.0)) throw c.Error("expected a damping >= 0, got " + FormatDouble(d.damping));
    } else {
      d.damping = 0.0;
    }
    e.MarkUsed("damping_Nms_per_rad");
    e.RejectUnknownKeys();
  }
  for (int j = 0; j < n; ++j) {
    if (seen_at[j] < 0) {
      throw list.Error("no entry for joint '" + names[j] + "' (every joint needs one)");
    }
  }
  if (doc.Has("joint_stiffness_Nm_per_rad")) {
    const YamlDoc kq = doc["joint_stiffness_Nm_per_rad"];
    const auto kv = kq.Numbers(n);
    for (int j = 0; j < n; ++j) {
      if (std::abs(kv[j] - out.drives[j].stiffness) > 1e-9 * out.drives[j].stiffness) {
        throw kq.at(j).Error("joint_stiffness_Nm_per_rad of " + names[j] + " is " + FormatDouble(kv[j]) +
                             ", but flexible_joints says " + FormatDouble(out.drives[j].stiffness));
      }
    }
  }
  doc.MarkUsed("joint_stiffness_Nm_per_rad");
  for (const char* s : {"damping", "end_effector", "spindle_toolholder_interface", "hammer_test",
                        "effects", "parameters"}) {
    if (doc.Has(s)) out.unused_sections.push_back(s);
    doc.MarkUsed(s);
  }
  doc.RejectUnknownKeys();
  return out;
}

}  // namespace robomach::io
