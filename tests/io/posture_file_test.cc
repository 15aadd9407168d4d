#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/io/posture_file.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using robomach::testing::CaptureError;
using robomach::testing::TempDir;
using robomach::testing::WriteText;
using ::testing::HasSubstr;

TEST(PostureFile, ReadsDegreesAndRadiansPerJointAndRoundTrips) {
  const std::string dir = TempDir("posture_ok");
  const std::string path = WriteText(dir + "/p.csv",
                                     "# comment\npose_id,q2_rad,q1_deg,q3_deg,note\nA,-1.5,30,90,x\n");
  const auto p = ReadPostureFile(path, 3);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].id, "A");
  EXPECT_DOUBLE_EQ(p[0].q(0), DegToRad(30));
  EXPECT_DOUBLE_EQ(p[0].q(1), -1.5);
  EXPECT_EQ(p[0].line, 3);
  WritePostureFile(dir + "/out.csv", p);
  const auto back = ReadPostureFile(dir + "/out.csv", 3);
  EXPECT_LE((back[0].q - p[0].q).norm(), 1e-15);
}

TEST(PostureFile, BadInputGetsLocatedMessages) {
  const std::string dir = TempDir("posture_bad");
  auto err = [&](const std::string& text, int n) {
    const std::string path = WriteText(dir + "/p.csv", text);
    return CaptureError([&] { ReadPostureFile(path, n); });
  };
  EXPECT_THAT(err("pose_id,q1_deg,q2_deg\nA,1,2\n", 3),
              HasSubstr("p.csv:1: missing column q3_deg (or q3_rad): the robot has 3 joints"));
  EXPECT_THAT(err("pose_id,q1_deg,q2_deg,q3_deg\nA,1,2,3\n", 2),
              HasSubstr("p.csv:1: the file has joint columns up to q3 but the robot has 2 joints"));
  // A joint number past int's range (std::stoi threw std::out_of_range; found
  // by fuzz_posture_csv, issue #22).
  EXPECT_THAT(err("pose_id,q1_deg,q99999999999_deg\nA,1,2\n", 2),
              HasSubstr("p.csv:1:3: column q99999999999_deg: the robot has 2 joints, so there is no joint 99999999999"));
  EXPECT_THAT(err("pose_id,q1_deg,q1_rad\nA,1,2\n", 1),
              HasSubstr("joint 1 is given twice, as q1_deg and q1_rad; keep one"));
  EXPECT_THAT(err("pose_id,q1_deg\nP2,1\nP2,3\n", 1),
              HasSubstr("p.csv:3: pose_id \"P2\" appears twice (first on line 2)"));
  EXPECT_THAT(err("pose_id,q1_deg\nP1,abc\n", 1),
              HasSubstr("p.csv:2: column q1_deg: expected a number, got \"abc\""));
  EXPECT_THAT(err("pose_id,q1_deg\n,1\n", 1), HasSubstr("p.csv:2: column pose_id: expected a value"));
  EXPECT_THAT(err("pose_id,q1_deg\n", 1), HasSubstr("no postures"));
  // num_joints 0: the count from the file, no column missing below its highest.
  EXPECT_THAT(err("pose_id,q1_deg,q3_deg\nA,1,2\n", 0),
              HasSubstr("p.csv:1: missing column q2_deg (or q2_rad): the file has columns up to q3"));
  EXPECT_THAT(err("pose_id,x_deg\nA,1\n", 0), HasSubstr("p.csv:1: no joint columns: expected q1_deg..qn_deg"));
  const std::string path = WriteText(dir + "/p.csv", "pose_id,q2_rad,q1_deg\nA,-1.5,30\n");
  const auto p = ReadPostureFile(path, 0);
  ASSERT_EQ(p.size(), 1u);
  ASSERT_EQ(p[0].q.size(), 2);
  EXPECT_DOUBLE_EQ(p[0].q(1), -1.5);
}

}  // namespace
}  // namespace robomach::io

namespace robomach::io {
namespace {

TEST(PostureFile, PoseIdsWithCommasAreRejected) {
  const std::string dir = robomach::testing::TempDir("posture_comma");
  const std::string path = robomach::testing::WriteText(dir + "/p.csv", "pose_id,q1_deg\n\"P,1\",0\n");
  EXPECT_THAT(robomach::testing::CaptureError([&] { ReadPostureFile(path, 1); }),
              ::testing::HasSubstr("p.csv:2: column pose_id: expected a name without commas"));
}

}  // namespace
}  // namespace robomach::io
