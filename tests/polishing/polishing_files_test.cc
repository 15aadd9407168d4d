#include "robomach/io/polishing_files.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_support.h"

namespace robomach::io {
namespace {

using ::testing::HasSubstr;
using robomach::testing::CaptureError;
using robomach::testing::SourcePath;

TEST(PolishingFiles, ReadsTheDemoPatchAndProcess) {
  const polishing::NurbsSurface s = ReadNurbsYaml(SourcePath("config/polishing/blade.yaml"));
  EXPECT_EQ(s.degree_u(), 3);
  EXPECT_EQ(s.num_u(), 5);
  EXPECT_NEAR(s.control_point(4, 3).x(), 0.120, 1e-12);  // mm -> m
  EXPECT_DOUBLE_EQ(s.weight(0, 1), 1.1);
  const polishing::PolishingProcess p = ReadPolishingProcess(SourcePath("config/polishing/belt_2N.yaml"));
  EXPECT_DOUBLE_EQ(p.belt_width, 0.020);
  EXPECT_DOUBLE_EQ(p.force, 2.0);
  EXPECT_DOUBLE_EQ(p.belt_speed, 3.0);
  EXPECT_DOUBLE_EQ(p.pad_modulus, 10e6);
  EXPECT_DOUBLE_EQ(p.max_speed, 0.050);
  // robot.contact_frame_in_flange_mm_deg [0, 0, 250, 180, 0, 0] = the default.
  EXPECT_NEAR(p.p_FC.z(), 0.25, 1e-15);
  EXPECT_TRUE(p.R_FC.isApprox(polishing::PolishingProcess{}.R_FC, 1e-12));
}

TEST(PolishingFiles, BadPatchesGetFileLineColumn) {
  const std::string dir = SourcePath("tests/data/polishing/");
  EXPECT_THAT(CaptureError([&] { ReadNurbsYaml(dir + "knots_mismatch.yaml"); }),
              HasSubstr("knots_mismatch.yaml:4:12: nurbs.knots_u: expected 4 knots (n_u 2 + degree 1 + 1), got 5"));
  EXPECT_THAT(CaptureError([&] { ReadNurbsYaml(dir + "negative_weight.yaml"); }),
              HasSubstr("negative_weight.yaml:11:11: nurbs.weights"));
  EXPECT_THAT(CaptureError([&] { ReadNurbsYaml(dir + "negative_weight.yaml"); }),
              HasSubstr("weight of control point (2, 2): expected a number > 0, got -2"));
}

TEST(PolishingFiles, PathRoundTripsAndBadRowsAreLocated) {
  const std::string dir = robomach::testing::TempDir("polishing_files");
  std::vector<polishing::PathRow> rows(2);
  rows[0].t = 0.0;
  rows[0].p = Eigen::Vector3d(0.001, 0.002, 0.0003);
  rows[0].n = Eigen::Vector3d::UnitZ();
  rows[0].tx = Eigen::Vector3d::UnitX();
  rows[0].u = 0.25;
  rows[0].v = 0.5;
  rows[1] = rows[0];
  rows[1].t = 0.5;
  rows[1].p.x() = 0.011;
  WritePolishPath(dir + "/p.csv", rows, {{"pattern", "cycloid"}, {"offset_mm", "8"}});
  const PolishPathFile f = ReadPolishPath(dir + "/p.csv");
  ASSERT_EQ(f.rows.size(), 2u);
  EXPECT_EQ(f.metadata.at("pattern"), "cycloid");
  EXPECT_NEAR(f.rows[1].p.x(), 0.011, 1e-12);
  EXPECT_DOUBLE_EQ(f.rows[0].u, 0.25);
  EXPECT_TRUE(f.has_uv);
  robomach::testing::WriteText(dir + "/bad.csv",
                               "t_s,x_mm,y_mm,z_mm,nx,ny,nz,tx,ty,tz\n0,0,0,0,0,0,1,1,0,0\n0,1,0,0,0,0,1,1,0,0\n");
  EXPECT_THAT(CaptureError([&] { ReadPolishPath(dir + "/bad.csv"); }),
              HasSubstr("bad.csv:3: column t_s: expected t_s strictly increasing"));
  robomach::testing::WriteText(dir + "/bad2.csv",
                               "t_s,x_mm,y_mm,z_mm,nx,ny,nz,tx,ty,tz\n0,0,0,0,0,0,1,1,0,0\n1,1,0,0,0,0,1,0,0,1\n");
  EXPECT_THAT(CaptureError([&] { ReadPolishPath(dir + "/bad2.csv"); }),
              HasSubstr("bad2.csv:3: column tx: tool x (tx,ty,tz) must be normal to (nx,ny,nz)"));
}

// force_N (formats.md §6): written when the path sets it (a planned path
// with lifts), read back; 0 is a lifted row, a negative force an error.
TEST(PolishingFiles, ForceColumnRoundTripsWithLiftedRows) {
  const std::string dir = robomach::testing::TempDir("polishing_files_force");
  std::vector<polishing::PathRow> rows(3);
  for (int i = 0; i < 3; ++i) {
    rows[i].t = 0.1 * i;
    rows[i].p = Eigen::Vector3d(0.001 * i, 0.0, 0.0);
    rows[i].n = Eigen::Vector3d::UnitZ();
    rows[i].tx = Eigen::Vector3d::UnitX();
    rows[i].force = i == 1 ? 0.0 : 2.5;
  }
  WritePolishPath(dir + "/f.csv", rows, {});
  const PolishPathFile f = ReadPolishPath(dir + "/f.csv");
  ASSERT_EQ(f.rows.size(), 3u);
  EXPECT_EQ(f.rows[0].force, 2.5);
  EXPECT_EQ(f.rows[1].force, 0.0);
  robomach::testing::WriteText(dir + "/badf.csv",
                               "t_s,x_mm,y_mm,z_mm,nx,ny,nz,tx,ty,tz,force_N\n0,0,0,0,0,0,1,1,0,0,2\n1,1,0,0,0,0,1,1,0,0,-1\n");
  EXPECT_THAT(CaptureError([&] { ReadPolishPath(dir + "/badf.csv"); }),
              HasSubstr("badf.csv:3: column force_N: expected a force >= 0 (0: the tool is lifted), got -1"));
}

}  // namespace
}  // namespace robomach::io
