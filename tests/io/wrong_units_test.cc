// Wrong units on purpose (issue #35 acceptance): for every reader that takes
// a dimensional quantity a user types, a valid shipped input with one
// quantity scaled as a user gets it wrong (x1000, /1000, deg <-> rad,
// N <-> kN, mm <-> m) must be flagged (a finding) or refused (InputError)
// with words naming the unit mistake; the unmodified input must give no
// finding, so a check that flags everything fails here too.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/compensation_file.h"
#include "robomach/io/counts_file.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/drilling_files.h"
#include "robomach/io/machine_file.h"
#include "robomach/io/polishing_files.h"
#include "robomach/io/region_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/temperature_log.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A reader under test: the findings it returns for a file (it may throw).
using Reader = std::function<std::vector<std::string>(const std::string& path)>;

struct NamedReader {
  const char* name;
  Reader read;
};

const std::vector<NamedReader>& Readers() {
  static const std::vector<NamedReader> readers = {
      {"robot_config",
       [](const std::string& p) {
         // The reader's findings, then the model's (joint frequencies, sag,
         // damping), as the tools read a config (workflows::LoadRobotConfigChecked).
         RobotConfig cfg = LoadRobotConfig(p);
         for (const std::string& f : dynamics::JointPlausibilityFindings(cfg.description, cfg.parameters,
                                                                         cfg.joint_value_locations)) {
           cfg.implausible.push_back(f);
         }
         return cfg.implausible;
       }},
      {"flexible_robot", [](const std::string& p) { return ReadFlexibleRobotFile(p).implausible; }},
      {"drill_file", [](const std::string& p) { return ReadDrillFile(p).implausible; }},
      {"cut_file", [](const std::string& p) { return ReadCutFile(p).implausible; }},
      {"polish_process",
       [](const std::string& p) {
         std::vector<std::string> w;
         ReadPolishingProcess(p, &w);
         return w;
       }},
      {"machine_file", [](const std::string& p) { return ReadMachineFile(p).implausible; }},
      {"compensation",
       [](const std::string& p) {
         return ReadCompensationFile(p, ReadMachineFile(SourcePath("config/machine/dmu80p.yaml"))).implausible;
       }},
      {"temperature_log",
       [](const std::string& p) {
         std::vector<std::string> w;
         ReadTemperatureLog(p, ReadMachineFile(SourcePath("config/machine/dmu80p.yaml")), &w);
         return w;
       }},
      {"region", [](const std::string& p) { return ReadRegionFile(p, 6).implausible; }},
      {"counts_file",
       [](const std::string& p) {
         std::vector<std::string> w;
         ReadCountsFile(p, ReadMachineFile(SourcePath("config/machine/dmu80p.yaml")), &w);
         return w;
       }},
  };
  return readers;
}

const Reader& FindReader(const std::string& name) {
  for (const auto& r : Readers()) {
    if (name == r.name) return r.read;
  }
  throw std::logic_error("no reader " + name);
}

enum class Expect { kFlagged, kRefused };

struct WrongUnitCase {
  const char* reader;
  const char* file;     // shipped or test input, relative to the source tree
  const char* key;      // `key` (a scalar or every number of a flow list), `key[i]` (element i of a
                        // flow list), or `key|key2|...` (each of them); `$NAME[...]` a controller
                        // assignment `$NAME[...]=value` (compensation tables); `csv:NAME` the
                        // column NAME of a CSV file (occurrence: its data row, -1 every row)
  int occurrence;       // which line with the key (0 = the first)
  double factor;        // the mistake: the value times this
  Expect expect;
  const char* words;    // regex the finding or the error must match
};

constexpr double kDegPerRad = 180.0 / kPi;
constexpr double kRadPerDeg = kPi / 180.0;

// One row per quantity and mistake.
const std::vector<WrongUnitCase>& Cases() {
  static const std::vector<WrongUnitCase> cases = {
      // robot config (config/kr210.yaml; DH table config/kr210_dh.yaml)
      {"robot_config", "config/kr210.yaml", "mass_kg", 0, 1000, Expect::kRefused, "the likely cause: .*mass_kg 22000 kg .*a mass in g typed in the kg field.* -- which makes this check fail: .*m6_kg must state"},
      {"robot_config", "config/kr210_dh.yaml", "mass_kg", 0, 1000, Expect::kFlagged, "mass_kg 363070 kg .*a mass in g typed in the kg field"},
      {"robot_config", "config/kr210.yaml", "com_m[2]", 0, 1000, Expect::kFlagged, "com_m\\[2\\] 110 m .*a length in mm typed in the m field"},
      {"robot_config", "config/kr210.yaml", "tcp_m[2]", 0, 1000, Expect::kRefused, "the likely cause: .*tcp_m\\[2\\] 335 m .*a length in mm typed in the m field.*which makes this check fail: the geometry puts the tool tip"},
      {"robot_config", "config/kr210.yaml", "joint_stiffness_Nm_per_rad[0]", 0, 1000, Expect::kFlagged, "joint_stiffness_Nm_per_rad\\[0\\] 3347900000 N·m/rad .*a stiffness in N·mm/rad"},
      {"robot_config", "config/kr210.yaml", "joint_stiffness_Nm_per_rad", 0, 1000, Expect::kFlagged, "joint 6 \\(joint_6\\).* 7\\d\\d\\d Hz.*a stiffness in N·mm/rad"},
      {"robot_config", "config/kr210.yaml", "joint_stiffness_Nm_per_rad", 0, 1e-3, Expect::kFlagged, "joint 2 \\(joint_2\\).* 0.328 Hz.*a stiffness in kN·m/rad"},
      // A stiffness typed per degree (N·m/deg, the value / 57.3): the joint
      // frequencies move by only 7.6 (the lowest to 1.3 Hz, in range); the
      // robot's own weight then turns joint 2 by about 5 deg (0.09 deg as shipped).
      {"robot_config", "config/kr210.yaml", "joint_stiffness_Nm_per_rad", 0, kRadPerDeg, Expect::kFlagged, "joint 2 \\(joint_2\\): the robot's own weight .* turns it by [4-6]\\.\\d+ deg .*a stiffness per degree typed in the N·m/rad field"},
      {"robot_config", "config/kr210_dh.yaml", "joint_stiffness_Nm_per_rad", 0, kRadPerDeg, Expect::kFlagged, "joint 2 \\(joint_2\\): the robot's own weight .* turns it by \\d+\\.\\d+ deg .*a stiffness per degree"},
      {"robot_config", "config/kr210.yaml", "alpha_s", 0, 1000, Expect::kFlagged, "alpha_s in ms"},
      {"robot_config", "config/kr210.yaml", "beta_per_s", 0, 1000, Expect::kRefused, "beta_per_s: expected a number in \\[0, 1000\\] /s"},
      {"robot_config", "config/kr210.yaml", "m6_kg", 0, 1000, Expect::kRefused, "1000 x 29.05: a value in g typed in the kg field"},
      {"robot_config", "config/kr210.yaml", "d6_m", 0, 1000, Expect::kRefused, "a value in mm typed in the m field"},
      {"robot_config", "config/kr210_dh.yaml", "a_prev_m", 1, 1000, Expect::kFlagged, "a_prev_m 330 m .*a length in mm typed in the m field"},
      {"robot_config", "config/kr210_dh.yaml", "d_m", 0, 1000, Expect::kFlagged, "d_m -645 m .*a length in mm typed in the m field"},
      // its spindle_toolholder_interface (the spindle_interface effect) and hammer_test sections
      {"robot_config", "config/kr210.yaml", "taper_large_diameter_m", 0, 1000, Expect::kFlagged, "kr210.yaml:\\d+:\\d+: spindle_toolholder_interface.taper_large_diameter_m 24.007 m .*a diameter in mm typed in the m field"},
      {"robot_config", "config/kr210.yaml", "taper_length_m", 0, 1000, Expect::kRefused, "the likely cause: .*taper_length_m 16 m .*a length in mm typed in the m field.*which makes this check fail: the taper's small diameter.*not > 0"},
      {"robot_config", "config/kr210.yaml", "drawbar_force_N", 0, 1e-3, Expect::kFlagged, "drawbar_force_N 5 N .*a force in kN typed in the N field"},
      {"robot_config", "config/kr210.yaml", "friction_coefficient", 0, 100, Expect::kFlagged, "friction_coefficient 15 .*a percentage typed"},
      {"robot_config", "config/kr210.yaml", "sample_rate_hz", 0, 1e-3, Expect::kFlagged, "hammer_test.sample_rate_hz 5.12 Hz .*a rate in kHz typed in the Hz field"},
      // drill-sim's flexible-joint robot (config/drilling/planar3r.yaml)
      {"flexible_robot", "config/drilling/planar3r.yaml", "mass_kg", 0, 1000, Expect::kFlagged, "mass_kg 6000 kg .*a mass in g typed in the kg field"},
      {"flexible_robot", "config/drilling/planar3r.yaml", "a_prev_m", 1, 1000, Expect::kFlagged, "a_prev_m 600 m .*a length in mm typed in the m field"},
      {"flexible_robot", "config/drilling/planar3r.yaml", "stiffness_Nm_per_rad", -1, 1e-3, Expect::kFlagged, "stiffness_Nm_per_rad 60 N·m/rad .*a stiffness in kN·m/rad"},
      {"flexible_robot", "config/drilling/planar3r.yaml", "rotor_inertia_kgm2", 0, 1e4, Expect::kFlagged, "rotor_inertia_kgm2 1.98 kg·m² .*kg·cm²"},
      {"flexible_robot", "config/drilling/planar3r.yaml", "alpha_prev_deg|base_rpy_deg|tip_rpy_deg", -1, kRadPerDeg, Expect::kFlagged, "radians typed in _deg fields"},
      // drill file (config/drilling/drill_5mm.yaml)
      {"drill_file", "config/drilling/drill_5mm.yaml", "point_angle_deg", 0, kRadPerDeg, Expect::kRefused, "point_angle_deg: expected an angle in \\(60, 180\\) deg, got 2.0594.*radians typed in a _deg field"},
      {"drill_file", "config/drilling/drill_5mm.yaml", "initial_posture_deg", 0, kRadPerDeg, Expect::kFlagged, "initial_posture_deg.*radians typed in _deg fields"},
      // cut file (config/cut_demo.yaml; checks of commit 648cfe0)
      {"cut_file", "config/cut_demo.yaml", "diameter_mm", 0, 1000, Expect::kFlagged, "diameter_mm 20000 mm .*a diameter in um"},
      {"cut_file", "config/cut_demo.yaml", "diameter_mm", 0, 1e-3, Expect::kFlagged, "diameter_mm 0.02 mm .*a diameter in m"},
      {"cut_file", "config/cut_demo.yaml", "ktc_N_per_mm2", 0, 1000, Expect::kFlagged, "ktc_N_per_mm2 .*N/m² \\(Pa\\) or kN/m²"},
      {"cut_file", "config/cut_demo.yaml", "ktc_N_per_mm2", 0, 1e-3, Expect::kFlagged, "ktc_N_per_mm2 .*kN/mm²"},
      // polishing process (config/polishing/belt_2N.yaml)
      {"polish_process", "config/polishing/belt_2N.yaml", "force_N", 0, 1e-3, Expect::kFlagged, "force_N 0.002 N .*a force in kN typed in the N field"},
      {"polish_process", "config/polishing/belt_2N.yaml", "force_N", 0, 1e4, Expect::kFlagged, "force_N 20000 N .*a force in mN"},
      {"polish_process", "config/polishing/belt_2N.yaml", "wheel_radius_mm", 0, 1e-3, Expect::kFlagged, "wheel_radius_mm 0.05 mm .*a length in m typed in the mm field"},
      {"polish_process", "config/polishing/belt_2N.yaml", "belt_width_mm", 0, 1000, Expect::kFlagged, "belt_width_mm 20000 mm .*a length in um"},
      {"polish_process", "config/polishing/belt_2N.yaml", "pad_modulus_MPa", 0, 1000, Expect::kFlagged, "pad_modulus_MPa 10000 MPa .*kPa or Pa"},
      {"polish_process", "config/polishing/belt_2N.yaml", "belt_speed_m_per_s", 0, 1000, Expect::kFlagged, "belt_speed_m_per_s 3000 m/s .*mm/s"},
      {"polish_process", "config/polishing/belt_2N.yaml", "modulus_GPa", 0, 1000, Expect::kFlagged, "modulus_GPa 200000 GPa .*MPa or Pa"},
      {"polish_process", "config/polishing/belt_2N.yaml", "preston_coefficient_m2_per_N", 0, 1e6, Expect::kFlagged, "preston_coefficient_m2_per_N .*mm²/N"},
      {"polish_process", "config/polishing/belt_2N.yaml", "max_speed_mm_per_s", 0, 1e-3, Expect::kFlagged, "max_speed_mm_per_s 0.05 mm/s .*m/s typed in the mm/s field"},
      {"robot_config", "config/kr210_dh.yaml", "alpha_prev_deg|theta_offset_deg|lower_deg|upper_deg|base_rpy_deg|tip_rpy_deg", -1, kRadPerDeg, Expect::kRefused, "radians typed in _deg fields"},
      // stability-map's region (config/region_demo.yaml: corner 2.1 m from the base; the
      // first origin_mm line is its comment)
      {"region", "config/region_demo.yaml", "origin_mm", 1, 1e-3, Expect::kFlagged, "region_demo.yaml:\\d+:\\d+: origin_mm at 2.1\\d* mm is outside the 50 to 20000 mm .*a position in m typed in the mm field"},
      {"region", "config/region_demo.yaml", "origin_mm", 1, 1000, Expect::kFlagged, "origin_mm at 2\\d{6} mm .*a position in um typed in the mm field"},
      {"region", "config/region_demo.yaml", "seed_posture_deg", 0, kRadPerDeg, Expect::kFlagged, "seed_posture_deg.*radians typed in _deg fields"},
      // five-axis machine file (config/machine/dmu80p.yaml)
      {"machine_file", "config/machine/dmu80p.yaml", "resolution_mm", -1, 1000, Expect::kFlagged, "resolution_mm 0.5 mm .*a resolution in um typed in the mm field"},
      {"machine_file", "config/machine/dmu80p.yaml", "resolution_mm", -1, 1e-3, Expect::kFlagged, "resolution_mm 5e-07 mm .*a resolution in m typed in the mm field"},
      {"machine_file", "config/machine/dmu80p.yaml", "resolution_deg", -1, 1000, Expect::kFlagged, "resolution_deg 0.1 deg .*arc-seconds or millidegrees"},
      {"machine_file", "config/machine/dmu80p.yaml", "resolution_deg", -1, 1e7, Expect::kRefused, "resolution_deg: expected a resolution of at most 360 deg .*arc-seconds"},
      {"machine_file", "config/machine/dmu80p.yaml", "nutation_deg", 0, kRadPerDeg, Expect::kFlagged, "nutation_deg 0.785398163397 deg .*45 deg; radians typed in a _deg field"},
      {"machine_file", "config/machine/dmu80p.yaml", "pivot_length_mm", 0, 1e-3, Expect::kFlagged, "pivot_length_mm 0.3 mm .*a length in m typed in the mm field"},
      {"machine_file", "config/machine/dmu80p.yaml", "pivot_length_mm", 0, 1000, Expect::kFlagged, "pivot_length_mm 300000 mm .*a length in um typed in the mm field"},
      {"machine_file", "config/machine/dmu80p.yaml", "tool_length_mm", 0, 1e-3, Expect::kFlagged, "tool_length_mm 0.12 mm .*a length in m typed in the mm field"},
      {"machine_file", "config/machine/dmu80p.yaml", "zero_offset_mm", 0, 1000, Expect::kFlagged, "zero_offset_mm\\[0\\] 350000 mm .*a length in um typed in the mm field"},
      {"machine_file", "config/machine/dmu80p.yaml", "c_centre_mm", 0, 1000, Expect::kFlagged, "c_centre_mm\\[0\\] 400000 mm .*a length in um"},
      {"machine_file", "config/machine/dmu80p.yaml", "zero_offset_mm", 0, 1e7, Expect::kRefused, "expected a length within \\+-1000000 mm \\(1 km\\).*um or nm typed in the mm field"},
      {"machine_file", "config/machine/dmu80p.yaml", "b_eccentricity_mm", 0, 1000, Expect::kFlagged, "b_eccentricity_mm\\[0\\] 4 mm .*an error in um typed in the mm field"},
      {"machine_file", "config/machine/dmu80p.yaml", "pivot_length_error_mm", 0, 1000, Expect::kFlagged, "pivot_length_error_mm 6 mm .*an error in um"},
      // Siemens compensation tables (config/machine/dmu80p_comp.mpf)
      {"compensation", "config/machine/dmu80p_comp.mpf", "$AA_ENC_COMP[0,6,AX1]", 0, 1000, Expect::kFlagged, "dmu80p_comp.mpf:\\d+: \\$AA_ENC_COMP table of axis X: value 2.827 mm .*values in um typed in the mm table"},
      {"compensation", "config/machine/dmu80p_comp.mpf", "$AA_ENC_COMP[0,6,AX1]", 0, 1e6, Expect::kRefused, "dmu80p_comp.mpf:\\d+: \\$AA_ENC_COMP table of axis X: value 2827 mm is beyond the 100 mm.*um or nm typed"},
      // temperature log (config/machine/dmu80p_temperature.csv; largest K0 0.0018 mm, tan_beta 1.5e-05, P0 -600 mm)
      {"temperature_log", "config/machine/dmu80p_temperature.csv", "csv:K0_mm", -1, 1000, Expect::kFlagged, "dmu80p_temperature.csv:5: column K0_mm: 1.8 mm is outside the \\+-1 mm .*an offset in um typed in the mm column"},
      {"temperature_log", "config/machine/dmu80p_temperature.csv", "csv:K0_mm", -1, 1e6, Expect::kRefused, "dmu80p_temperature.csv:3: column K0_mm: expected a thermal offset within \\+-100 mm, got 1000 mm: an offset in um or nm"},
      {"temperature_log", "config/machine/dmu80p_temperature.csv", "csv:tan_beta", -1, 1000, Expect::kFlagged, "dmu80p_temperature.csv:5: column tan_beta: 0.015 is outside the \\+-0.001 .*um/m \\(ppm\\), mm/m or percent"},
      {"temperature_log", "config/machine/dmu80p_temperature.csv", "csv:tan_beta", -1, 1e6, Expect::kRefused, "dmu80p_temperature.csv:3: column tan_beta: expected a thermal slope within \\+-0.1 .*got 12: a slope in um/m \\(ppm\\)"},
      {"temperature_log", "config/machine/dmu80p_temperature.csv", "csv:P0_mm", -1, 1000, Expect::kFlagged, "dmu80p_temperature.csv:4: column P0_mm: -600000 mm is outside the \\+-50000 mm .*a position in um typed in the mm column"},
      // encoder counts (tests/data/machine/counts_tiny.csv: 8 kHz, a step of 0.000125 s)
      {"counts_file", "tests/data/machine/counts_tiny.csv", "csv:t_s", -1, 1000, Expect::kFlagged, "counts_tiny.csv:3: column t_s: the rows are 0.125 s apart .*more than the 0.1 s .*a time in ms typed in the s column"},
  };
  return cases;
}

std::string ScaleNumber(const std::string& v, double factor) {
  std::ostringstream s;
  s.precision(12);
  s << std::stod(v) * factor;
  return s.str();
}

// A CSV file (formats.md: `#` comments, one header row) with the cells of
// `column` scaled: in data row c.occurrence, or every row for -1.
std::string ScaledCsv(const std::string& text, const WrongUnitCase& c, const std::string& column) {
  std::istringstream in(text);
  std::string line, out;
  int col = -1, row = 0, changed = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') {
      out += line + "\n";
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream cs(line);
    for (std::string cell; std::getline(cs, cell, ',');) cells.push_back(cell);
    if (col < 0) {
      for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i] == column) col = static_cast<int>(i);
      }
      if (col < 0) throw std::logic_error("no column " + column + " in the file");
    } else if ((c.occurrence < 0 || row++ == c.occurrence) && col < static_cast<int>(cells.size())) {
      cells[col] = ScaleNumber(cells[col], c.factor);
      ++changed;
    }
    for (size_t i = 0; i < cells.size(); ++i) out += (i ? "," : "") + cells[i];
    out += "\n";
  }
  if (changed == 0) throw std::logic_error("no row with column " + column + " in the file");
  return out;
}

// The file's text with the case's value scaled; -1 as occurrence scales
// every line with the key (all angles of a table typed in radians).
std::string Scaled(const std::string& text, const WrongUnitCase& c, const std::string& folder) {
  std::string key = c.key;
  int element = -1;
  std::smatch m;
  // Matched on the case's own string: `m` points into it, so `key` may be
  // reassigned (matching `key` and then assigning it left m[2] dangling).
  const std::string full_key = c.key;
  if (std::regex_match(full_key, m, std::regex(R"((\w+)\[(\d+)\])"))) {
    key = m[1];
    element = std::stoi(m[2]);
  }
  // A CSV column: the cells of that column in the data rows.
  if (key.rfind("csv:", 0) == 0) return ScaledCsv(text, c, key.substr(4));
  // The key at the start of a line, or inside a flow map ({a: 1, key: 2});
  // a controller assignment `$NAME[...]=value` taken literally.
  const bool assignment = c.key[0] == '$';
  if (assignment) {
    key = std::regex_replace(std::string(c.key), std::regex(R"([$\[\]\\.^*+?(){}|])"), "\\$&");
    element = -1;
  }
  const std::regex line_re(assignment ? "^(" + key + "\\s*=\\s*)([-+0-9.eE]+)(.*)$"
                                      : "^(.*?(?:^|[\\s{,-])(?:" + key + "):\\s*)(\\[[^\\]]*\\]|[-+0-9.eE]+)(.*)$");
  std::istringstream in(text);
  std::string line, out;
  int seen = 0, changed = 0;
  const auto scale = [&](const std::string& v) {
    std::ostringstream s;
    s.precision(12);
    s << std::stod(v) * c.factor;
    return s.str();
  };
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, line_re) && (c.occurrence < 0 || seen++ == c.occurrence)) {
      std::string value = m[2];
      if (value[0] == '[') {
        std::vector<std::string> items;
        std::stringstream list(value.substr(1, value.size() - 2));
        for (std::string item; std::getline(list, item, ',');) items.push_back(item);
        for (size_t i = 0; i < items.size(); ++i) {
          if (element < 0 || static_cast<int>(i) == element) items[i] = scale(items[i]);
        }
        value = "[";
        for (size_t i = 0; i < items.size(); ++i) value += (i ? ", " : "") + items[i];
        value += "]";
      } else {
        value = scale(value);
      }
      line = m[1].str() + value + m[3].str();
      ++changed;
    }
    // A relative file reference made absolute: the copy lives elsewhere.
    if (std::regex_match(line, m, std::regex(R"(^(\s*urdf:\s*)(\S+)(.*)$)"))) {
      line = m[1].str() + folder + "/" + m[2].str() + m[3].str();
    }
    out += line + "\n";
  }
  if (changed == 0) throw std::logic_error(std::string("no ") + c.key + " in the file");
  return out;
}

std::string CaseName(const WrongUnitCase& c) {
  std::ostringstream s;
  s << c.reader << " " << c.file << " " << c.key << "#" << c.occurrence << " x" << c.factor;
  return s.str();
}

// The shipped inputs give no finding: a check that flags them would make
// every row below pass for the wrong reason.
TEST(WrongUnits, ShippedInputsAreNotFlagged) {
  std::vector<std::pair<std::string, std::string>> done;
  for (const WrongUnitCase& c : Cases()) {
    const std::pair<std::string, std::string> k{c.reader, c.file};
    if (std::find(done.begin(), done.end(), k) != done.end()) continue;
    done.push_back(k);
    std::vector<std::string> findings;
    ASSERT_NO_THROW(findings = FindReader(c.reader)(SourcePath(c.file))) << c.reader << " " << c.file;
    std::string all;
    for (const auto& f : findings) all += "\n  " + f;
    EXPECT_TRUE(findings.empty()) << c.reader << " " << c.file << ":" << all;
  }
}

// Every case: flagged or refused with the words naming the mistake.
TEST(WrongUnits, EachMistakeIsNamed) {
  const std::string dir = TempDir("wrong_units");
  int n = 0;
  for (const WrongUnitCase& c : Cases()) {
    SCOPED_TRACE(CaseName(c));
    const std::string src = SourcePath(c.file);
    const std::string folder = std::filesystem::path(src).parent_path().string();
    const std::string path = dir + "/case" + std::to_string(n++) + "_" + std::filesystem::path(c.file).filename().string();
    WriteText(path, Scaled(ReadText(src), c, folder));
    std::vector<std::string> findings;
    std::string error;
    try {
      findings = FindReader(c.reader)(path);
    } catch (const InputError& e) {
      error = e.what();
    }
    if (c.expect == Expect::kRefused) {
      EXPECT_TRUE(std::regex_search(error, std::regex(c.words))) << "refusal: '" << error << "'";
      continue;
    }
    EXPECT_EQ(error, "");
    if (!error.empty()) continue;
    std::string all;
    for (const auto& f : findings) all += "\n  " + f;
    bool named = false;
    for (const auto& f : findings) named = named || std::regex_search(f, std::regex(c.words));
    EXPECT_TRUE(named) << "findings:" << all;
    for (const auto& f : findings) EXPECT_EQ(f.rfind("implausible (unit mistake?): ", 0), 0u) << f;
  }
}

}  // namespace
}  // namespace robomach::io
