#include "robomach/io/tracker_file.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/io/kq_yaml.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using testing::CaptureError;
using testing::TempDir;
using testing::WriteText;
using ::testing::HasSubstr;

const std::string kForceHeader =
    "case_id,pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,x0_mm,y0_mm,z0_mm,x1_mm,y1_mm,z1_mm,"
    "fx_N,fy_N,fz_N\n";
const std::string kRopeHeader =
    "case_id,pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,x0_mm,y0_mm,z0_mm,x1_mm,y1_mm,z1_mm,"
    "mass_kg,ax_mm,ay_mm,az_mm,bx_mm,by_mm,bz_mm\n";

std::string File(const std::string& dir, const std::string& name, const std::string& text) {
  return WriteText(dir + "/" + name, text);
}

TEST(TrackerFile, ReadsForceFormWithMetadataAndUnits) {
  const std::string dir = TempDir("tracker_force");
  const std::string path = File(dir, "t.csv",
                                "# tracker: Leica AT960\n" + kForceHeader +
                                    "C1,P1,0,-90,90,0,45,0,1938.9,0,1521.1,1938.9,0.02,1520.6,0,0,-294.2\n");
  const TrackerFile f = ReadTrackerFile(path, 6);
  ASSERT_EQ(f.measurements.size(), 1u);
  const auto& m = f.measurements[0];
  EXPECT_FALSE(f.rope_form);
  EXPECT_EQ(f.metadata.at("tracker"), "Leica AT960");
  EXPECT_EQ(m.case_id, "C1");
  EXPECT_NEAR(m.q(1), DegToRad(-90.0), 1e-15);
  EXPECT_NEAR(m.p0.x(), 1.9389, 1e-15);  // mm -> m
  EXPECT_NEAR((m.p1 - m.p0).z(), -0.0005, 1e-12);
  EXPECT_NEAR(m.force->z(), -294.2, 1e-12);
  EXPECT_FALSE(m.p_load_tip.has_value());
  EXPECT_EQ(m.line, 3);
}

TEST(TrackerFile, ReadsRopeFormAndOptionalTipFramePoints) {
  const std::string dir = TempDir("tracker_rope");
  const std::string header = kRopeHeader.substr(0, kRopeHeader.size() - 1) +
                             ",lx_mm,ly_mm,lz_mm,tx_mm,ty_mm,tz_mm\n";
  const std::string path =
      File(dir, "t.csv", header +
                             "C1,P1,0,-90,90,0,45,0,0,0,0,0,0,-0.5,20,0,0,1000,300,0,600,150,0,100,0,120,50\n"
                             "C2,P1,0,-90,90,0,45,0,0,0,0,0,0,-0.5,20,0,0,1000,300,0,600,,,,,,\n");
  const TrackerFile f = ReadTrackerFile(path, 6);
  ASSERT_EQ(f.measurements.size(), 2u);
  EXPECT_TRUE(f.rope_form);
  const auto& m = f.measurements[0];
  EXPECT_DOUBLE_EQ(m.mass_kg, 20.0);
  EXPECT_NEAR((m.rope_B - m.rope_A).norm(), 0.5, 1e-15);  // 300, 0, -400 mm
  ASSERT_TRUE(m.p_load_tip.has_value());
  EXPECT_NEAR(m.p_load_tip->x(), 0.15, 1e-15);
  EXPECT_NEAR(m.p_target_tip->z(), 0.05, 1e-15);
  // Empty tip-frame cells mean the TCP.
  EXPECT_FALSE(f.measurements[1].p_load_tip.has_value());
  // The rope force: 20 kg · 9.80665 along (0.6, 0, −0.8).
  const auto c = identification::ToLoadCase(m);
  EXPECT_NEAR(c.force.x(), 20 * 9.80665 * 0.6, 1e-9);
  EXPECT_NEAR(c.force.z(), -20 * 9.80665 * 0.8, 1e-9);
}

// Numbers that fit another unit far better than the header's: a KR210
// load test (targets 1.5-2.5 m from the base, 20 kg on a rope, degrees)
// reads without a unit warning; the same file with the positions in m, the
// masses in g, or the angles in radians under the same headers gives one
// warning each, naming the column and the likely unit; a force in kN under
// _N likewise.
TEST(TrackerFile, UnitMistakesAreNamed) {
  const std::string dir = TempDir("tracker_units");
  auto rope_file = [&](const std::string& name, double pos_scale, double mass, bool radians) {
    std::string text = kRopeHeader;
    const double q[3][6] = {{0, -90, 90, 0, 45, 0}, {30.5, -60, 100, 10, 30, 20}, {-40, -110, 80, 5, 60, -30}};
    const double p0[3][3] = {{1938.9, 0, 1521.1}, {1500.2, 866.1, 1200.4}, {1700.7, -1400.3, 900.8}};
    for (int r = 0; r < 3; ++r) {
      std::ostringstream row;
      row.precision(10);
      row << "C" << r + 1 << ",P" << r + 1;
      for (double a : q[r]) row << "," << (radians ? DegToRad(a) : a);
      for (int k = 0; k < 3; ++k) row << "," << p0[r][k] * pos_scale;
      for (int k = 0; k < 3; ++k) row << "," << (p0[r][k] + (k == 2 ? -0.4 : 0.0)) * pos_scale;
      row << "," << mass << "," << 1000 * pos_scale << ",0,0," << 1300 * pos_scale << ",0," << -400 * pos_scale;
      text += row.str() + "\n";
    }
    return File(dir, name, text);
  };
  EXPECT_TRUE(ReadTrackerFile(rope_file("ok.csv", 1.0, 20.0, false), 6).unit_warnings.empty());
  auto one_warning = [&](const std::string& path, const std::string& what) {
    const TrackerFile f = ReadTrackerFile(path, 6);
    ASSERT_EQ(f.unit_warnings.size(), 1u) << path;
    EXPECT_THAT(f.unit_warnings[0], HasSubstr("implausible (unit mistake?)"));
    EXPECT_THAT(f.unit_warnings[0], HasSubstr(what));
  };
  one_warning(rope_file("metres.csv", 1e-3, 20.0, false), "look like metres under the _mm headers");
  one_warning(rope_file("grams.csv", 1.0, 20000.0, false), "grams under mass_kg");
  one_warning(rope_file("radians.csv", 1.0, 20.0, true), "these look like radians");
  const std::string kn = File(dir, "kn.csv", kForceHeader +
                                                 "C1,P1,0,-90,90,0,45,0,1938.9,0,1521.1,1938.9,0.02,1520.6,0,0,-0.294\n"
                                                 "C2,P1,0,-90,90,0,45,0,1938.9,0,1521.1,1938.9,0.02,1520.6,0.2,0,0\n");
  one_warning(kn, "kN under the _N headers");
  EXPECT_THAT(TrackerNoiseUnitFinding("--noise-mm", 10.0), HasSubstr("um typed in the mm option"));
  EXPECT_THAT(TrackerNoiseUnitFinding("--noise-mm", 1e-5), HasSubstr("m typed in the mm option"));
  EXPECT_EQ(TrackerNoiseUnitFinding("--noise-mm", 0.01), "");
  EXPECT_EQ(TrackerNoiseUnitFinding("--noise-mm", 0.0), "");
}

TEST(TrackerFile, WriteReadRoundTrip) {
  const std::string dir = TempDir("tracker_roundtrip");
  std::vector<identification::TrackerMeasurement> ms(2);
  for (int i = 0; i < 2; ++i) {
    auto& m = ms[i];
    m.case_id = "C" + std::to_string(i + 1);
    m.pose_id = "P1";
    m.q = Eigen::VectorXd::LinSpaced(6, -0.3 * (i + 1), 0.7);
    m.p0 = Eigen::Vector3d(1.234567891234, -0.5, 0.9);
    m.p1 = m.p0 + Eigen::Vector3d(1e-5, -2e-4, 3.3e-4);
    m.mass_kg = 10.0 * (i + 1);
    m.rope_A = Eigen::Vector3d(1.1, 0.2, 0.8);
    m.rope_B = Eigen::Vector3d(1.3, 0.5, 0.1);
    m.p_target_tip = Eigen::Vector3d(0.0, 0.12, 0.05);
  }
  const std::string path = dir + "/out.csv";
  WriteTrackerFile(path, ms, {{"generator", "test"}});
  const TrackerFile f = ReadTrackerFile(path, 6);
  ASSERT_EQ(f.measurements.size(), 2u);
  EXPECT_EQ(f.metadata.at("generator"), "test");
  for (int i = 0; i < 2; ++i) {
    const auto& a = ms[i];
    const auto& b = f.measurements[i];
    // Shortest round-trip decimals of mm and degrees: one unit conversion
    // each way, so ~2 ulp relative.
    EXPECT_LT((a.q - b.q).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((a.p1 - b.p1).norm(), 1e-15);
    EXPECT_LT((a.rope_B - b.rope_B).norm(), 1e-15);
    EXPECT_EQ(a.mass_kg, b.mass_kg);
    EXPECT_FALSE(b.p_load_tip.has_value());
    ASSERT_TRUE(b.p_target_tip.has_value());
    EXPECT_LT((*a.p_target_tip - *b.p_target_tip).norm(), 1e-15);
  }
}

TEST(TrackerFile, ErrorsNameFileLineAndColumn) {
  const std::string dir = TempDir("tracker_errors");
  const std::string row = "C1,P1,0,-90,90,0,45,0,0,0,0,0,0,-0.5,0,0,-98\n";
  // Non-numeric cell.
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "comma.csv",
                                     kForceHeader + row + "C2,P1,0,-90,90,0,45,0,0,0,0,0,0,-0.5,0,\"12,5\",-98\n"),
                                6);
              }),
              HasSubstr("comma.csv:3: column fy_N: expected a number, got \"12,5\" (decimal comma?)"));
  // A joint number past int's range (std::stoi threw std::out_of_range; found
  // by fuzz_tracker_csv, issue #22).
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "q_huge.csv", "q99999999999_deg," + kForceHeader + "0," + row), 6);
              }),
              HasSubstr("q_huge.csv:1:1: column q99999999999_deg: the robot has 6 joints, so there is no joint "
                        "99999999999"));
  // Duplicate case id.
  EXPECT_THAT(CaptureError([&] { ReadTrackerFile(File(dir, "dup.csv", kForceHeader + row + row), 6); }),
              HasSubstr("dup.csv:3: column case_id: case \"C1\" appears twice (first on line 2)"));
  // Both load forms in one file.
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "mixed.csv",
                                     kForceHeader.substr(0, kForceHeader.size() - 1) + ",mass_kg\n" +
                                         "C1,P1,0,-90,90,0,45,0,0,0,0,0,0,-0.5,0,0,-98,10\n"),
                                6);
              }),
              HasSubstr("mixed.csv:1:18: column mass_kg: the file mixes the two load forms"));
  // Zero rope vector.
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "rope.csv", kRopeHeader +
                                                          "C1,P1,0,-90,90,0,45,0,0,0,0,0,0,-0.5,10,5,5,5,5,5,5\n"),
                                6);
              }),
              HasSubstr("rope.csv:2: column bx_mm: rope points A (ax_mm..az_mm) and B (bx_mm..bz_mm) coincide"));
  // Wrong joint count: a q7 column for a 6-joint robot, and a missing q6.
  const std::string h7 =
      "case_id,pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,q7_deg,x0_mm,y0_mm,z0_mm,x1_mm,y1_mm,z1_mm,"
      "fx_N,fy_N,fz_N\n";
  EXPECT_THAT(CaptureError([&] { ReadTrackerFile(File(dir, "q7.csv", h7), 6); }),
              HasSubstr("q7.csv:1:9: column q7_deg: the robot has 6 joints, so there is no joint 7"));
  std::string h5 = kForceHeader;
  h5.replace(h5.find("q6_deg,"), 7, "");
  EXPECT_THAT(CaptureError([&] { ReadTrackerFile(File(dir, "q5.csv", h5), 6); }),
              HasSubstr("q5.csv:1: missing column q6_deg (or q6_rad): the robot has 6 joints"));
  // nan, negative mass, no load columns, partial tip-frame triple.
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "nan.csv", kForceHeader + "C1,P1,0,-90,90,0,45,0,0,0,nan,0,0,-0.5,0,0,-98\n"), 6);
              }),
              HasSubstr("nan.csv:2: column z0_mm: expected a number, got \"nan\""));
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "mass.csv", kRopeHeader +
                                                          "C1,P1,0,-90,90,0,45,0,0,0,0,0,0,-0.5,-10,0,0,0,5,5,5\n"),
                                6);
              }),
              HasSubstr("mass.csv:2: column mass_kg: expected a mass > 0 kg, got -10"));
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "noload.csv",
                                     "case_id,pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,x0_mm,y0_mm,"
                                     "z0_mm,x1_mm,y1_mm,z1_mm\n"),
                                6);
              }),
              HasSubstr("noload.csv:1: no load columns"));
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "partial.csv",
                                     kForceHeader.substr(0, kForceHeader.size() - 1) + ",lx_mm,ly_mm\n"),
                                6);
              }),
              HasSubstr("partial.csv:1:18: column lx_mm: the load point needs all of lx_mm, ly_mm, lz_mm"));
  EXPECT_THAT(CaptureError([&] {
                ReadTrackerFile(File(dir, "zero.csv", kForceHeader + "C1,P1,0,-90,90,0,45,0,0,0,0,0,0,-0.5,0,0,0\n"), 6);
              }),
              HasSubstr("zero.csv:2: column fx_N: the force is zero"));
  EXPECT_THAT(CaptureError([&] { ReadTrackerFile(File(dir, "empty.csv", kForceHeader), 6); }),
              HasSubstr("empty.csv: no load cases"));
}

// kq.yaml pasted into a robot config reads back the identified values:
// LoadRobotConfig on a copy of config/kr210.yaml with the merged entry.
TEST(KqYaml, MergedConfigLoadsWithIdentifiedStiffness) {
  const std::string dir = TempDir("kq_merge");
  Eigen::VectorXd kq(6);
  kq << 3.1e6, 3.0e6, 4.4e6, 2.5e5, 6.0e5, 1.9e5;
  const std::string out = dir + "/merged.yaml";
  WriteText(out, MergeJointStiffness(testing::SourcePath("config/kr210.yaml"), kq, out, {"merged"}));
  const RobotConfig cfg = LoadRobotConfig(out);
  // Five significant digits are written: 5e-6 relative.
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(cfg.Build()->joint_stiffness()(j), kq(j), 5e-6 * kq(j));
  }
}

// The `parameters:` form of kq.yaml appended to a robot config overrides
// its stiffness: LoadRobotConfig reads the pasted block back (5 significant
// digits written: 5e-6 relative).
TEST(KqYaml, PastedParametersBlockOverridesConfigStiffness) {
  const std::string dir = TempDir("kq_paste");
  identification::JointStiffnessResult r;
  r.status = identification::FitStatus::kConverged;
  r.num_joints = 6;
  r.joint_stiffness.resize(6);
  r.joint_stiffness << 3.2e6, 3.05e6, 4.1e6, 2.6e5, 6.1e5, 1.95e5;
  r.std_dev = r.lower_95 = r.upper_95 = r.relative_std = r.joint_stiffness;
  r.correlation = Eigen::MatrixXd::Identity(6, 6);
  r.determination.assign(6, identification::Determination::kDetermined);
  KqYamlOptions o;
  o.as_parameters = true;
  const std::string out = dir + "/robot.yaml";
  // A copy of the config that stays valid in `dir` (urdf path rewritten),
  // with the kq.yaml text pasted at the end.
  const std::string base = MergeJointStiffness(testing::SourcePath("config/kr210.yaml"),
                                               LoadRobotConfig(testing::SourcePath("config/kr210.yaml"))
                                                   .description.joint_stiffness,
                                               out);
  WriteText(out, base + "\n" + JointStiffnessYaml(r, o));
  const auto model = LoadRobotConfig(out).Build();
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(model->joint_stiffness()(j), r.joint_stiffness(j), 5e-6 * r.joint_stiffness(j));
  }
}

TEST(KqYaml, YamlHasPasteableEntriesAndMarksUndeterminedJoints) {
  identification::JointStiffnessResult r;
  r.status = identification::FitStatus::kConverged;
  r.num_joints = 6;
  r.joint_stiffness = Eigen::VectorXd::LinSpaced(6, 1e5, 6e5);
  r.std_dev = r.lower_95 = r.upper_95 = r.relative_std = r.joint_stiffness;
  r.correlation = Eigen::MatrixXd::Identity(6, 6);
  r.determination.assign(6, identification::Determination::kDetermined);
  r.determination[5] = identification::Determination::kNotDetermined;
  r.not_determined = {5};
  KqYamlOptions o;
  o.as_parameters = true;
  const std::string y = JointStiffnessYaml(r, o);
  EXPECT_THAT(y, HasSubstr("parameters:\n  kq1_Nm_per_rad: 1.00000e+05\n"));
  EXPECT_THAT(y, HasSubstr("kq6_Nm_per_rad: 6.00000e+05   # NOT DETERMINED"));
  o.as_parameters = false;
  EXPECT_THAT(JointStiffnessYaml(r, o),
              HasSubstr("joint_stiffness_Nm_per_rad: [1.00000e+05, 2.00000e+05, 3.00000e+05, 4.00000e+05, "
                        "5.00000e+05, 6.00000e+05]   # NOT DETERMINED (prior kept): joint 6\n"));
}

}  // namespace
}  // namespace robomach::io
