// frf-predict as one library call (issue #36 §1): workflows::RunFrfPredict,
// FrequencyGrid and ApplyAddsAndSets. References: the grid's line count and
// ends by hand; the receptance (modal superposition, the default) against
// a direct solve of each posture's assembled system (dynamics::
// ReceptanceDirect: exact for the KR 210's proportional damping); errors by
// their field, as the tools name them.
#include "robomach/workflows/frf_predict.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "robomach/common/errors.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "test_support.h"

namespace robomach::workflows {
namespace {

using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;

std::string FieldOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const OptionError& e) {
    return e.field() + ": " + e.what();
  }
  return "";
}

TEST(FrequencyGrid, LinesEndsAndRefusals) {
  const Eigen::VectorXd f = FrequencyGrid(0.625, 500.0, 0.625);
  ASSERT_EQ(f.size(), 800);  // 0.625 .. 500 in steps of 0.625
  EXPECT_DOUBLE_EQ(f(0), 0.625);
  EXPECT_DOUBLE_EQ(f(799), 500.0);
  EXPECT_EQ(FieldOf([] { FrequencyGrid(10.0, 5.0, 1.0); }).rfind("fmin_hz: expected finite 0 <= fmin_hz < fmax_hz", 0),
            0u);
  // 1e9 Hz: too many lines, and the likely mistake named.
  const std::string m = FieldOf([] { FrequencyGrid(0.625, 1e9, 0.625); });
  EXPECT_NE(m.find("more than the 200000 allowed"), std::string::npos) << m;
  EXPECT_NE(m.find("typed in the Hz option?"), std::string::npos) << m;
  // A step wider than the band: one line, no FRF.
  const std::string one = FieldOf([] { FrequencyGrid(0.625, 50.0, 1e30); });
  EXPECT_EQ(one.rfind("df_hz: df_hz 1e+30: leaves 1 frequency line in fmin_hz 0.625 to fmax_hz 50 Hz", 0), 0u) << one;
  EXPECT_EQ(FrequencyGrid(0.625, 50.0, 49.375).size(), 2);
}

TEST(ApplyAddsAndSets, ChangesTheConfigOrNamesTheField) {
  io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  ApplyAddsAndSets({"tip_mass"}, {"m6_kg=31.5"}, &cfg);
  EXPECT_DOUBLE_EQ(cfg.parameters.Get("m6_kg"), 31.5);
  EXPECT_EQ(cfg.description.effects.size(), 1u);
  EXPECT_EQ(FieldOf([&] { ApplyAddsAndSets({"tip_masss"}, {}, &cfg); }).rfind("adds: adds tip_masss: ", 0), 0u);
  EXPECT_EQ(FieldOf([&] { ApplyAddsAndSets({}, {"m6_kg=abc"}, &cfg); }),
            "sets: sets m6_kg=abc: expected NAME=VALUE with a number, e.g. m6_kg=30");
  EXPECT_EQ(FieldOf([&] { ApplyAddsAndSets({}, {"m9_kg=1"}, &cfg); }).rfind("sets: sets m9_kg=1: ", 0), 0u);
}

TEST(RunFrfPredict, ReceptanceOfEveryPostureAndTheFindings) {
  FrfPredictOptions o;
  o.robot_path = SourcePath("config/kr210.yaml");
  o.postures_path = SourcePath("config/postures_demo.csv");
  o.freq_hz = FrequencyGrid(1.0, 100.0, 1.0);
  const FrfPredictRun run = RunFrfPredict(o);
  ASSERT_EQ(run.predictions.size(), 5u);
  EXPECT_FALSE(run.flagged());
  // The second path: a direct solve per line of the same assembled system.
  for (size_t p = 0; p < run.postures.size(); ++p) {
    const std::vector<Eigen::Matrix3cd> h = dynamics::ReceptanceDirect(run.dynamics[p].system, o.freq_hz);
    ASSERT_EQ(h.size(), run.predictions[p].H.size());
    for (size_t i = 0; i < h.size(); i += 9) {
      EXPECT_LE((h[i] - run.predictions[p].H[i]).norm(), 1e-8 * h[i].norm()) << run.postures[p].id << " line " << i;
    }
  }
  // Radians under _deg headers: a unit finding that flags the run.
  const std::string dir = TempDir("frf_predict_run");
  o.postures_path = WriteText(dir + "/rad.csv", "pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n"
                                                "P1,0.1,-1.2,1.4,0.3,0.7,0.2\nP2,0.5,-0.9,1.1,-0.2,0.4,1.0\n");
  const FrfPredictRun rad = RunFrfPredict(o);
  ASSERT_EQ(rad.unit_findings.size(), 1u);
  EXPECT_TRUE(rad.flagged());
  EXPECT_EQ(rad.status(), RunStatus::kFlagged);
  // A set parameter that the uncertainty also gives, and a grid too large
  // for the postures: OptionErrors on their fields.
  o.postures_path = SourcePath("config/postures_demo.csv");
  o.sets = {"kq2_Nm_per_rad=3e6"};
  o.uncertainty_paths = {SourcePath("tests/data/uncertainty/kq_demo.yaml")};
  o.intervals = true;
  EXPECT_EQ(FieldOf([&] { RunFrfPredict(o); }).rfind("sets: sets kq2_Nm_per_rad and uncertainty_paths (", 0), 0u);
  o.sets.clear();
  o.uncertainty_paths.clear();
  o.intervals = false;
  o.freq_hz = Eigen::VectorXd::LinSpaced(400001, 0.0, 400000.0);  // 5 postures x 400 001 lines > 2e6
  EXPECT_EQ(FieldOf([&] { RunFrfPredict(o); }).rfind("postures_path: postures_path: 5 postures × 400001", 0), 0u);
}

}  // namespace
}  // namespace robomach::workflows
