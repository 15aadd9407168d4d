#include <fstream>
#include <iterator>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/io/urdf_loader.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using robomach::testing::CaptureError;
using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;
using ::testing::HasSubstr;

// A two-link arm; `inertia` is spliced into link b.
std::string Urdf(const std::string& inertia, const std::string& extra_link = "") {
  return R"(<?xml version="1.0"?>
<robot name="two">
  <link name="world"/>
  <link name="a"><inertial><mass value="2"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b">
    <inertial><mass value="1"/>)" + inertia + R"(</inertial>
  </link>)" + extra_link + R"(
  <joint name="j1" type="revolute"><parent link="world"/><child link="a"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>
)";
}

const char kGoodInertia[] = R"(<inertia ixx="0.2" iyy="0.3" izz="0.4" ixy="0" ixz="0" iyz="0"/>)";

TEST(UrdfLoader, ReadsTheChainWithLimits) {
  const std::string dir = TempDir("urdf_ok");
  const auto chain = LoadUrdfChain(WriteText(dir + "/r.urdf", Urdf(kGoodInertia)), "world", "b");
  EXPECT_EQ(chain.num_joints(), 2);
  EXPECT_EQ(chain.joint_names(), (std::vector<std::string>{"j1", "j2"}));
  EXPECT_DOUBLE_EQ(chain.limits()[1].upper, 2.0);
  EXPECT_NEAR(chain.segment_inertial(1).inertia_com(2, 2), 0.4, 1e-15);
}

TEST(UrdfLoader, MalformedXmlKeepsUrdfdomsReason) {
  const std::string dir = TempDir("urdf_bad");
  const std::string path = WriteText(dir + "/bad.urdf", "<robot name=\"x\"><link name=\"a\"></robot>");
  EXPECT_THAT(CaptureError([&] { LoadUrdfChain(path, "a", "a"); }),
              HasSubstr("bad.urdf: not a valid URDF model: "));
  const std::string dup = WriteText(dir + "/dup.urdf", Urdf(kGoodInertia, "<link name=\"b\"/>"));
  EXPECT_THAT(CaptureError([&] { LoadUrdfChain(dup, "world", "b"); }),
              HasSubstr("link 'b' is not unique"));
}

// NaN or inf in a number (urdfdom rejects some without saying where, and
// reads others, e.g. an inertial origin, as numbers): file, line and column
// of the attribute value (line 11, column 22 of the two-link arm:
// `    <origin xyz="0.5 nan 0"/>`; line 6, column 49 for the inertial origin of b).
TEST(UrdfLoader, NanOrInfIsRejectedWithLineAndColumn) {
  const std::string dir = TempDir("urdf_nan");
  for (const std::string t : {"nan", "inf", "-inf", "NaN"}) {
    std::string text = Urdf(kGoodInertia);
    const std::string origin = "<origin xyz=\"0.5 0 0\"/>";
    text.replace(text.find(origin), origin.size(), "<origin xyz=\"0.5 " + t + " 0\"/>");
    const std::string path = WriteText(dir + "/r.urdf", text);
    EXPECT_THAT(CaptureError([&] { LoadUrdfChain(path, "world", "b"); }),
                HasSubstr("r.urdf:11:22: expected a finite number, got \"" + t + "\""));
  }
  std::string text = Urdf(std::string(R"(<origin xyz="0 0 inf"/>)") + kGoodInertia);
  const std::string path = WriteText(dir + "/com.urdf", text);
  EXPECT_THAT(CaptureError([&] { LoadUrdfChain(path, "world", "b"); }),
              HasSubstr("com.urdf:6:49: expected a finite number, got \"inf\""));
}

TEST(UrdfLoader, MissingLinksAreNamedWithTheAvailableOnes) {
  const std::string dir = TempDir("urdf_link");
  const std::string path = WriteText(dir + "/r.urdf", Urdf(kGoodInertia));
  EXPECT_THAT(CaptureError([&] { LoadUrdfChain(path, "world", "tool0"); }),
              HasSubstr("r.urdf: tip link 'tool0' is not in the URDF; its links: a, b, world"));
  EXPECT_THAT(CaptureError([&] { LoadUrdfChain(path, "b", "a"); }),
              HasSubstr("tip link 'a' is not below base link 'b'"));
}

TEST(UrdfLoader, UnphysicalInertiasAreRejectedWithTheLinkAndLine) {
  const std::string dir = TempDir("urdf_inertia");
  const std::string npd = WriteText(
      dir + "/npd.urdf", Urdf(R"(<inertia ixx="0.2" iyy="-0.3" izz="0.4" ixy="0" ixz="0" iyz="0"/>)"));
  EXPECT_THAT(CaptureError([&] { LoadUrdfChain(npd, "world", "b"); }),
              HasSubstr("npd.urdf:5: link 'b': inertial is not physical: inertia is not positive definite"));
  const std::string tri = WriteText(
      dir + "/tri.urdf", Urdf(R"(<inertia ixx="0.1" iyy="0.1" izz="0.5" ixy="0" ixz="0" iyz="0"/>)"));
  EXPECT_THAT(CaptureError([&] { LoadUrdfChain(tri, "world", "b"); }),
              HasSubstr("violate the triangle inequality I1 + I2 >= I3"));
}

TEST(UrdfLoader, ShippedKr210HasSixJointsWithinLimits) {
  const auto chain = LoadUrdfChain(SourcePath("config/kr210_r2700_2.urdf"), "base_link", "tool0");
  EXPECT_EQ(chain.num_joints(), 6);
  EXPECT_NEAR(chain.limits()[1].lower, -2.443460952792061, 1e-15);
}

// A joint whose parent is its own child link: urdfdom accepts the cycle, and
// walking up from the tip never ended (issue #22, found by fuzz_urdf; the
// input is tests/fuzz/corpus/urdf/cycle_joint_parent_is_child.urdf).
TEST(UrdfLoader, CycleInTheJointTreeIsRejectedWithTheJointsLine) {
  std::ifstream in(SourcePath("config/kr210_r2700_2.urdf"));
  std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "<parent link=\"link_4\"/>";
  ASSERT_NE(xml.find(from), std::string::npos);
  xml.replace(xml.find(from), from.size(), "<parent link=\"link_5\"/>");
  const std::string path = WriteText(TempDir("urdf_cycle") + "/cycle.urdf", xml);
  // Line 100 of the shipped file: <joint name="joint_5" type="revolute">.
  EXPECT_THAT(CaptureError([&] { LoadUrdfChain(path, "base_link", "tool0"); }),
              HasSubstr("cycle.urdf:100: link 'link_5' is its own ancestor"));
}

}  // namespace
}  // namespace robomach::io
