// io is formats only (issue #36): the figures io's writers used to compute
// are the workflows' (path figures and edge overrun of polish-plan and
// polish-sim, axis-acquire's contour figures) and the model's (a robot
// config's joint plausibility); the writers write what they are given.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "robomach/common/units.h"
#include "robomach/dynamics/joint_plausibility.h"
#include "robomach/io/acquired_path_file.h"
#include "robomach/io/polishing_summary.h"
#include "robomach/io/robot_config.h"
#include "robomach/workflows/acquisition_inputs.h"
#include "robomach/workflows/polish_simulation.h"
#include "robomach/workflows/robot_config.h"
#include "test_support.h"

namespace robomach::workflows {
namespace {

using ::testing::HasSubstr;
using testing::SourcePath;
using testing::TempDir;
using testing::WriteText;

polishing::PathRow Row(double t, double x_m, double y_m, double force) {
  polishing::PathRow r;
  r.t = t;
  r.p = Eigen::Vector3d(x_m, y_m, 0.0);
  r.n = Eigen::Vector3d::UnitZ();
  r.tx = Eigen::Vector3d::UnitX();
  r.force = force;
  return r;
}

// 3 mm and 4 mm in contact, then a lift (force 0) and 7 mm in the air, each
// segment in 0.1 s: 7 mm of contact, one lift, 70 mm/s at most.
TEST(PathFigures, ContactLengthLiftsTimeAndSpeedOfTheRows) {
  const std::vector<polishing::PathRow> rows = {Row(0.0, 0.0, 0.0, -1.0), Row(0.1, 0.003, 0.0, -1.0),
                                                Row(0.2, 0.003, 0.004, 0.0), Row(0.3, 0.010, 0.004, -1.0)};
  const io::PathFigures f = PathFiguresOf(rows);
  EXPECT_NEAR(f.contact_length_m, 0.007, 1e-12);
  EXPECT_EQ(f.lifts, 1);
  EXPECT_NEAR(f.time_s, 0.3, 1e-12);
  EXPECT_EQ(f.rows, 4u);
  EXPECT_NEAR(f.max_speed_m_per_s, 0.07, 1e-12);
  const nlohmann::json j = io::PathSummaryJson(f);
  EXPECT_NEAR(j["length_mm"].get<double>(), 7.0, 1e-9);
  EXPECT_EQ(j["lifts"].get<int>(), 1);
  EXPECT_EQ(j["rows"].get<int>(), 4);
  EXPECT_NEAR(j["max_speed_mm_per_s"].get<double>(), 70.0, 1e-9);
  const io::PathFigures none = PathFiguresOf({});
  EXPECT_EQ(none.time_s, 0.0);
  EXPECT_EQ(none.rows, 0u);
}

// The zig-zag's largest edge overrun is the process margin: a larger one
// asked for is reported (and written in the path's header) as the margin.
TEST(PathFigures, EdgeOverrunUsedIsAtMostTheLargestThePatternAllows) {
  polishing::PolishingProcess process;
  process.margin = 0.002;
  polishing::PathParameters p;
  p.pattern = polishing::Pattern::kParallel;
  p.offset = 0.008;
  p.edge_overrun = 0.005;
  EXPECT_DOUBLE_EQ(EdgeOverrunUsed(p, process), 0.002);
  bool found = false;
  for (const auto& [key, value] : PlannedPathMetadata(p, process)) {
    if (key != "edge_overrun_mm") continue;
    found = true;
    EXPECT_EQ(value, "2");
  }
  EXPECT_TRUE(found);
  p.edge_overrun = 0.001;
  EXPECT_DOUBLE_EQ(EdgeOverrunUsed(p, process), 0.001);
}

TEST(ContourFigures, StatisticsInMicrometresAndDegreesAndTheCoveredPart) {
  const machine::ProgrammedPath path({Eigen::Vector3d::Zero(), Eigen::Vector3d(0.1, 0.0, 0.0)},
                                     {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()});
  std::vector<machine::ContourError> contour(2);
  contour[0] = {1e-6, 0.0, 0.01};
  contour[1] = {3e-6, DegToRad(0.5), 0.05};
  const io::ContourFigures f = ContourFiguresOf(contour, path);
  EXPECT_NEAR(f.contour_error_um.max_abs, 3.0, 1e-9);
  EXPECT_NEAR(f.contour_error_um.mean, 2.0, 1e-9);
  EXPECT_NEAR(f.axis_error_deg.max_abs, 0.5, 1e-9);
  EXPECT_NEAR(f.path_length_mm, 100.0, 1e-9);
  const nlohmann::json j = io::ContourSummaryJson(f);
  EXPECT_NEAR(j["covered_mm"][0].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(j["covered_mm"][1].get<double>(), 50.0, 1e-9);
  EXPECT_NEAR(j["contour_error_um"]["max"].get<double>(), 3.0, 1e-9);
  const io::ContourFigures none = ContourFiguresOf({}, path);
  EXPECT_EQ(none.covered_min_mm, 0.0);
  EXPECT_EQ(none.covered_max_mm, 0.0);
}

// config/kr210.yaml with the joint stiffnesses typed per degree (/57.3): no
// value of the file is out of its range (the reader finds nothing), but the
// robot's own weight turns joint 2 by degrees: the model's finding, named at
// the stiffness's file:line:col, comes after the reader's.
TEST(RobotConfigChecked, TheJointsPlausibilityFollowsTheReadersFindings) {
  std::ifstream in(SourcePath("config/kr210.yaml"));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::string kq = "[3.3479e+6, 3.1318e+6, 4.2895e+6, 2.4787e+5, 6.4292e+5, 1.8847e+5]";
  const size_t at = text.find(kq);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, kq.size(), "[58430, 54660, 74870, 4326, 11221, 3289]");
  const std::string dir = TempDir("robot_config_checked");
  std::ifstream urdf(SourcePath("config/kr210_r2700_2.urdf"));
  std::stringstream u;
  u << urdf.rdbuf();
  WriteText(dir + "/kr210_r2700_2.urdf", u.str());
  const std::string path = WriteText(dir + "/robot.yaml", text);

  const io::RobotConfig read = io::LoadRobotConfig(path);
  EXPECT_TRUE(read.implausible.empty());
  ASSERT_EQ(read.joint_value_locations.joint_stiffness.size(), 6u);
  const io::RobotConfig checked = LoadRobotConfigChecked(path);
  ASSERT_EQ(checked.implausible.size(), 1u);
  EXPECT_THAT(checked.implausible[0],
              HasSubstr("robot.yaml:" + std::to_string(read.joint_value_locations.joint_stiffness[1].line)));
  EXPECT_THAT(checked.implausible[0], HasSubstr("joint 2 (joint_2): the robot's own weight"));
  EXPECT_THAT(checked.implausible[0], HasSubstr("a stiffness per degree typed in the N·m/rad field"));

  // The shipped config: nothing from the reader, nothing from the model.
  EXPECT_TRUE(LoadRobotConfigChecked(SourcePath("config/kr210.yaml")).implausible.empty());
}

}  // namespace
}  // namespace robomach::workflows
