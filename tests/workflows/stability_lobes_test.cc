// stability-lobes as one library call (workflows/stability_lobes.h, issue
// #36 §1): the options' checks name the field and its bound; a run on a
// modal table and a cut file written here by hand gives the lobes of the
// closed-form single-mode ZOA, and an implausible cut value flags the run.

#include "robomach/workflows/stability_lobes.h"

#include <cmath>
#include <functional>
#include <iostream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/errors.h"
#include "test_support.h"

namespace robomach::workflows {
namespace {

using ::testing::HasSubstr;
using robomach::testing::TempDir;
using robomach::testing::WriteText;


std::string FieldOf(const std::function<void()>& f, std::string* message) {
  try {
    f();
  } catch (const OptionError& e) {
    *message = e.what();
    return e.field();
  }
  return "";
}

TEST(StabilityLobesOptions, EachBadValueNamesItsFieldAndBound) {
  StabilityLobesOptions ok;
  ok.cut_path = "cut.yaml";
  ok.modal_table_path = "modes.csv";
  EXPECT_NO_THROW(ok.Validate());
  struct Case {
    std::function<void(StabilityLobesOptions&)> set;
    std::string field, words;
  };
  const Case cases[] = {
      {[](auto& o) { o.sd_speeds = 0; }, "sd_speeds", "sd_speeds 0 is outside [1, 10000]"},
      {[](auto& o) { o.speeds = 200000; }, "speeds", "speeds 200000 is outside [0, 100000]"},
      {[](auto& o) { o.sd_steps = 1; }, "sd_steps", "sd_steps 1 is outside [2, 1000]"},
      {[](auto& o) { o.sd_steps_per_mode_period = 2.0; }, "sd_steps_per_mode_period", "outside [4, 1000]"},
      {[](auto& o) { o.sd_modes = 0; }, "sd_modes", "sd_modes 0 is outside [1, 200]"},
      {[](auto& o) { o.sd_max_depth_mm = NAN; }, "sd_max_depth_mm", "sd_max_depth_mm nan"},
      {[](auto& o) { o.threads = -1; }, "threads", "threads -1 is outside [0, 256]"},
      {[](auto& o) { o.max_lobe = 5000; }, "max_lobe", "outside [0, 1000]"},
      {[](auto& o) { o.tool_axis.setZero(); }, "tool_axis", "expected a non-zero vector"},
      {[](auto& o) { o.frf_path = "h.csv"; }, "robot_path", "exactly one tool-tip source"},
      {[](auto& o) { o.modal_table_path.clear(); }, "robot_path", "exactly one tool-tip source"},
      {[](auto& o) {
         o.modal_table_path.clear();
         o.robot_path = "r.yaml";
       },
       "postures_path", "robot_path needs postures_path"},
      {[](auto& o) { o.frf_y_path = "y.csv"; }, "frf_y_path", "frf_y_path needs frf_path"},
  };
  for (const Case& c : cases) {
    StabilityLobesOptions o = ok;
    c.set(o);
    std::string message;
    EXPECT_EQ(FieldOf([&] { o.Validate(); }, &message), c.field) << c.words;
    EXPECT_THAT(message, HasSubstr(c.words));
  }
  std::string message;
  EXPECT_EQ(FieldOf([] { stability::ParseLobeMethod("zo"); }, &message), "method");
  EXPECT_THAT(message, HasSubstr("expected zoa, sd or both"));
  for (auto m : {stability::LobeMethod::kZoa, stability::LobeMethod::kSd, stability::LobeMethod::kBoth}) {
    EXPECT_EQ(stability::ParseLobeMethod(stability::ToString(m)), m);
  }
}

// One mode in x, a rigid y, slotting (the directional factor is then a
// constant): alpha_xx = -pi Kr over the immersion 0..pi [Altintas,
// Manufacturing Automation, 2nd ed. (2012), eq. (3.65)], the eigenvalue
// Lambda = -1/(alpha_xx G) and a_lim = -2 pi Lambda_R (1 + kappa^2)/(N Kt)
// = 2 pi / (N Kt Re(alpha_xx G)) (eq. (3.73)); its smallest value, where
// Re G = -1/(4 k zeta (1 + zeta)), is a_min = 8 k zeta (1 + zeta)/(N Kt Kr)
// with Kr = Krc/Ktc. The run samples the lobes at 4000 speeds over eight
// lobes: the sampled minimum is within 1 % of the bottom.
TEST(RunStabilityLobes, ModalTableAndCutFromFilesGiveTheClosedFormMinimumAndFindingsFlag) {
  const std::string dir = TempDir("workflow_lobes");
  const double f_hz = 500.0, zeta = 0.03, k = 2.0e7;  // [Hz], [-], [N/m]
  const std::string table = WriteText(dir + "/modes.csv",
                                      "pose_id,mode,freq_hz,damping_ratio,modal_stiffness_N_per_m,ux,uy,uz\n"
                                      "T,1," + std::to_string(f_hz) + "," + std::to_string(zeta) + "," +
                                          std::to_string(k) + ",1,0,0\n");
  const std::string cut_text =
      "diameter_mm: 20\nteeth: 2\nradial_immersion: 1\nmilling: down\nfeed_direction: [1, 0, 0]\n"
      "feed_per_tooth_mm: 0.05\ncutting_coefficients:\n  ktc_N_per_mm2: 1000\n  krc_N_per_mm2: 300\n"
      "spindle_speed_min_rpm: 3000\nspindle_speed_max_rpm: 30000\nspindle_speed_count: 4000\n";
  StabilityLobesOptions o;
  o.cut_path = WriteText(dir + "/cut.yaml", cut_text);
  o.modal_table_path = table;
  const StabilityLobesRun run = RunStabilityLobes(o);
  ASSERT_EQ(run.tips.size(), 1u);
  EXPECT_TRUE(run.input_findings.empty());
  double smallest = INFINITY;
  for (const stability::LobeRow& r : run.lobes.rows) {
    if (r.point.status == stability::LobeStatus::kOk) smallest = std::min(smallest, r.point.critical_depth);
  }
  const double Kt = 1000e6, Kr = 300.0 / 1000.0, N = 2.0;  // [N/m^2], [-], teeth
  const double a_min = 8.0 * k * zeta * (1.0 + zeta) / (N * Kt * Kr);  // [m]
  std::cout << "smallest " << smallest << " a_min " << a_min << "\n";
  EXPECT_NEAR(smallest, a_min, 0.01 * a_min);
  const nlohmann::json s = run.Summary(o);
  EXPECT_EQ(s["source"], "modal_table");
  EXPECT_EQ(s["method"], "zoa");
  EXPECT_EQ(s["teeth"], 2);

  // A cutter diameter of 20 m (mm typed as um?) is a finding: the run is flagged.
  std::string big = cut_text;
  big.replace(big.find("diameter_mm: 20"), 15, "diameter_mm: 20000");
  o.cut_path = WriteText(dir + "/cut_big.yaml", big);
  std::vector<std::string> told;
  const StabilityLobesRun flagged = RunStabilityLobes(o, [&](const Message& msg) {
    if (msg.kind == Message::Kind::kWarning) told.push_back(msg.text);
  });
  ASSERT_EQ(flagged.input_findings.size(), 1u);
  EXPECT_TRUE(flagged.flagged());
  EXPECT_THAT(told, ::testing::Contains(flagged.input_findings[0]));
  EXPECT_EQ(flagged.Summary(o)["input_findings"].size(), 1u);
}

}  // namespace
}  // namespace robomach::workflows
