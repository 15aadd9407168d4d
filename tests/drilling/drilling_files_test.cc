#include "robomach/io/drilling_files.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/drilling/drilling_sim.h"
#include "robomach/drilling/plausibility.h"
#include "robomach/io/atomic_file.h"
#include "drilling/drilling_test_models.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using ::testing::HasSubstr;
using robomach::testing::CaptureError;
using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;

TEST(DrillingFiles, ReadsTheShippedForceTable) {
  const ForceTableFile t = ReadForceTable(SourcePath("config/drilling/q235_hss.csv"));
  ASSERT_EQ(t.rows.size(), 7u);
  EXPECT_DOUBLE_EQ(t.rows[0].diameter, 5e-3);
  EXPECT_DOUBLE_EQ(t.rows[0].feed_per_rev, 0.08e-3);
  EXPECT_DOUBLE_EQ(t.rows[0].thrust, 676.0);
  EXPECT_DOUBLE_EQ(t.rows[0].torque, 1.010);
  EXPECT_DOUBLE_EQ(*t.speed_rpm[6], 795.8);
  EXPECT_THAT(t.source, HasSubstr("seed 003, Table 1"));
}

TEST(DrillingFiles, ForceTableErrorsNameFileLineAndColumn) {
  const std::string dir = TempDir("drilling_files_table");
  const std::string bad = WriteText(dir + "/bad.csv",
                                    "# source: test\ndiameter_mm,feed_mm_per_rev,thrust_N,torque_Nm\n"
                                    "5,0.08,676,1.01\n5,0.10,0,1.2\n");
  EXPECT_THAT(CaptureError([&] { ReadForceTable(bad); }),
              HasSubstr("bad.csv:4: column thrust_N: expected a positive number, got 0"));
  const std::string neg = WriteText(dir + "/neg.csv",
                                    "diameter_mm,feed_mm_per_rev,thrust_N,torque_Nm\n5,-0.1,676,1.01\n");
  EXPECT_THAT(CaptureError([&] { ReadForceTable(neg); }),
              HasSubstr("neg.csv:2: column feed_mm_per_rev: expected a positive number"));
  // --predict rows need no forces.
  const std::string rows = WriteText(dir + "/rows.csv", "diameter_mm,feed_mm_per_rev\n6,0.11\n");
  EXPECT_EQ(ReadForceTable(rows, false).rows.size(), 1u);
  EXPECT_THAT(CaptureError([&] { ReadForceTable(rows, true); }), HasSubstr("missing required column 'thrust_N'"));
}

// Unit plausibility (issue #22 item 1) on the shipped Q235/HSS table: its
// median T / (F D) is row 3's 1.39 / (902 x 0.005) = 0.3082 (by hand, the
// 7 ratios 0.299..0.314), inside 0.02..3; with the torque in N·mm (x1000)
// it is 308.2 and named. A feed in mm/min (x rpm) is rejected by the reader
// at its cell; a diameter in m is flagged with the cutting speed it implies.
TEST(DrillingFiles, UnitMistakesInForceTablesAndDrillFilesAreNamed) {
  ForceTableFile t = ReadForceTable(SourcePath("config/drilling/q235_hss.csv"));
  EXPECT_TRUE(drilling::ForceTableFindings(t.rows).empty());
  for (auto& r : t.rows) r.torque *= 1000.0;
  const auto f = drilling::ForceTableFindings(t.rows);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_THAT(f[0], HasSubstr("median torque / (thrust x diameter) of the table is 308.2"));
  EXPECT_THAT(f[0], HasSubstr("N·mm"));

  const std::string dir = TempDir("drilling_files_units");
  const std::string mm_min = WriteText(dir + "/mm_min.csv",
                                       "diameter_mm,feed_mm_per_rev,thrust_N,torque_Nm,speed_rpm\n"
                                       "5,0.08,676,1.010,1782.5\n5,152.79,794,1.200,1527.9\n");
  EXPECT_THAT(CaptureError([&] { ReadForceTable(mm_min); }),
              HasSubstr("mm_min.csv:3: column feed_mm_per_rev: expected 0.005 to 1 mm/rev (twist-drilling practice), "
                        "got 152.79: a feed in mm/min"));
  const std::string d_m = WriteText(dir + "/d_m.csv", "diameter_mm,feed_mm_per_rev,thrust_N,torque_Nm\n0.005,0.08,676,1\n");
  EXPECT_THAT(CaptureError([&] { ReadForceTable(d_m); }),
              HasSubstr("d_m.csv:2: column diameter_mm: expected 0.1 to 100 mm"));

  DrillFile d = ReadDrillFile(SourcePath("config/drilling/drill_5mm.yaml"));
  EXPECT_TRUE(drilling::ToolingFindings(d.drill, &d.process).empty());
  d.drill.diameter *= 1e-3;  // 0.005 mm: metres typed in the mm field
  const auto g = drilling::ToolingFindings(d.drill, &d.process);
  ASSERT_EQ(g.size(), 2u);
  EXPECT_THAT(g[0], HasSubstr("drill diameter_mm 0.005 mm is outside the 0.1 to 100 mm of twist drills: a diameter in m"));
  // pi x 0.005 mm x 1500 rpm = 0.02356 m/min.
  EXPECT_THAT(g[1], HasSubstr("the cutting speed pi D n = 0.02356 m/min"));
  d = ReadDrillFile(SourcePath("config/drilling/drill_5mm.yaml"));
  d.process.feed_per_rev *= 1500.0;  // mm/min
  ASSERT_EQ(drilling::ToolingFindings(d.drill, &d.process).size(), 1u);
  EXPECT_THAT(drilling::ToolingFindings(d.drill, &d.process)[0], HasSubstr("a feed in mm/min"));

  const drilling::DrillingMaterial q235 = ReadMaterialFile(SourcePath("config/drilling/q235.yaml"));
  EXPECT_TRUE(drilling::MaterialFindings(q235).empty());
  drilling::DrillingMaterial gpa = q235;
  gpa.shear_stress_torque = 600e9;
  ASSERT_EQ(drilling::MaterialFindings(gpa).size(), 1u);
  EXPECT_THAT(drilling::MaterialFindings(gpa)[0], HasSubstr("shear_stress_torque (K_TQ) = 6e+05 MPa"));
}

TEST(DrillingFiles, ReadsDrillFileAndRejectsUnknownKeys) {
  const DrillFile d = ReadDrillFile(SourcePath("config/drilling/drill_5mm.yaml"));
  EXPECT_DOUBLE_EQ(d.drill.diameter, 5e-3);
  EXPECT_NEAR(d.drill.point_angle, DegToRad(118.0), 1e-15);
  ASSERT_TRUE(d.has_process);
  EXPECT_NEAR(d.process.feed_speed(), 2.5e-3, 1e-15);
  EXPECT_EQ(d.process.initial_posture.size(), 3);
  const std::string dir = TempDir("drilling_files_drill");
  const std::string bad = WriteText(dir + "/drill.yaml",
                                    "drill:\n  diameter_mm: 5\n  lips: 2\n  point_angle_deg: 118\n"
                                    "  helix_angle_deg: 30\n  web_thickness_ratio: 0.18\n"
                                    "  chisel_edge_angle_deg: 125\n  lip_relief_angle_deg: 12\n  colour: red\n");
  EXPECT_THAT(CaptureError([&] { ReadDrillFile(bad); }), HasSubstr("drill.yaml:9:3"));
}

// The hole axis is read with its enum's parser (issue #36): an unknown name
// is refused at its place, naming the three.
TEST(DrillingFiles, RefusesAnUnknownHoleAxisNamingTheKnownOnes) {
  std::ifstream in(SourcePath("config/drilling/drill_5mm.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const size_t at = yaml.find("hole_axis: tip_z");
  ASSERT_NE(at, std::string::npos);
  yaml.replace(at, 16, "hole_axis: tip_w");
  const std::string bad = WriteText(TempDir("drilling_files_axis") + "/drill.yaml", yaml);
  const std::string what = CaptureError([&] { ReadDrillFile(bad); });
  EXPECT_THAT(what, HasSubstr("drill.yaml:19:"));
  EXPECT_THAT(what, HasSubstr(": process.hole_axis: hole axis 'tip_w': expected tip_x, tip_y or tip_z"));
}

const char* kRobotHead =
    "robot:\n"
    "  dh:\n"
    "    links:\n"
    "      - {joint: joint_1, alpha_prev_deg: 0, a_prev_m: 0, d_m: 0, mass_kg: 5, com_m: [0.3, 0, 0],"
    " inertia_kgm2: [0.001, 0.15, 0.15, 0, 0, 0]}\n"
    "      - {joint: joint_2, alpha_prev_deg: 0, a_prev_m: 0.6, d_m: 0, mass_kg: 3, com_m: [0.2, 0, 0],"
    " inertia_kgm2: [0.001, 0.04, 0.04, 0, 0, 0]}\n";

TEST(DrillingFiles, FlexibleJointErrorsNameFileAndLine) {
  const std::string dir = TempDir("drilling_files_robot");
  const std::string ok = WriteText(dir + "/ok.yaml", std::string(kRobotHead) +
      "flexible_joints:\n"
      "  - {joint: joint_2, stiffness_Nm_per_rad: 50000, damping_Nms_per_rad: 5, rotor_inertia_kgm2: 2e-4, gear_ratio: 100}\n"
      "  - {joint: joint_1, stiffness_Nm_per_rad: 60000, rotor_inertia_kgm2: 2e-4, gear_ratio: 120}\n");
  const FlexibleRobotFile f = ReadFlexibleRobotFile(ok);
  ASSERT_EQ(f.drives.size(), 2u);
  EXPECT_DOUBLE_EQ(f.drives[0].stiffness, 60000.0);   // chain order, not file order
  EXPECT_DOUBLE_EQ(f.drives[1].gear_ratio, 100.0);
  EXPECT_DOUBLE_EQ(f.drives[0].damping, 0.0);

  const std::string missing = WriteText(dir + "/missing.yaml", std::string(kRobotHead) +
      "flexible_joints:\n"
      "  - {joint: joint_1, stiffness_Nm_per_rad: 60000, rotor_inertia_kgm2: 2e-4, gear_ratio: 120}\n");
  EXPECT_THAT(CaptureError([&] { ReadFlexibleRobotFile(missing); }),
              HasSubstr("missing.yaml:7:3: flexible_joints: no entry for joint 'joint_2'"));
  const std::string unknown = WriteText(dir + "/unknown.yaml", std::string(kRobotHead) +
      "flexible_joints:\n"
      "  - {joint: joint_1, stiffness_Nm_per_rad: 60000, rotor_inertia_kgm2: 2e-4, gear_ratio: 120}\n"
      "  - {joint: joint_7, stiffness_Nm_per_rad: 60000, rotor_inertia_kgm2: 2e-4, gear_ratio: 120}\n");
  EXPECT_THAT(CaptureError([&] { ReadFlexibleRobotFile(unknown); }),
              HasSubstr("unknown.yaml:8:13: flexible_joints[1].joint: unknown joint 'joint_7'"));
  const std::string stiff = WriteText(dir + "/stiff.yaml", std::string(kRobotHead) +
      "flexible_joints:\n"
      "  - {joint: joint_1, stiffness_Nm_per_rad: 0, rotor_inertia_kgm2: 2e-4, gear_ratio: 120}\n"
      "  - {joint: joint_2, stiffness_Nm_per_rad: 60000, rotor_inertia_kgm2: 2e-4, gear_ratio: 120}\n");
  EXPECT_THAT(CaptureError([&] { ReadFlexibleRobotFile(stiff); }),
              HasSubstr("stiff.yaml:7:44: flexible_joints[0].stiffness_Nm_per_rad: expected a joint stiffness > 0, got 0"));
  const std::string gear = WriteText(dir + "/gear.yaml", std::string(kRobotHead) +
      "flexible_joints:\n"
      "  - {joint: joint_1, stiffness_Nm_per_rad: 1, rotor_inertia_kgm2: 2e-4, gear_ratio: -120}\n"
      "  - {joint: joint_2, stiffness_Nm_per_rad: 60000, rotor_inertia_kgm2: 2e-4, gear_ratio: 120}\n");
  EXPECT_THAT(CaptureError([&] { ReadFlexibleRobotFile(gear); }),
              HasSubstr("gear.yaml:7:"));
  EXPECT_THAT(CaptureError([&] { ReadFlexibleRobotFile(gear); }), HasSubstr("expected a gear ratio > 0"));
}

TEST(DrillingFiles, SixAxisUrdfDerivativeMatchesKdlDynamics) {
  // A URDF chain (six revolute joints plus fixed segments, inertias with
  // rotated principal axes, centres of mass off the joint axes):
  // Derivative()'s own dynamics against KDL's ChainDynParam, to rounding.
  const FlexibleRobotFile rf = ReadFlexibleRobotFile(SourcePath("tests/data/drilling/kr210_flexible.yaml"));
  drilling::FlexibleJointRobot robot(rf.chain, rf.drives);
  ASSERT_EQ(robot.num_joints(), 6);
  const double d = drilling::testing::DerivativeVsKdl(robot, 50, 11);
  EXPECT_LT(d, 1e-10);
  std::printf("Derivative vs KDL (KR210): %.2g relative\n", d);
}

TEST(DrillingFiles, MaterialFileRoundTrip) {
  drilling::ForceFitResult fit;
  fit.material.shear_stress_thrust = 929.4567e6;
  fit.material.shear_stress_torque = 600.123e6;
  fit.material.kienzle_exponent = 0.2411234;
  fit.status = drilling::FitStatus::kConverged;
  ForceTableFile table;
  table.path = "t.csv";
  table.rows = {{5e-3, 0.1e-3, 794, 1.2}};
  const std::string dir = TempDir("drilling_files_material");
  WriteFileAtomically(dir + "/m.yaml", MaterialYaml(fit, drilling::DrillGeometry{}, table));
  const drilling::DrillingMaterial m = ReadMaterialFile(dir + "/m.yaml");
  // Pa -> MPa -> Pa: the shortest round-trip text of the MPa value, then one
  // multiplication, so at most a few ulps (1e-15 relative) of difference.
  EXPECT_NEAR(m.shear_stress_thrust, fit.material.shear_stress_thrust, 1e-15 * 929.4567e6);
  EXPECT_NEAR(m.shear_stress_torque, fit.material.shear_stress_torque, 1e-15 * 600.123e6);
  EXPECT_EQ(m.kienzle_exponent, fit.material.kienzle_exponent);
  EXPECT_EQ(m.chisel, drilling::ChiselModel::kSeedScaling);
}

}  // namespace
}  // namespace robomach::io
