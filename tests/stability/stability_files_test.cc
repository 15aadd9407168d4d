// Readers of the stability inputs: cut_*.yaml, region_*.yaml, tool-path
// CSV, FRF CSV (formats.md §3) and modal tables (§4).
#include <cmath>
#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/region_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/stability_map_file.h"
#include "robomach/io/tip_dynamics_files.h"
#include "robomach/workflows/tip_sources.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using ::testing::HasSubstr;
using robomach::testing::CaptureError;
using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;
using workflows::CutFrame;
using workflows::TipsFromModalTableFile;
using workflows::TipsFromRobotPostures;

constexpr char kCut[] =
    "diameter_mm: 20\n"
    "teeth: 4\n"
    "radial_immersion: 0.5\n"
    "milling: down\n"
    "feed_direction: [0, 1, 0]\n"
    "feed_per_tooth_mm: 0.08\n"
    "cutting_coefficients:\n"
    "  ktc_N_per_mm2: 1800\n"
    "  krc_N_per_mm2: 650\n"
    "spindle_speed_min_rpm: 6000\n"
    "spindle_speed_max_rpm: 24000\n";

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  s.replace(s.find(from), from.size(), to);
  return s;
}

TEST(CutFile, ReadsDemoInSiUnits) {
  const CutSpec c = ReadCutFile(SourcePath("config/cut_demo.yaml"));
  EXPECT_EQ(c.process.teeth, 4);
  EXPECT_DOUBLE_EQ(c.tool_diameter, 0.020);
  EXPECT_DOUBLE_EQ(c.process.coefficients.Kt, 1800e6);  // N/mm² -> N/m²
  EXPECT_DOUBLE_EQ(c.spindle_speed_max_rad_s, RpmToRadPerSec(24000.0));
  EXPECT_EQ(c.process.direction, stability::MillingDirection::kDown);
  EXPECT_EQ(c.SpeedGrid().size(), 200);
}

TEST(CutFile, KsBetaForm) {
  const std::string dir = TempDir("cut_ks");
  const std::string text = Replace(kCut, "  ktc_N_per_mm2: 1800\n  krc_N_per_mm2: 650\n",
                                   "  Ks_N_per_mm2: 2000\n  beta_deg: 70\n");
  const CutSpec c = ReadCutFile(WriteText(dir + "/cut.yaml", text));
  EXPECT_NEAR(c.process.coefficients.Kt, 2000e6 * std::sin(DegToRad(70.0)), 1e-3);
}

TEST(CutFile, ZeroTeethIsLocatedError) {
  const std::string dir = TempDir("cut_teeth");
  const std::string p = WriteText(dir + "/cut_bad.yaml", Replace(kCut, "teeth: 4", "teeth: 0"));
  EXPECT_THAT(CaptureError([&] { ReadCutFile(p); }), HasSubstr("cut_bad.yaml:2:8: teeth: expected a whole number of teeth >= 1, got 0"));
}

TEST(CutFile, ImmersionOutsideRangeIsLocatedError) {
  const std::string dir = TempDir("cut_imm");
  for (const std::string v : {"0", "1.5", "-0.2", "50"}) {
    const std::string p = WriteText(dir + "/cut_bad.yaml", Replace(kCut, "radial_immersion: 0.5", "radial_immersion: " + v));
    const std::string e = CaptureError([&] { ReadCutFile(p); });
    EXPECT_THAT(e, HasSubstr("cut_bad.yaml:3:19: radial_immersion: expected the radial immersion a_e/D in (0, 1], got " + v)) << e;
  }
  const std::string p = WriteText(dir + "/cut_pct.yaml", Replace(kCut, "radial_immersion: 0.5", "radial_immersion: 50"));
  EXPECT_THAT(CaptureError([&] { ReadCutFile(p); }), HasSubstr("percentage"));
}

TEST(CutFile, OtherErrors) {
  const std::string dir = TempDir("cut_other");
  auto err = [&](const std::string& text) { return CaptureError([&] { ReadCutFile(WriteText(dir + "/c.yaml", text)); }); };
  EXPECT_THAT(err(Replace(kCut, "milling: down", "milling: climb")), HasSubstr("c.yaml:4:10: milling: expected up or down"));
  EXPECT_THAT(err(Replace(kCut, "spindle_speed_max_rpm: 24000", "spindle_speed_max_rpm: 600")),
              HasSubstr("c.yaml:11:24: spindle_speed_max_rpm: expected a number > spindle_speed_min_rpm (6000), got 600"));
  EXPECT_THAT(err(kCut + std::string("spindel: 3\n")), HasSubstr("c.yaml:12:1: unknown key 'spindel'"));
  EXPECT_THAT(err(Replace(kCut, "  krc_N_per_mm2: 650\n", "  krc_N_per_mm2: 650\n  Ks_N_per_mm2: 3\n")),
              HasSubstr("give either"));
}

TEST(RegionFile, ReadsDemoAndBuildsTheGrid) {
  const RegionSpec r = ReadRegionFile(SourcePath("config/region_demo.yaml"), 6);
  EXPECT_GT(r.num_u(), 1);
  EXPECT_GT(r.num_v(), 1);
  const auto targets = r.Targets(Eigen::Vector3d::UnitY());
  ASSERT_EQ(static_cast<int>(targets.size()), r.num_u() * r.num_v());
  // Row-major: the second target is one step along u from the origin.
  EXPECT_NEAR((targets[1].p_BT - r.origin_B - r.grid_step * r.u_B).norm(), 0.0, 1e-15);
  // The tool points into the plane (along −n) without lead or tilt.
  EXPECT_NEAR(r.ToolDirection().dot(r.u_B.cross(r.v_B)), r.lead == 0.0 && r.tilt == 0.0 ? -1.0 : r.ToolDirection().dot(r.u_B.cross(r.v_B)), 1e-12);
}

TEST(RegionFile, SeedWithWrongJointCountIsLocatedError) {
  const std::string dir = TempDir("region_bad");
  const std::string p = WriteText(dir + "/region_bad.yaml",
                                  "origin_mm: [1800, -300, 800]\nu_axis: [1, 0, 0]\nv_axis: [0, 1, 0]\n"
                                  "size_mm: [400, 600]\ngrid_step_mm: 50\nseed_posture_deg: [0, -90, 90]\n");
  EXPECT_THAT(CaptureError([&] { ReadRegionFile(p, 6); }),
              HasSubstr("region_bad.yaml:6:19: seed_posture_deg: expected a list of 6 numbers, got 3"));
}

TEST(ToolPathFile, ReadsPosesAndRejectsZeroAxis) {
  const std::string dir = TempDir("path");
  const std::string ok = WriteText(dir + "/path.csv",
                                   "point_id,x_mm,y_mm,z_mm,tool_i,tool_j,tool_k\nA,2000,0,800,0,0,1\nB,2000,50,800,0,0,2\n");
  const auto pts = ReadToolPathFile(ok, Eigen::Vector3d::UnitX());
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_NEAR((pts[1].target.p_BT - Eigen::Vector3d(2.0, 0.05, 0.8)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((pts[1].target.z_T - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-15);  // tip direction
  const std::string bad = WriteText(dir + "/path_bad.csv",
                                    "x_mm,y_mm,z_mm,tool_i,tool_j,tool_k\n2000,0,800,0,0,1\n2000,0,800,0,0,0\n");
  EXPECT_THAT(CaptureError([&] { ReadToolPathFile(bad, Eigen::Vector3d::UnitX()); }),
              HasSubstr("path_bad.csv:3: column tool_i: expected a non-zero tool axis"));
}

// Round trip: frf-predict's writer (formats.md §3) and this reader.
TEST(FrfCsv, RoundTripWithPredictionWriter) {
  const std::string dir = TempDir("frf_rt");
  PosturePrediction pred;
  pred.pose_id = "P1";
  pred.freq_hz = Eigen::VectorXd::LinSpaced(5, 10.0, 50.0);
  for (int i = 0; i < 5; ++i) {
    Eigen::Matrix3cd H;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) H(a, b) = {1e-7 * (a + 1) / (i + 1), -2e-8 * (b + 1)};
    pred.H.push_back(H);
  }
  WritePredictedFrfCsv(dir + "/p.csv", {pred}, ParseDirectionPairs("xx,yy,xy,yx"));
  const auto sets = ReadTipFrfs(dir + "/p.csv");
  ASSERT_EQ(sets.size(), 1u);
  EXPECT_TRUE(sets[0].present[0][1]);
  EXPECT_FALSE(sets[0].present[2][2]);
  for (int i = 0; i < 5; ++i) {
    // FormatDouble writes the shortest round-trip text: exact.
    EXPECT_EQ(sets[0].H[i](0, 1), pred.H[i](0, 1));
    EXPECT_EQ(sets[0].H[i](1, 1), pred.H[i](1, 1));
  }
}

TEST(FrfCsv, AccelerancesAreConvertedAndGridsChecked) {
  const std::string dir = TempDir("frf_acc");
  const auto sets = ReadTipFrfs(WriteText(dir + "/a.csv",
                                         "# quantity: accelerance\npose_id,response,excitation,freq_hz,re,im\n"
                                         "P1,x,x,10,1,0\nP1,x,x,20,1,0\n"));
  const double w = HzToRadPerSec(10.0);
  EXPECT_NEAR(sets[0].H[0](0, 0).real(), -1.0 / (w * w), 1e-18);  // A = −ω² H
  const std::string bad = WriteText(dir + "/b.csv",
                                    "pose_id,response,excitation,freq_hz,re,im\nP1,x,x,10,1,0\nP1,x,x,20,1,0\n"
                                    "P1,y,y,10,1,0\nP1,y,y,25,1,0\n");
  EXPECT_THAT(CaptureError([&] { ReadTipFrfs(bad); }), HasSubstr("b.csv: FRF pose P1, response y, excitation y uses another frequency grid than FRF pose P1, response x, excitation x"));
}

TEST(ModalTable, StiffnessFormGivesTheSameModes) {
  const std::string dir = TempDir("modal");
  const double f = 922.0, m = 0.03993, k = m * std::pow(HzToRadPerSec(f), 2);
  const auto a = ReadModalTable(WriteText(dir + "/m.csv",
      "pose_id,mode,freq_hz,damping_ratio,modal_mass_kg,ux,uy,uz\nT,1,922,0.011,0.03993,1,0,0\n"));
  const auto b = ReadModalTable(WriteText(dir + "/k.csv",
      "pose_id,mode,freq_hz,damping_ratio,modal_stiffness_N_per_m,ux,uy,uz\nT,1,922,0.011," +
          std::to_string(k) + ",2,0,0\n"));
  // std::to_string keeps 6 decimals of k ≈ 1.3e6: ~1e-12 relative.
  EXPECT_NEAR(a[0].modes.p(0, 0), 1.0 / std::sqrt(m), 1e-12);
  EXPECT_NEAR(b[0].modes.p(0, 0), a[0].modes.p(0, 0), 1e-9 * a[0].modes.p(0, 0));
}

// stability-lobes' sources of tool tips (io/tip_sources.h). The modal
// table's 1-DOF benchmark lies along x_B, in the cutting plane of a tool
// along z_B: the tip keeps its frequency and |p|^2 = 1/m of the file.
TEST(TipSources, ModalTableTipKeepsTheFilesModeAndUnknownPosturesAreNamed) {
  const std::string cut_path = WriteText(TempDir("tip_sources") + "/cut.yaml", kCut);
  const CutSpec cut = ReadCutFile(cut_path);
  const std::string table = SourcePath("tests/data/stability/modal_benchmark.csv");
  const Eigen::Matrix3d R = CutFrame(cut, Eigen::Vector3d::UnitZ(), "tool_axis 0,0,1");
  const auto tips = TipsFromModalTableFile(table, {}, R, cut);
  ASSERT_EQ(tips.size(), 1u);
  EXPECT_EQ(tips[0].id, "IS2004");
  ASSERT_EQ(tips[0].modes_C.num_modes(), 1);
  EXPECT_NEAR(tips[0].modes_C.omega_rad_s(0), HzToRadPerSec(922.0), 1e-9);
  EXPECT_NEAR(tips[0].modes_C.p.col(0).squaredNorm(), 1.0 / 0.03993, 1e-9 / 0.03993);
  const std::string none = CaptureError([&] { TipsFromModalTableFile(table, {"P7"}, R, cut); });
  EXPECT_THAT(none, HasSubstr("modal_benchmark.csv"));
  EXPECT_THAT(none, HasSubstr("none of the requested postures"));
  // A tool axis along the feed has no cutting plane: the cut file's
  // feed_direction is named, with how the axis was given.
  const std::string along = CaptureError([&] { CutFrame(cut, Eigen::Vector3d::UnitY(), "--tool-axis 0,1,0"); });
  EXPECT_THAT(along, HasSubstr(cut_path + ":5:"));
  EXPECT_THAT(along, HasSubstr("feed_direction"));
  EXPECT_THAT(along, HasSubstr("(--tool-axis 0,1,0)"));
}

// The robot source: the postures asked for, in the order asked; an unknown
// one names the file and lists the known ones; a posture at the wrist
// singularity (q5 = 0) is told as a warning with its line.
TEST(TipSources, RobotPosturesInTheOrderAskedAndSingularOnesTold) {
  const std::string dir = TempDir("tip_sources_robot");
  const std::string cut_path = WriteText(dir + "/cut.yaml", kCut);
  const CutSpec cut = ReadCutFile(cut_path);
  const std::string postures = WriteText(dir + "/postures.csv",
                                         "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n"
                                         "A,0,-90,90,0,45,0\n"
                                         "B,30,-60,100,10,60,0\n"
                                         "W,0,-90,90,0,0,0\n");
  const auto model = LoadRobotConfig(SourcePath("config/kr210.yaml")).Build();
  std::vector<std::string> warnings;
  auto tell = [&](const Message& m) {
    if (m.kind == Message::Kind::kWarning) warnings.push_back(m.text);
  };
  const auto two = TipsFromRobotPostures(model, postures, {"B", "A"}, cut, tell);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].id, "B");
  EXPECT_EQ(two[1].id, "A");
  EXPECT_TRUE(warnings.empty());
  const auto all = TipsFromRobotPostures(model, postures, {}, cut, tell);
  ASSERT_EQ(all.size(), 3u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr(postures + ":4: posture W is near a singularity"));
  const std::string unknown = CaptureError([&] { TipsFromRobotPostures(model, postures, {"C"}, cut); });
  EXPECT_THAT(unknown, HasSubstr("no posture \"C\" in the file; it has A, B, W"));
}

// Issue #35: an unreachable point's row showed the inverse kinematics' last
// iterate as its joint angles and that iterate's cond(J); it has no
// posture, so both are empty. A point outside the joint limits keeps the
// posture the IK reached (which joint is out is worth seeing).
TEST(StabilityMapCsv, UnreachablePointsHaveNoPosture) {
  MapPoints pts;
  pts.grid = true;
  pts.rows = 1;
  pts.cols = 2;
  pts.grid_step = 0.01;
  pts.targets.resize(2);
  std::vector<stability::MapPoint> results(2);
  for (auto& r : results) {
    r.q = Eigen::VectorXd::Constant(6, 0.5);
    r.jacobian_condition = 12.5;
  }
  results[0].status = stability::PointStatus::kUnreachable;
  results[1].status = stability::PointStatus::kJointLimits;
  const std::string path = TempDir("map_csv") + "/map.csv";
  WriteStabilityMapCsv(path, pts, results, 6);
  std::ifstream in(path);
  std::string header, unreachable, limits;
  std::getline(in, header);
  std::getline(in, unreachable);
  std::getline(in, limits);
  const auto cells = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) out.push_back(c);
    if (!line.empty() && line.back() == ',') out.push_back("");
    return out;
  };
  const std::vector<std::string> h = cells(header), a = cells(unreachable), b = cells(limits);
  ASSERT_EQ(a.size(), h.size());
  ASSERT_EQ(b.size(), h.size());
  for (size_t i = 0; i < h.size(); ++i) {
    if (h[i].rfind('q', 0) == 0 && h[i].find("_deg") != std::string::npos) {
      EXPECT_EQ(a[i], "") << h[i];
      EXPECT_NEAR(std::stod(b[i]), RadToDeg(0.5), 1e-9) << h[i];
    }
    if (h[i] == "jacobian_condition") {
      EXPECT_EQ(a[i], "");
      EXPECT_EQ(b[i], "12.5");
    }
    if (h[i] == "status") {
      EXPECT_EQ(a[i], "unreachable");
      EXPECT_EQ(b[i], "joint_limits");
    }
  }
}

}  // namespace
}  // namespace robomach::io
