#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "robomach/dynamics/robot_model.h"
#include "robomach/io/kq_yaml.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/yaml_doc.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using robomach::testing::CaptureError;
using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;
using ::testing::HasSubstr;

// The shipped config with `from` replaced by `to`, written next to a copy of
// the URDF so the relative path still resolves.
std::string Variant(const std::string& name, const std::string& from, const std::string& to) {
  std::ifstream in(SourcePath("config/kr210.yaml"));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const size_t pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  text.replace(pos, from.size(), to);
  const std::string dir = TempDir("config_" + name);
  std::ifstream urdf(SourcePath("config/kr210_r2700_2.urdf"));
  std::stringstream u;
  u << urdf.rdbuf();
  WriteText(dir + "/kr210_r2700_2.urdf", u.str());
  return WriteText(dir + "/robot.yaml", text);
}

TEST(RobotConfig, UnknownKeysAreRejectedWithLineColumnAndTheKnownKeys) {
  const std::string p = Variant("unknown", "  alpha_s: 1.0e-4", "  alpha_s: 1.0e-4\n  gamma: 3");
  EXPECT_THAT(CaptureError([&] { LoadRobotConfig(p); }),
              HasSubstr("robot.yaml:31:3: unknown key 'gamma' in 'damping'; known keys: alpha_s, beta_per_s"));
}

TEST(RobotConfig, AMistypedKeyIsAnsweredWithTheKeyMeant) {
  const std::string p = Variant("typo", "  alpha_s: 1.0e-4", "  alpha_s: 1.0e-4\n  beta_per_ss: 3");
  EXPECT_THAT(CaptureError([&] { LoadRobotConfig(p); }),
              HasSubstr("robot.yaml:31:3: unknown key 'beta_per_ss' in 'damping'; did you mean 'beta_per_s'? "
                        "Known keys: alpha_s, beta_per_s"));
}

TEST(RobotConfig, BadValuesAreLocated) {
  EXPECT_THAT(CaptureError([&] {
                LoadRobotConfig(Variant("kq", "[3.3479e+6, 3.1318e+6,", "[3.3479e+6, abc,"));
              }),
              HasSubstr("robot.yaml:26:41: joint_stiffness_Nm_per_rad[1]: expected a finite number, got \"abc\""));
  EXPECT_THAT(CaptureError([&] {
                LoadRobotConfig(Variant("kq5", "3.3479e+6, 3.1318e+6, 4.2895e+6, 2.4787e+5, 6.4292e+5, 1.8847e+5]",
                                        "3.3479e+6, 3.1318e+6, 4.2895e+6, 2.4787e+5, 6.4292e+5]"));
              }),
              HasSubstr("joint_stiffness_Nm_per_rad: expected a list of 6 numbers, got 5"));
  EXPECT_THAT(CaptureError([&] {
                LoadRobotConfig(Variant("inertia", "[0.256, 0.256, 0.062,", "[0.256, 0.01, 0.062,"));
              }),
              HasSubstr("violate the triangle inequality"));
  EXPECT_THAT(CaptureError([&] { LoadRobotConfig(Variant("m6", "m6_kg: 29.05", "m6_kg: 31")); }),
              HasSubstr("weigh 29.05 kg; m6_kg must state that reference"));
  EXPECT_THAT(CaptureError([&] { LoadRobotConfig(Variant("tip", "tip_frame: tool0", "tip_frame: tool9")); }),
              HasSubstr("tip link 'tool9' is not in the URDF"));
  EXPECT_THAT(CaptureError([&] {
                LoadRobotConfig(Variant("param", "\nhammer_test:", "\nparameters:\n  m6_kg: -4\nhammer_test:"));
              }),
              HasSubstr("parameter 'm6_kg': -4 kg is outside its bounds"));
  EXPECT_THAT(CaptureError([&] {
                LoadRobotConfig(Variant("effect", "\nhammer_test:", "\neffects:\n  - name: tip_mas\nhammer_test:"));
              }),
              HasSubstr("unknown effect 'tip_mas': expected "));
}

// Issue #37: a config names parameter-uncertainty files relative to its
// folder, as it names its URDF.
TEST(RobotConfig, UncertaintyFilesAreResolvedAgainstTheConfigsFolder) {
  const std::string p = Variant("uncertainty", "\ndamping:", "\nuncertainty: [unc/kq.yaml, /abs/other.yaml]\ndamping:");
  const RobotConfig cfg = LoadRobotConfig(p);
  ASSERT_EQ(cfg.uncertainty_files.size(), 2u);
  EXPECT_EQ(cfg.uncertainty_files[0], (std::filesystem::path(p).parent_path() / "unc/kq.yaml").lexically_normal().string());
  EXPECT_EQ(cfg.uncertainty_files[1], "/abs/other.yaml");
  EXPECT_TRUE(LoadRobotConfig(testing::SourcePath("config/kr210.yaml")).uncertainty_files.empty());
}

TEST(RobotConfig, MalformedYamlIsLocated) {
  const std::string dir = TempDir("config_yaml");
  const std::string p = WriteText(dir + "/r.yaml", "robot:\n  urdf: [a, b\n");
  EXPECT_THAT(CaptureError([&] { LoadRobotConfig(p); }), HasSubstr("r.yaml:3:1: not valid YAML"));
}

TEST(RobotConfig, ParametersAndEffectsRoundTripThroughYaml) {
  const std::string p = Variant("roundtrip", "\nhammer_test:",
                                "\neffects:\n  - name: tip_mass\n    mass_kg: 0.02\n"
                                "parameters:\n  m6_kg: 30.5\nhammer_test:");
  const RobotConfig cfg = LoadRobotConfig(p);
  EXPECT_DOUBLE_EQ(cfg.parameters.Get("m6_kg"), 30.5);
  EXPECT_DOUBLE_EQ(cfg.parameters.Get("tip_mass.mass_kg"), 0.02);
  const std::string yaml = ParametersYaml(cfg.parameters, dynamics::DefaultParameters(cfg.description));
  EXPECT_THAT(yaml, HasSubstr("  m6_kg: 30.5   # [kg]"));
  EXPECT_THAT(yaml, ::testing::Not(HasSubstr("d6_m")));
}

}  // namespace
}  // namespace robomach::io

namespace robomach::io {
namespace {

// yaml-cpp silently keeps the first of two equal keys; we refuse the file.
TEST(RobotConfig, DuplicateKeysAreRejectedWithBothLines) {
  const std::string p = Variant("dupkey", "damping:\n", "damping:\n  alpha_s: 2.0e-4\n");
  EXPECT_THAT(CaptureError([&] { LoadRobotConfig(p); }),
              HasSubstr("robot.yaml:31:3: key 'alpha_s' appears twice (first on line 30)"));
}

// frf-calibrate's calibrated config, written to another folder: it loads
// (the URDF path follows), the calibrated values and the effect switched on
// for the calibration come back, and the input's old parameters block is
// gone. A config with its own effects list gets the effects it lacks.
TEST(RobotConfig, CalibratedConfigLoadsFromAnotherFolderWithItsValues) {
  const RobotConfig in = LoadRobotConfig(SourcePath("config/kr210.yaml"));
  auto [desc, params] = dynamics::WithEffect(in.description, in.parameters, "tip_mass");
  params.Set("m6_kg", 31.25);
  params.Set("tip_mass.mass_kg", 0.125);
  const std::string out = TempDir("calibrated_config") + "/sub/cal.yaml";
  std::filesystem::create_directories(std::filesystem::path(out).parent_path());
  bool left_out = true;
  const std::string text = CalibratedConfigText(SourcePath("config/kr210.yaml"), out,
                                                ParametersYaml(params, dynamics::DefaultParameters(desc)),
                                                {"tip_mass"}, &left_out);
  EXPECT_FALSE(left_out);
  WriteText(out, text);
  const RobotConfig back = LoadRobotConfig(out);
  EXPECT_EQ(back.parameters.Get("m6_kg"), 31.25);
  EXPECT_EQ(back.parameters.Get("tip_mass.mass_kg"), 0.125);
  // Once more from the calibrated config (it has a parameters block and an
  // effects list now): one parameters block, and the effects list has
  // tip_mass once (it is not added again; issue #33: effects are added to a
  // config's own list, so nothing is left to the user here).
  const std::string again =
      CalibratedConfigText(out, out, ParametersYaml(params, dynamics::DefaultParameters(desc)), {"tip_mass"}, &left_out);
  EXPECT_FALSE(left_out);
  size_t listed = 0;
  for (size_t at = again.find("name: tip_mass"); at != std::string::npos; at = again.find("name: tip_mass", at + 1)) {
    ++listed;
  }
  EXPECT_EQ(listed, 1u) << again;
  WriteText(out, again);
  EXPECT_EQ(LoadRobotConfig(out).parameters.Get("tip_mass.mass_kg"), 0.125);
  // A config with its own effects list gets a new effect at the end of it.
  const std::string more = CalibratedConfigText(out, out, ParametersYaml(params, dynamics::DefaultParameters(desc)),
                                                {"tip_mass", "joint_damping"}, &left_out);
  EXPECT_FALSE(left_out);
  EXPECT_NE(more.find("  - name: tip_mass\n  - name: joint_damping\n"), std::string::npos) << more;
  size_t blocks = 0;
  for (size_t at = again.find("\nparameters:"); at != std::string::npos; at = again.find("\nparameters:", at + 1)) {
    ++blocks;
  }
  EXPECT_EQ(blocks, 1u);
}

// Both writers of a config copy (frf-calibrate's calibrated config,
// kq-identify --merge) re-base the relative URDF path so that the copy
// loads, also when the copy's folder is reached through a symbolic link to a
// folder at another depth: the loader resolves '..' lexically, and a path
// re-based from the link's target would climb too far.
TEST(RobotConfig, CopiesLoadThroughASymbolicLinkToAnotherDepth) {
  namespace fs = std::filesystem;
  EXPECT_EQ(RebaseRelative("/a/b/c.yaml", "../r.urdf", "/a/x/y/out.yaml"), "../../r.urdf");
  EXPECT_EQ(RebaseRelative("/a/b/c.yaml", "r.urdf", "/a/b/out.yaml"), "r.urdf");
  EXPECT_EQ(RebaseRelative("/a/b/c.yaml", "/abs/r.urdf", "/q/out.yaml"), "/abs/r.urdf");

  const fs::path dir = TempDir("config_copy_symlink");
  fs::create_directories(dir / "deep" / "er" / "real");
  std::error_code ec;
  fs::remove(dir / "link", ec);
  fs::create_directory_symlink(dir / "deep" / "er" / "real", dir / "link");
  const std::string src = SourcePath("config/kr210.yaml");
  const RobotConfig in = LoadRobotConfig(src);
  const std::string cal = (dir / "link" / "cal.yaml").string();
  WriteText(cal, CalibratedConfigText(src, cal, ParametersYaml(in.parameters, dynamics::DefaultParameters(in.description)),
                                      {}, nullptr));
  EXPECT_EQ(LoadRobotConfig(cal).Build()->num_joints(), 6);
  const std::string merged = (dir / "link" / "merged.yaml").string();
  Eigen::VectorXd kq = in.Build()->joint_stiffness();
  WriteText(merged, MergeJointStiffness(src, kq, merged, {"merged"}));
  EXPECT_EQ(LoadRobotConfig(merged).Build()->num_joints(), 6);
}

}  // namespace
}  // namespace robomach::io
