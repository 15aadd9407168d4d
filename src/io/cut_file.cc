#include "robomach/io/cut_file.h"

#include <cmath>

#include "robomach/common/units.h"
#include "robomach/io/number_format.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {

Eigen::VectorXd CutSpec::SpeedGrid() const {
  if (spindle_speed_rad_s) return Eigen::VectorXd::Constant(1, *spindle_speed_rad_s);
  return Eigen::VectorXd::LinSpaced(spindle_speed_count, spindle_speed_min_rad_s, spindle_speed_max_rad_s);
}

Eigen::VectorXd CutSpec::SpeedRange(int count) const {
  return Eigen::VectorXd::LinSpaced(count > 0 ? count : spindle_speed_count, spindle_speed_min_rad_s,
                                    spindle_speed_max_rad_s);
}

namespace {

Eigen::Vector3d UnitVector(const YamlDoc& node) {
  const std::vector<double> v = node.Numbers(3);
  const Eigen::Vector3d e(v[0], v[1], v[2]);
  if (!(e.norm() > 1e-9)) throw node.Error("expected a non-zero direction [x, y, z]");
  return e.normalized();
}

// A value outside its plausible range: a warning naming the likely mistake.
void CheckPlausible(const YamlDoc& node, double v, double lo, double hi, const std::string& unit,
                    const std::string& practice, const std::string& low_hint, const std::string& high_hint,
                    std::vector<std::string>* out) {
  if (v >= lo && v <= hi) return;
  // The value as typed; the limits in plain digits (100000, not 1e+05).
  out->push_back("implausible (unit mistake?): " + node.location().ToString() + ": " + node.key_path() + " " +
                 node.String() + " " + unit + " is outside the " + FormatNumber(lo, 7) + " to " + FormatNumber(hi, 7) +
                 " " + unit + " of " + practice + ": " + (v < lo ? low_hint : high_hint));
}

}  // namespace

CutSpec ReadCutFile(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path, kCutFileFormat);
  if (!doc.IsMap()) throw doc.Error("expected a map of cut parameters (see config/cut_demo.yaml)");
  CutSpec c;
  c.path = path;
  {
    const YamlDoc d = doc["diameter_mm"];
    const double mm = d.PositiveNumber();
    c.tool_diameter = MmToM(mm);
    CheckPlausible(d, mm, kMinPlausibleCutterDiameterMm, kMaxPlausibleCutterDiameterMm, "mm", "milling cutters",
                   "a diameter in m typed in the mm field?", "a diameter in um typed in the mm field?",
                   &c.implausible);
  }
  {
    const YamlDoc t = doc["teeth"];
    const int teeth = t.Int();
    if (teeth < 1) throw t.Error("expected a whole number of teeth >= 1, got " + t.String());
    if (teeth > 200) throw t.Error("expected at most 200 teeth, got " + t.String());
    c.process.teeth = teeth;
  }
  {
    const YamlDoc r = doc["radial_immersion"];
    const double v = r.Number();
    if (!(v > 0.0 && v <= 1.0)) {
      throw r.Error("expected the radial immersion a_e/D in (0, 1], got " + r.String() +
                    (v > 1.0 && v <= 100.0 ? " (a percentage? write it as a fraction)" : ""));
    }
    c.process.radial_immersion = v;
  }
  {
    const YamlDoc m = doc["milling"];
    const std::string s = m.String();
    if (s == "up") {
      c.process.direction = stability::MillingDirection::kUp;
    } else if (s == "down") {
      c.process.direction = stability::MillingDirection::kDown;
    } else {
      throw m.Error("expected up or down, got \"" + s + "\"");
    }
  }
  {
    const YamlDoc f = doc["feed_direction"];
    c.feed_direction_B = UnitVector(f);
    c.feed_line = f.location().line;
    c.feed_column = f.location().column;
  }
  {
    const YamlDoc f = doc["feed_per_tooth_mm"];
    const double mm = f.PositiveNumber();
    c.feed_per_tooth = MmToM(mm);
    CheckPlausible(f, mm, kMinPlausibleFeedPerToothMm, kMaxPlausibleFeedPerToothMm, "mm", "milling feeds per tooth",
                   "a feed in m typed in the mm field?", "a feed rate in mm/min (feed per tooth x teeth x rpm)?",
                   &c.implausible);
  }
  {
    const YamlDoc k = doc["cutting_coefficients"];
    if (!k.IsMap()) throw k.Error("expected a map with ktc_N_per_mm2, krc_N_per_mm2[, kac_N_per_mm2] or Ks_N_per_mm2, beta_deg");
    constexpr double kNPerMm2 = 1e6;  // N/mm² -> N/m²
    const bool has_t = k.Has("ktc_N_per_mm2"), has_s = k.Has("Ks_N_per_mm2");
    if (has_t == has_s) {
      // A coefficient mistyped (ktc_N_per_m2) is named with the key meant.
      for (const char* key : {"ktc_N_per_mm2", "krc_N_per_mm2", "kac_N_per_mm2", "Ks_N_per_mm2", "beta_deg"}) {
        k.MarkUsed(key);
      }
      k.RejectUnknownKeys();
      throw k.Error("give either ktc_N_per_mm2 and krc_N_per_mm2 (optional kac_N_per_mm2), or Ks_N_per_mm2 and beta_deg");
    }
    const std::string practice = "metal-cutting coefficients (300 to 4000 N/mm² for aluminium to nickel alloys)";
    const std::string low = "a value in kN/mm² (GPa)?";
    const std::string high = "a value in N/m² (Pa) or kN/m² typed in the N/mm² field?";
    const auto coefficient = [&](const char* key, bool positive) {
      const YamlDoc v = k[key];
      const double x = positive ? v.PositiveNumber() : v.Number();
      CheckPlausible(v, std::abs(x), positive ? kMinPlausibleCuttingCoefficientNPerMm2 : 0.0,
                     kMaxPlausibleCuttingCoefficientNPerMm2, "N/mm²", practice, low, high, &c.implausible);
      return x * kNPerMm2;
    };
    if (has_t) {
      c.process.coefficients.Kt = coefficient("ktc_N_per_mm2", true);
      c.process.coefficients.Kr = coefficient("krc_N_per_mm2", false);
      if (k.Has("kac_N_per_mm2")) c.process.coefficients.Ka = coefficient("kac_N_per_mm2", false);
    } else {
      const double Ks = coefficient("Ks_N_per_mm2", true);
      const double beta = DegToRad(k["beta_deg"].NumberInRange(0.0, 90.0, false, true));
      c.process.coefficients = stability::CuttingCoefficients::FromKsBeta(Ks, beta);
    }
    for (const char* key : {"ktc_N_per_mm2", "krc_N_per_mm2", "kac_N_per_mm2", "Ks_N_per_mm2", "beta_deg"}) {
      k.MarkUsed(key);
    }
    k.RejectUnknownKeys();
  }
  const YamlDoc lo = doc["spindle_speed_min_rpm"];
  const YamlDoc hi = doc["spindle_speed_max_rpm"];
  const double lo_rpm = lo.PositiveNumber(), hi_rpm = hi.PositiveNumber();
  if (!(hi_rpm > lo_rpm)) {
    throw hi.Error("expected a number > spindle_speed_min_rpm (" + lo.String() + "), got " + hi.String());
  }
  for (const auto& [node, rpm] : {std::pair{lo, lo_rpm}, std::pair{hi, hi_rpm}}) {
    CheckPlausible(node, rpm, kMinPlausibleSpindleSpeedRpm, kMaxPlausibleSpindleSpeedRpm, "rpm", "machining spindles",
                   "a speed in rev/s or krpm typed in the rpm field?", "a typo (an extra zero)?",
                   &c.implausible);
  }
  c.spindle_speed_min_rad_s = RpmToRadPerSec(lo_rpm);
  c.spindle_speed_max_rad_s = RpmToRadPerSec(hi_rpm);
  if (doc.Has("spindle_speed_count")) c.spindle_speed_count = doc["spindle_speed_count"].IntInRange(1, 100000);
  if (doc.Has("spindle_speed_rpm")) {
    const YamlDoc s = doc["spindle_speed_rpm"];
    const double rpm = s.PositiveNumber();
    if (rpm < lo_rpm || rpm > hi_rpm) {
      throw s.Error("expected a speed within [spindle_speed_min_rpm, spindle_speed_max_rpm], got " + s.String());
    }
    c.spindle_speed_rad_s = RpmToRadPerSec(rpm);
  }
  doc.MarkUsed("spindle_speed_count");
  doc.MarkUsed("spindle_speed_rpm");
  doc.RejectUnknownKeys();
  return c;
}

}  // namespace robomach::io
