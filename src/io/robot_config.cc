#include "robomach/io/robot_config.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <fstream>
#include <sstream>
#include <tuple>

#include "plausible.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/effect.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/number_format.h"
#include "robomach/io/urdf_loader.h"
#include "robomach/io/yaml_doc.h"
#include "robomach/kinematics/modified_dh.h"

namespace robomach::io {
namespace {

using kinematics::Inertial;

Eigen::Vector3d Vec3(const YamlDoc& node) {
  const auto v = node.Numbers(3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

// [Ixx Iyy Izz Ixy Ixz Iyz] about the COM, as the reference YAML writes it.
Eigen::Matrix3d Inertia6(const YamlDoc& node) {
  const auto v = node.Numbers(6);
  Eigen::Matrix3d I;
  I << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
  return I;
}

const PlausibleRange& BodyMassRange() {
  static const PlausibleRange r{0.0, kMaxPlausibleBodyMassKg, "kg",
                                "robot links and end-effector bodies (a 1000 kg-payload robot's heaviest link is "
                                "about 1 t)",
                                "", "a mass in g typed in the kg field?"};
  return r;
}

const PlausibleRange& LengthRange() {
  static const PlausibleRange r{0.0, kMaxPlausibleRobotLengthM, "m",
                                "robot geometry (the longest industrial arms reach 4 m)", "",
                                "a length in mm typed in the m field?"};
  return r;
}

// Each component of a length vector (com_m, tcp_m, xyz): |v| within LengthRange.
void CheckLengths(const YamlDoc& node, const Eigen::Vector3d& v, std::vector<std::string>* implausible) {
  for (int i = 0; i < 3; ++i) {
    if (std::abs(v(i)) > kMaxPlausibleRobotLengthM) {
      CheckPlausible(node.at(i), std::abs(v(i)), LengthRange(), implausible);
      return;  // one finding per vector
    }
  }
}

Inertial ReadInertial(const YamlDoc& node, std::vector<std::string>* implausible) {
  Inertial b;
  {
    // A negative mass is reported on its own line, not on inertia_kgm2's.
    const YamlDoc m = node["mass_kg"];
    b.mass = m.Number();
    if (b.mass < 0.0) throw m.Error("expected a mass >= 0 kg, got " + m.String() + " (a link's mass cannot be negative)");
    CheckPlausible(m, b.mass, BodyMassRange(), implausible);
  }
  b.com = Vec3(node["com_m"]);
  CheckLengths(node["com_m"], b.com, implausible);
  const YamlDoc inertia = node["inertia_kgm2"];
  b.inertia_com = Inertia6(inertia);
  if (auto problem = kinematics::CheckInertial(b)) throw inertia.Error(*problem);
  return b;
}

Eigen::Isometry3d ReadPose(const YamlDoc& node, const std::string& xyz_key,
                           const std::string& rpy_key, std::vector<TypedAngle>* angles,
                           std::vector<std::string>* implausible) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  if (node.Has(xyz_key)) {
    X.translation() = Vec3(node[xyz_key]);
    CheckLengths(node[xyz_key], X.translation(), implausible);
  } else {
    node.MarkUsed(xyz_key);
  }
  if (node.Has(rpy_key)) {
    const YamlDoc rpy_node = node[rpy_key];
    const Eigen::Vector3d rpy = Vec3(rpy_node);
    for (int i = 0; i < 3; ++i) angles->push_back({rpy_node.at(i), rpy(i)});
    // URDF convention: fixed-axis roll, pitch, yaw: R = Rz(y) Ry(p) Rx(r).
    X.linear() = (Eigen::AngleAxisd(DegToRad(rpy(2)), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(DegToRad(rpy(1)), Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(DegToRad(rpy(0)), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  } else {
    node.MarkUsed(rpy_key);
  }
  return X;
}

kinematics::SerialChain ReadDh(const YamlDoc& dh, std::vector<std::string>* implausible) {
  std::vector<kinematics::ModifiedDhRow> rows;
  std::vector<TypedAngle> angles;  // every _deg value of the table, for the unit check
  const auto angle = [&](const YamlDoc& node) {
    const double v = node.Number();
    angles.push_back({node, v});
    return DegToRad(v);
  };
  const auto length = [&](const YamlDoc& node) {
    const double v = node.Number();
    CheckPlausible(node, std::abs(v), LengthRange(), implausible);
    return v;
  };
  const YamlDoc links = dh["links"];
  for (int i = 0; i < links.size(); ++i) {
    const YamlDoc l = links.at(i);
    kinematics::ModifiedDhRow r;
    r.joint_name = l.Has("joint") ? l["joint"].String() : "joint_" + std::to_string(i + 1);
    l.MarkUsed("joint");
    r.alpha_prev = angle(l["alpha_prev_deg"]);
    r.a_prev = length(l["a_prev_m"]);
    r.d = length(l["d_m"]);
    r.theta_offset = l.Has("theta_offset_deg") ? angle(l["theta_offset_deg"]) : 0.0;
    l.MarkUsed("theta_offset_deg");
    if (l.Has("lower_deg") || l.Has("upper_deg")) {
      r.limits.lower = angle(l["lower_deg"]);
      const YamlDoc up = l["upper_deg"];
      r.limits.upper = angle(up);
      if (!(r.limits.lower < r.limits.upper)) throw up.Error("expected upper_deg > lower_deg");
      r.limits.bounded = true;
    }
    l.MarkUsed("lower_deg");
    l.MarkUsed("upper_deg");
    r.inertial = ReadInertial(l, implausible);
    l.RejectUnknownKeys();
    rows.push_back(r);
  }
  if (rows.empty()) throw links.Error("expected at least one link");
  const Eigen::Isometry3d X_B0 = ReadPose(dh, "base_xyz_m", "base_rpy_deg", &angles, implausible);
  const Eigen::Isometry3d X_nT = ReadPose(dh, "tip_xyz_m", "tip_rpy_deg", &angles, implausible);
  // Radians in the _deg fields: the twists of a real arm are 0 and +-90 deg,
  // +-1.5708 in radians (issue #35: named whatever the joint limits).
  CheckDegreesNotRadians(angles, implausible);
  dh.RejectUnknownKeys();
  return kinematics::BuildModifiedDhChain(rows, X_B0, X_nT, "base", "tip");
}

void ReadNumericSection(const YamlDoc& section, const std::string& prefix,
                        std::map<std::string, double>* out, std::map<std::string, SourceLocation>* where) {
  for (const std::string& key : section.Keys()) {
    const YamlDoc v = section[key];
    if (v.IsSequence()) continue;  // lists such as hammer_test.directions are informational
    (*out)[prefix + "." + key] = v.Number();
    (*where)[prefix + "." + key] = v.location();
  }
}

std::string FormatNumber(double v) { return FormatDouble(v); }

// ": 29050 is 1000 x 29.05: a value in g typed in the kg field?" when value
// and reference differ by a factor within 20 % of 1000 (or 1/1000).
std::string ThousandHint(double value, double reference, const std::string& small_unit, const std::string& unit) {
  if (!(reference != 0.0) || !std::isfinite(value)) return "";
  const double r = value / reference;
  if (r > 800.0 && r < 1250.0) {
    return "; " + FormatDouble(value) + " is 1000 x " + FormatDouble(reference) + ": a value in " + small_unit +
           " typed in the " + unit + " field?";
  }
  if (r > 0.0008 && r < 0.00125) {
    return "; " + FormatDouble(value) + " is " + FormatDouble(reference) + " / 1000: a value in k" + unit +
           " typed in the " + unit + " field?";
  }
  return "";
}

// The findings so far, for a refusal they may explain (a body mass in g
// makes m6_kg disagree with the bodies): put first, since the refusal is
// only their consequence (issue #35: the cause came at the end).
std::string LikelyCause(const std::vector<std::string>& findings) {
  if (findings.empty()) return "";
  const std::string prefix = "implausible (unit mistake?): ";
  std::string s = "the likely cause: ";
  for (size_t i = 0; i < findings.size(); ++i) {
    const std::string& f = findings[i];
    s += (i ? "; and " : "") + (f.rfind(prefix, 0) == 0 ? f.substr(prefix.size()) : f);
  }
  return s + " -- which makes this check fail: ";
}

// The keys of `spindle_toolholder_interface` (docs/plausibility.md): a value
// no holder can have is refused here, with file:line:col (the library's
// check would name neither the place nor, for a zero diameter, the key); a
// value outside the plausible range of holders (a diameter in mm under an
// `_m` key, a drawbar force in kN) is a finding: the tool flags its result.
void CheckSpindleInterface(const YamlDoc& section, std::vector<std::string>* implausible) {
  struct Rule {
    const char* key;
    double impossible_below;  // refused at or below (or below, see `strict`)
    bool strict;              // true: value <= bound refused; false: value < bound
    const char* expected;
    PlausibleRange range;
  };
  const Rule rules[] = {
      {"friction_coefficient", 0.0, false, "a friction coefficient >= 0",
       {0.0, kMaxPlausibleFrictionCoefficient, "", "holder-spindle contacts (dry steel on steel 0.1 - 0.8)", "",
        "a percentage typed for a coefficient (15 for 0.15)?"}},
      {"alpha_prime", 0.0, true, "Yoshimura's alpha' > 0 (k_n = alpha' p^beta', p in Pa, k_n in N/m³)",
       {kMinPlausibleYoshimuraAlpha, kMaxPlausibleYoshimuraAlpha, "", "Yoshimura's alpha' with p in Pa (the seed's 3.26e6)",
        "alpha' for a pressure in MPa or k_n in N/mm³?", "alpha' for a pressure in kPa or k_n per mm²?"}},
      {"beta_prime", 0.0, false, "Yoshimura's exponent beta' >= 0",
       {kMinPlausibleYoshimuraBeta, kMaxPlausibleYoshimuraBeta, "", "Yoshimura's exponent of machined joints (0.3 - 1)",
        "the exponent of another law?", "alpha' and beta' swapped, or a percentage?"}},
      {"tangential_to_normal", 0.0, true, "a ratio > 0",
       {kMinPlausibleTangentialToNormal, kMaxPlausibleTangentialToNormal, "", "contact stiffness ratios (the seed's 0.5)",
        "a ratio inverted?", "a percentage typed for a ratio (50 for 0.5)?"}},
      {"drawbar_force_N", 0.0, true, "a clamping force > 0 N",
       {kMinPlausibleDrawbarForceN, kMaxPlausibleDrawbarForceN, "N",
        "spindle drawbars (3 kN for HSK-E25 to 60 kN for SK/BT 50)", "a force in kN typed in the N field?",
        "a force in mN, or in N x 1000?"}},
      {"taper_large_diameter_m", 0.0, true, "a diameter > 0 m",
       {kMinPlausibleTaperDiameterM, kMaxPlausibleTaperDiameterM, "m",
        "HSK, SK and BT holders (19 - 120 mm: HSK-25 to HSK-160, SK/BT 30 - 60)", "a radius, or a diameter in km?",
        "a diameter in mm typed in the m field?"}},
      {"taper_length_m", 0.0, true, "a length > 0 m",
       {kMinPlausibleTaperLengthM, kMaxPlausibleTaperLengthM, "m", "holder tapers (10 - 170 mm)", "",
        "a length in mm typed in the m field?"}},
      {"taper_ratio", 0.0, true, "a diameter change per length > 0 (HSK 1:10 = 0.1, SK/BT 7:24 = 0.29)",
       {kMinPlausibleTaperRatio, kMaxPlausibleTaperRatio, "", "holder tapers (HSK 0.1, SK/BT 7:24 = 0.29)",
        "a ratio in percent of a percent?", "the ratio inverted (10 for 1:10) or an angle in degrees?"}},
  };
  for (const Rule& r : rules) {
    if (!section.Has(r.key)) continue;
    const YamlDoc node = section[r.key];
    const double v = node.Number();
    if (r.strict ? !(v > r.impossible_below) : !(v >= r.impossible_below)) {
      throw node.Error(std::string("expected ") + r.expected + ", got " + node.String());
    }
    CheckPlausible(node, v, r.range, implausible);
  }
  if (section.Has("elements")) {
    const YamlDoc node = section["elements"];
    const double v = node.Number();
    if (!(v >= 1.0 && v <= kMaxTaperElements) || v != std::floor(v)) {
      throw node.Error("expected a whole number of taper rings in [1, " + std::to_string(kMaxTaperElements) +
                       "] (the seed: 6), got " + node.String());
    }
  }
  // The taper must keep a small diameter: D - ratio L > 0.
  if (section.Has("taper_ratio") && section.Has("taper_length_m") && section.Has("taper_large_diameter_m")) {
    const YamlDoc ratio = section["taper_ratio"];
    const double L = section["taper_length_m"].Number(), D = section["taper_large_diameter_m"].Number();
    if (!(ratio.Number() * L < D)) {
      throw ratio.Error(LikelyCause(*implausible) +
                        "the taper's small diameter taper_large_diameter_m - taper_ratio x taper_length_m = " +
                        FormatDouble(D) + " - " + ratio.String() + " x " + FormatDouble(L) + " m is not > 0");
    }
  }
}

void CheckHammerTest(const YamlDoc& section, std::vector<std::string>* implausible) {
  if (!section.Has("sample_rate_hz")) return;
  const YamlDoc node = section["sample_rate_hz"];
  if (!(node.Number() > 0.0)) throw node.Error("expected a sample rate > 0 Hz, got " + node.String());
  CheckPlausible(node, node.Number(),
                 {kMinPlausibleHammerSampleRateHz, kMaxPlausibleHammerSampleRateHz, "Hz",
                  "hammer-test acquisition (1 - 200 kHz; the seed's 5120 Hz)", "a rate in kHz typed in the Hz field?",
                  "a rate in mHz typed in the Hz field?"},
                 implausible);
}

// joint_stiffness_Nm_per_rad: one stiffness > 0 per joint of the chain, each
// checked to be plausible. The node is returned for where each was typed
// (RobotConfig::joint_value_locations).
YamlDoc ReadJointStiffness(const YamlDoc& doc, RobotConfig* cfg) {
  dynamics::RobotDescription& d = cfg->description;
  const int n = d.arm.num_joints();
  const YamlDoc kq = doc["joint_stiffness_Nm_per_rad"];
  const auto kv = kq.Numbers(n);
  d.joint_stiffness = Eigen::Map<const Eigen::VectorXd>(kv.data(), n);
  for (int j = 0; j < n; ++j) {
    if (!(kv[j] > 0.0)) throw kq.at(j).Error("expected a joint stiffness > 0");
    CheckPlausible(kq.at(j), kv[j],
                   {kMinPlausibleJointStiffnessNmPerRad, kMaxPlausibleJointStiffnessNmPerRad, "N·m/rad",
                    "robot joints (1e3 for a small wrist to 1e7 for a heavy robot's base)",
                    "a stiffness in kN·m/rad typed in the N·m/rad field?",
                    "a stiffness in N·mm/rad typed in the N·m/rad field?"},
                   &cfg->implausible);
  }
  return kq;
}

// damping: the Rayleigh coefficients alpha_s and beta_per_s, each in its
// range. The node is returned for where it was typed.
YamlDoc ReadDamping(const YamlDoc& doc, dynamics::RobotDescription* d) {
  const YamlDoc damping = doc["damping"];
  // alpha_s and beta_per_s swapped is the likely mistake behind an alpha
  // beyond 0.1 s (the seed's are 1e-4 s and 5 /s): say so when refusing.
  const YamlDoc a = damping["alpha_s"];
  const YamlDoc b = damping["beta_per_s"];
  const double av = a.Number(), bv = b.Number();
  const bool swapped = av > 0.1 && bv >= 0.0 && bv <= 0.1 && av <= 1e3;
  const std::string hint = swapped ? " (alpha_s and beta_per_s swapped? C = alpha K + beta M: alpha is a time of "
                                     "about 1e-4 s, beta a rate of about 1-10 /s)"
                                   : "";
  if (!(av >= 0.0 && av <= 0.1)) {
    throw a.Error("expected a number in [0, 0.1] s, got " + a.String() + hint +
                  (swapped || av < 0.0 ? "" : " (alpha_s in ms? x1000)"));
  }
  if (!(bv >= 0.0 && bv <= 1e3)) throw b.Error("expected a number in [0, 1000] /s, got " + b.String() + hint);
  d->alpha = av;
  d->beta = bv;
  damping.RejectUnknownKeys();
  return damping;
}

// end_effector: its bodies, the TCP and spindle nose positions, and the
// reference m6_kg / d6_m, which must agree with the geometry.
void ReadEndEffector(const YamlDoc& doc, RobotConfig* cfg) {
  dynamics::RobotDescription& d = cfg->description;
  const YamlDoc ee = doc["end_effector"];
  if (ee.Has("bodies")) {
    const YamlDoc bodies = ee["bodies"];
    for (int i = 0; i < bodies.size(); ++i) {
      const YamlDoc b = bodies.at(i);
      dynamics::EndEffectorBody body;
      body.name = b["name"].String();
      body.inertial = ReadInertial(b, &cfg->implausible);
      b.RejectUnknownKeys();
      d.end_effector.bodies.push_back(body);
    }
  }
  ee.MarkUsed("bodies");
  d.end_effector.p_tcp = Vec3(ee["tcp_m"]);
  CheckLengths(ee["tcp_m"], d.end_effector.p_tcp, &cfg->implausible);
  if (ee.Has("spindle_nose_m")) {
    d.end_effector.p_spindle_nose = Vec3(ee["spindle_nose_m"]);
    CheckLengths(ee["spindle_nose_m"], d.end_effector.p_spindle_nose, &cfg->implausible);
  } else {
    d.end_effector.p_spindle_nose = d.end_effector.p_tcp;
  }
  ee.MarkUsed("spindle_nose_m");
  // m6_kg and d6_m document the reference values; they must match the
  // geometry (a calibrated value goes under `parameters:` instead).
  const double m6 = dynamics::ReferenceM6(d);
  const double d6 = dynamics::ReferenceD6(d);
  if (ee.Has("m6_kg")) {
    const YamlDoc node = ee["m6_kg"];
    if (std::abs(node.Number() - m6) > 1e-6 * std::max(1.0, m6)) {
      throw node.Error(LikelyCause(cfg->implausible) + "the last link and the end-effector bodies weigh " +
                       FormatNumber(m6) +
                       " kg; m6_kg must state that reference (put a calibrated m6 under "
                       "'parameters: m6_kg')" + ThousandHint(node.Number(), m6, "g", "kg"));
    }
  }
  if (ee.Has("d6_m")) {
    const YamlDoc node = ee["d6_m"];
    if (std::abs(node.Number() - d6) > 1e-6) {
      throw node.Error(LikelyCause(cfg->implausible) + "the geometry puts the tool tip " + FormatNumber(d6) +
                       " m from the wrist centre along the last joint axis; d6_m must state "
                       "that reference (put a calibrated d6 under 'parameters: d6_m')" +
                       ThousandHint(node.Number(), d6, "mm", "m"));
    }
  }
  ee.MarkUsed("m6_kg");
  ee.MarkUsed("d6_m");
  ee.RejectUnknownKeys();
}

// effects: each named effect from the registry, with the values of its
// parameters.
void ReadEffects(const YamlDoc& doc, dynamics::RobotDescription* d) {
  if (doc.Has("effects")) {
    const YamlDoc effects = doc["effects"];
    for (int i = 0; i < effects.size(); ++i) {
      const YamlDoc e = effects.at(i);
      dynamics::EffectConfig ec;
      const YamlDoc name = e["name"];
      ec.name = name.String();
      const std::shared_ptr<const dynamics::Effect> effect =
          name.Checked([&] { return dynamics::EffectRegistry::Instance().Create(ec.name); });
      for (const auto& spec : effect->parameters()) {
        if (e.Has(spec.name)) ec.values[spec.name] = e[spec.name].Number();
        e.MarkUsed(spec.name);
      }
      e.RejectUnknownKeys();
      d->effects.push_back(ec);
    }
  }
  doc.MarkUsed("effects");
}

// The model parameters: the defaults of the description, then the values
// given under `parameters:`, each accepted by the parameter set.
void ReadParameters(const YamlDoc& doc, const std::string& path, RobotConfig* cfg) {
  cfg->parameters = AtLocation({path, 0, 0}, "", [&] { return dynamics::DefaultParameters(cfg->description); });
  if (doc.Has("parameters")) {
    const YamlDoc params = doc["parameters"];
    for (const std::string& key : params.Keys()) {
      const YamlDoc v = params[key];
      try {
        cfg->parameters.Set(key, v.Number());
      } catch (const std::invalid_argument& ex) {
        // A value 1000 times the configured one is a unit mistake more
        // often than a calibration (g for kg, mm for m, N·mm for N·m).
        const double reference = cfg->parameters.Has(key) ? cfg->parameters.Get(key) : 0.0;
        std::string unit = "", small = "";
        for (const auto& [suffix, u, su] : {std::tuple{"_Nm_per_rad", "N·m/rad", "N·mm/rad"}, {"_kg", "kg", "g"},
                                            {"_per_s", "1/s", "1/ms"}, {"_m", "m", "mm"}, {"_s", "s", "ms"}}) {
          const std::string sfx = suffix;
          if (key.size() > sfx.size() && key.compare(key.size() - sfx.size(), sfx.size(), sfx) == 0) {
            unit = u;
            small = su;
            break;
          }
        }
        throw v.Error(ex.what() + (unit.empty() ? "" : ThousandHint(v.Number(), reference, small, unit)));
      }
    }
  }
  doc.MarkUsed("parameters");
}

}  // namespace

kinematics::SerialChain ReadRobotChain(const YamlDoc& robot, const std::string& path,
                                       std::vector<std::string>* implausible) {
  kinematics::SerialChain arm;
  if (robot.Has("dh")) {
    arm = ReadDh(robot["dh"], implausible);
  } else {
    const YamlDoc urdf = robot["urdf"];
    const std::string urdf_path = ResolveRelative(path, urdf.String());
    const FileSniff sniff = SniffFileKind(urdf_path);
    if (sniff.kind == FileKind::kMissing) {
      // Say where the file was looked for: a config copied to another
      // folder without its URDF is the usual cause (issue #35).
      namespace fs = std::filesystem;
      const std::string where =
          fs::path(urdf.String()).is_absolute()
              ? " (an absolute path): check it, or copy the URDF there"
              : "; a relative urdf: path is resolved against the config's folder " +
                    fs::absolute(fs::path(path).parent_path()).lexically_normal().string() +
                    " (not the working folder), which gives " + fs::absolute(urdf_path).lexically_normal().string() +
                    ": copy the URDF there or write its absolute path";
      const InputError e = urdf.Error(urdf.String() + ": " + sniff.description + where);
      throw MissingFileError(e.where(), e.message());
    }
    if (sniff.kind != FileKind::kXml && sniff.kind != FileKind::kText && sniff.kind != FileKind::kEmpty) {
      throw urdf.Error(urdf_path + ": " + WrongFileKindMessage(sniff, "a URDF (XML) file"));
    }
    const std::string base = robot["base_link"].String();
    const std::string tip = robot["tip_frame"].String();
    arm = LoadUrdfChain(urdf_path, base, tip);
  }
  if (robot.Has("joint_names")) {
    const YamlDoc jn = robot["joint_names"];
    if (jn.Strings() != arm.joint_names()) {
      std::string have;
      for (const auto& n : arm.joint_names()) have += (have.empty() ? "" : ", ") + n;
      throw jn.Error("the chain's joints are [" + have + "]");
    }
  }
  robot.MarkUsed("joint_names");
  robot.RejectUnknownKeys();
  return arm;
}

RobotConfig LoadRobotConfig(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path, kRobotConfigFormat);
  if (!doc.IsMap()) throw doc.Error("expected a robot config (a YAML map)");
  RobotConfig cfg;
  cfg.path = path;
  dynamics::RobotDescription& d = cfg.description;
  d.source = path;

  d.arm = ReadRobotChain(doc["robot"], path, &cfg.implausible);
  const YamlDoc kq = ReadJointStiffness(doc, &cfg);
  const YamlDoc damping = ReadDamping(doc, &d);
  ReadEndEffector(doc, &cfg);

  for (const char* section : {"spindle_toolholder_interface", "hammer_test"}) {
    if (doc.Has(section)) ReadNumericSection(doc[section], section, &d.extra_values, &cfg.extra_value_locations);
    doc.MarkUsed(section);
  }
  if (doc.Has("spindle_toolholder_interface")) {
    CheckSpindleInterface(doc["spindle_toolholder_interface"], &cfg.implausible);
  }
  if (doc.Has("hammer_test")) CheckHammerTest(doc["hammer_test"], &cfg.implausible);

  ReadEffects(doc, &d);
  ReadParameters(doc, path, &cfg);
  // Parameter-uncertainty files (formats.md §12), relative to the config.
  if (doc.Has("uncertainty")) {
    const YamlDoc files = doc["uncertainty"];
    for (const std::string& f : files.Strings()) cfg.uncertainty_files.push_back(ResolveRelative(path, f));
  }
  doc.MarkUsed("uncertainty");
  doc.RejectUnknownKeys();
  for (int j = 0; j < d.arm.num_joints(); ++j) cfg.joint_value_locations.joint_stiffness.push_back(kq.at(j).location());
  cfg.joint_value_locations.damping = damping.location();
  return cfg;
}

std::string ParametersYaml(const dynamics::ParameterSet& p, const dynamics::ParameterSet& defaults,
                           bool all) {
  std::ostringstream s;
  s << "parameters:\n";
  for (const auto& spec : p.specs()) {
    const double v = p.Get(spec.name);
    if (!all && defaults.Has(spec.name) && defaults.Get(spec.name) == v) continue;
    s << "  " << spec.name << ": " << FormatNumber(v) << "   # [" << spec.unit << "] "
      << spec.description << "\n";
  }
  return s.str();
}

std::string CalibratedConfigText(const std::string& input_path, const std::string& output_path,
                                 const std::string& parameters_yaml, const std::vector<std::string>& effects,
                                 bool* effects_left_out, const std::string& comment) {
  std::ifstream in(input_path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::istringstream lines(ss.str());
  std::vector<std::string> out;
  std::string line;
  bool skipping = false;
  const std::regex urdf_re(R"(^(\s+urdf:\s*)([^#\s]+)(.*)$)");
  while (std::getline(lines, line)) {
    if (skipping) {
      if (line.empty() || line[0] == ' ' || line[0] == '\t' || line[0] == '#') continue;
      skipping = false;
    }
    if (line.rfind("parameters:", 0) == 0) {
      skipping = true;
      continue;
    }
    std::smatch m;
    if (std::regex_match(line, m, urdf_re)) {
      line = m[1].str() + RebaseRelative(input_path, m[2].str(), output_path) + m[3].str();
    }
    out.push_back(line);
  }
  if (effects_left_out) *effects_left_out = false;
  std::string added;  // a new effects: block, when the config has none
  if (!effects.empty()) {
    // The config's own top-level `effects:` list, if any: the new entries
    // go at its end, with the indentation of its items (block style), or
    // replace an empty flow list `effects: []`.
    int at = -1;
    for (size_t i = 0; i < out.size(); ++i) {
      if (out[i].rfind("effects:", 0) == 0) at = static_cast<int>(i);
    }
    if (at < 0) {
      added = "effects:\n";
      for (const std::string& e : effects) added += "  - name: " + e + "\n";
    } else {
      const std::string rest = std::regex_replace(out[at].substr(8), std::regex(R"(\s*(#.*)?$)"), "");
      if (rest.empty() || rest == "[]") {
        out[at] = "effects:";
        std::string indent = "  ";
        size_t last = static_cast<size_t>(at);
        const std::regex item_re(R"(^(\s*)- .*$)");
        for (size_t i = at + 1; i < out.size(); ++i) {
          const std::string& l = out[i];
          if (!l.empty() && l[0] != ' ' && l[0] != '\t' && l[0] != '#') break;
          std::smatch m;
          if (std::regex_match(l, m, item_re) && last == static_cast<size_t>(at)) indent = m[1].str();
          if (!l.empty() && l.find_first_not_of(" \t") != std::string::npos && l[l.find_first_not_of(" \t")] != '#') {
            last = i;
          }
        }
        // Effects the list already has (a config calibrated before) are not
        // listed twice.
        std::vector<std::string> listed;
        const std::regex name_re(R"(^\s*-?\s*name:\s*([A-Za-z0-9_]+).*$)");
        for (size_t i = at + 1; i <= last && i < out.size(); ++i) {
          std::smatch m;
          if (std::regex_match(out[i], m, name_re)) listed.push_back(m[1].str());
        }
        std::vector<std::string> items;
        for (const std::string& e : effects) {
          if (std::find(listed.begin(), listed.end(), e) == listed.end()) items.push_back(indent + "- name: " + e);
        }
        out.insert(out.begin() + static_cast<long>(last) + 1, items.begin(), items.end());
      } else if (effects_left_out) {
        *effects_left_out = true;  // a non-empty flow list: the user's layout, not edited
      }
    }
  }
  std::string text;
  for (const std::string& l : out) text += l + "\n";
  text += "\n# " + comment + "\n" + parameters_yaml + added;
  return text;
}

}  // namespace robomach::io
