// The io pieces that came out of the tools (issue #21): the load-test plan
// read back, the part frame and the polishing path on a robot, the joint
// trajectory CSV. Expected values are worked out by hand.
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/kq_files.h"
#include "robomach/io/polishing_files.h"
#include "robomach/workflows/polish_robot_check.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using robomach::testing::CaptureError;
using robomach::testing::TempDir;
using robomach::testing::WriteText;

TEST(LoadTestPlanCsv, ReadsPosturesTheirPulleysAndTheHeader) {
  const std::string path = WriteText(TempDir("plan_read") + "/plan.csv",
                                     "# load_point_mm: 0,0,150\n"
                                     "pose_id,q1_deg,q2_deg,pulley_x_mm,pulley_y_mm,pulley_z_mm,load_kg\n"
                                     "A,10,-20,1000,0,500,10\n"
                                     "A,10,-20,0,1000,500,10\n"
                                     "B,30,40,-1000,0,500,20\n");
  const LoadTestPlanFile plan = ReadLoadTestPlanCsv(path, 2);
  ASSERT_EQ(plan.pose_ids, (std::vector<std::string>{"A", "B"}));
  ASSERT_EQ(plan.q.size(), 2u);
  EXPECT_NEAR(plan.q[0](0), DegToRad(10.0), 1e-15);
  EXPECT_NEAR(plan.q[0](1), DegToRad(-20.0), 1e-15);
  EXPECT_NEAR(plan.q[1](1), DegToRad(40.0), 1e-15);
  ASSERT_EQ(plan.pulleys[0].size(), 2u);
  ASSERT_EQ(plan.pulleys[1].size(), 1u);
  EXPECT_TRUE(plan.pulleys[0][1].isApprox(Eigen::Vector3d(0.0, 1.0, 0.5)));
  EXPECT_TRUE(plan.pulleys[1][0].isApprox(Eigen::Vector3d(-1.0, 0.0, 0.5)));
  EXPECT_EQ(plan.metadata.at("load_point_mm"), "0,0,150");
}

TEST(LoadTestPlanCsv, RefusesSplitPosturesAndEmptyPlansWithTheLine) {
  const std::string dir = TempDir("plan_bad");
  const std::string split = WriteText(dir + "/split.csv",
                                      "pose_id,q1_deg,pulley_x_mm,pulley_y_mm,pulley_z_mm\n"
                                      "A,0,1000,0,0\n"
                                      "B,0,1000,0,0\n"
                                      "A,0,0,1000,0\n");
  const std::string e = CaptureError([&] { ReadLoadTestPlanCsv(split, 1); });
  EXPECT_NE(e.find(split + ":4:"), std::string::npos) << e;
  EXPECT_NE(e.find("rows of posture A must be adjacent"), std::string::npos) << e;
  const std::string empty = WriteText(dir + "/empty.csv", "pose_id,q1_deg,pulley_x_mm,pulley_y_mm,pulley_z_mm\n");
  EXPECT_NE(CaptureError([&] { ReadLoadTestPlanCsv(empty, 1); }).find("no postures in the plan"), std::string::npos);
}

TEST(PartFrameFromMmDeg, MillimetresAndFixedAxisAnglesZYX) {
  const Eigen::Isometry3d t = workflows::PartFrameFromMmDeg({100, 200, 300, 0, 0, 0});
  EXPECT_TRUE(t.translation().isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_TRUE(t.linear().isIdentity(1e-15));
  // rx = 90 deg turns y into z; rz = 90 deg then turns x into y and leaves z.
  const Eigen::Matrix3d R = workflows::PartFrameFromMmDeg({0, 0, 0, 90, 0, 90}).linear();
  EXPECT_TRUE((R * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_TRUE((R * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  // ry = 90 deg turns z into x.
  const Eigen::Matrix3d Ry = workflows::PartFrameFromMmDeg({0, 0, 0, 0, 90, 0}).linear();
  EXPECT_TRUE((Ry * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_THROW(workflows::PartFrameFromMmDeg({1, 2, 3}), std::invalid_argument);
}

TEST(PolishPathOnRobot, VerdictCountsTheFlaggedRowsAndNamesTheFirst) {
  kinematics::PosePathCheck check;
  EXPECT_FALSE(workflows::JudgePolishPathOnRobot(check).flagged());
  check.num_unreachable = 2;
  check.num_jumps = 1;
  check.first_bad_row = 4;
  const RunFindings v = workflows::JudgePolishPathOnRobot(check);
  ASSERT_EQ(v.findings.size(), 1u);
  EXPECT_EQ(v.findings[0].message,
            "2 rows unreachable, 0 outside the joint limits, 1 with a joint jump > 0.5 rad (first: row 5)");
}

TEST(PolishPathOnRobot, JointTrajectoryLeavesUnreachableRowsEmpty) {
  std::vector<polishing::PathRow> rows(2);
  rows[0].t = 0.0;
  rows[1].t = 0.25;
  kinematics::PosePathCheck check;
  check.q = {Eigen::Vector2d(0.5, -0.25), Eigen::VectorXd()};
  check.reachable = {1, 0};
  check.limit_margin = {0.1, NAN};
  check.condition = {12.5, NAN};
  const std::string path = TempDir("joint_trajectory") + "/joints.csv";
  WriteJointTrajectoryCsv(path, rows, check, 2);
  const CsvTable t = CsvTable::ReadFile(path);
  ASSERT_EQ(t.num_rows(), 2);
  EXPECT_NEAR(t.Number(0, "q1_deg"), RadToDeg(0.5), 1e-12);
  EXPECT_NEAR(t.Number(0, "q2_deg"), RadToDeg(-0.25), 1e-12);
  EXPECT_NEAR(t.Number(0, "limit_margin_deg"), RadToDeg(0.1), 1e-12);
  EXPECT_EQ(t.Number(0, "jacobian_condition"), 12.5);
  EXPECT_EQ(t.Number(1, "t_s"), 0.25);
  EXPECT_EQ(t.Number(1, "reachable"), 0.0);
  EXPECT_TRUE(t.IsEmpty(1, "q1_deg"));
  EXPECT_TRUE(t.IsEmpty(1, "jacobian_condition"));
}

}  // namespace
}  // namespace robomach::io
