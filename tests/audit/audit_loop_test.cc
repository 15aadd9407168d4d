// Issue #33 acceptance: the demo loop done by hand, as docs/model-audit.md
// says, with the tools as a user runs them: model-audit on the shipped demo
// data with --write-config, then frf-predict with the written config (no
// calibration again), whose predicted FRFs must be within 1.3 × the noise of
// the demo data (AuditOptions::explained_factor), the noise taken as
// model-audit takes it (the scatter model of the data, its usable lines).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "robomach/calibration/frf_noise.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach {
namespace {

using robomach::testing::SourcePath;

int RunTool(const std::string& command) {
  const int rc = std::system(command.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(AuditLoop, WrittenConfigPredictsTheDemoDataWithinTheNoiseWithoutCalibratingAgain) {
  const std::string dir = robomach::testing::TempDir("audit_loop");
  const std::string config = dir + "/kr210_audited.yaml";
  const std::string postures = SourcePath("config/demo/postures.csv");
  const std::string hammer = SourcePath("config/demo/hammer.csv");
  std::remove(config.c_str());
  ASSERT_EQ(RunTool(std::string(MODEL_AUDIT_EXE) + " --robot " + SourcePath("config/kr210.yaml") + " --postures " +
                    postures + " --measured " + hammer + " --report " + dir + "/audit --write-config " + config +
                    " > " + dir + "/effects.yaml 2> " + dir + "/audit.log"),
            0);
  // The config loads as every tool loads it, with the named effect in it.
  const io::RobotConfig written = io::LoadRobotConfig(config);
  ASSERT_EQ(written.description.effects.size(), 1u);
  EXPECT_EQ(written.description.effects[0].name, "spindle_interface");
  // The summary and the report say where it is.
  std::ifstream sj(dir + "/audit/summary.json");
  const nlohmann::json summary = nlohmann::json::parse(sj);
  EXPECT_EQ(summary["written_config"], config);
  EXPECT_EQ(summary["verdict"]["grade"], "explained");

  // frf-predict with the written config on the measured grid.
  const std::string predicted = dir + "/pred.csv";
  ASSERT_EQ(RunTool(std::string(FRF_PREDICT_EXE) + " --robot " + config + " --postures " + postures +
                    " --fmin-hz 0.25 --fmax-hz 500 --df-hz 0.25 --directions xx,yy --out " + predicted + " 2> " +
                    dir + "/predict.log"),
            0);
  const dynamics::FrfSet read = io::ReadFrfCsv(hammer).frfs;
  const dynamics::FrfSet measured = calibration::UsableData(read, calibration::EstimateNoise(read, {}));
  const dynamics::FrfSet model = io::ReadFrfCsv(predicted).frfs;
  double sum = 0.0;
  long lines = 0;
  for (const auto& [key, m] : measured) {
    ASSERT_TRUE(model.contains(key)) << key.ToString();
    const dynamics::Frf& p = model.at(key);
    const Eigen::VectorXd w = calibration::LogResidualWeights(m);
    std::map<long long, int> at;  // predicted line by frequency in mHz
    for (int i = 0; i < p.size(); ++i) at[std::llround(p.freq_hz()(i) * 1e3)] = i;
    for (int i = 0; i < m.size(); ++i) {
      const auto it = at.find(std::llround(m.freq_hz()(i) * 1e3));
      ASSERT_NE(it, at.end()) << m.freq_hz()(i);
      const double r = w(i) * (std::log(std::abs(p.receptance()(it->second))) - std::log(std::abs(m.receptance()(i))));
      sum += r * r;
      ++lines;
    }
  }
  const double error = std::sqrt(sum / static_cast<double>(lines));
  std::cout << "frf-predict with the written config: " << error << " x the noise over " << lines << " lines\n";
  EXPECT_LE(error, 1.3);
  // And the config with effects.yaml appended, as the docs also allow.
  {
    std::ifstream base(SourcePath("config/kr210.yaml")), yaml(dir + "/effects.yaml");
    std::stringstream text;
    text << base.rdbuf() << "\n" << yaml.rdbuf();
    std::string t = text.str();
    // The copy lives in another folder: its URDF path must be absolute.
    const std::string urdf = "urdf: kr210_r2700_2.urdf";
    t.replace(t.find(urdf), urdf.size(), "urdf: " + SourcePath("config/kr210_r2700_2.urdf"));
    std::ofstream(dir + "/appended.yaml") << t;
    const io::RobotConfig appended = io::LoadRobotConfig(dir + "/appended.yaml");
    for (const auto& s : written.parameters.specs()) {
      EXPECT_NEAR(appended.parameters.Get(s.name), written.parameters.Get(s.name),
                  1e-5 * std::abs(written.parameters.Get(s.name)))
          << s.name;  // effects.yaml has 6 significant digits
    }
  }
}

// The loop's last step as docs/model-audit.md and docs/python.md show it:
// frf-calibrate with the effect the audit named, its two scales free, on the
// demo data. Reference: the values the data were made with (frf-synth;
// docs/model-audit.md). Each estimate within 3 standard deviations of its
// truth and the misfit at the noise (rms 1 when sigma is right; 1.3 as
// AuditOptions::explained_factor). It failed (tilting_scale 1e4 at its
// bound, 111 x the noise) when the features came from the common-pole
// fitter (FitOneFrf, which also reports the weak neighbour-direction modes
// of each FRF: Hyy's 35.5 Hz mode of the x direction) and the whole-curve
// polish started only from the modal stage's result, in the bound's basin.
// Calibrate now also polishes from the start values when the result is
// still doubtful (one fitter for every tool, issue #34).
TEST(AuditLoop, CalibratingTheNamedEffectRecoversTheValuesTheDemoWasMadeWith) {
  const std::string dir = robomach::testing::TempDir("audit_loop_calibrate");
  ASSERT_EQ(RunTool(std::string(FRF_CALIBRATE_EXE) + " --robot " + SourcePath("config/kr210.yaml") + " --postures " +
                    SourcePath("config/demo/postures.csv") + " --measured " + SourcePath("config/demo/hammer.csv") +
                    " --add spindle_interface --free spindle_interface.tilting_scale"
                    " --free spindle_interface.translational_scale --out " +
                    dir + "/calibrated.yaml --report " + dir + "/report 2> " + dir + "/calibrate.log"),
            0);
  std::ifstream sj(dir + "/report/summary.json");
  const nlohmann::json summary = nlohmann::json::parse(sj);
  EXPECT_EQ(summary["status"], "converged");
  const std::map<std::string, double> truth = {{"m6_kg", 31.0},
                                               {"d6_m", 0.53},
                                               {"alpha_s", 1.2e-4},
                                               {"beta_per_s", 4.3},
                                               {"spindle_interface.tilting_scale", 10.0},
                                               {"spindle_interface.translational_scale", 1.5}};
  ASSERT_EQ(summary["parameters"].size(), truth.size());
  for (const auto& p : summary["parameters"]) {
    const std::string name = p["name"];
    ASSERT_TRUE(truth.count(name)) << name;
    const double value = p["value"], sd = p["std_dev"];
    EXPECT_LT(std::abs(value - truth.at(name)), 3.0 * sd) << name << " = " << value << " +- " << sd;
  }
  EXPECT_LE(static_cast<double>(summary["misfit"]["rms_per_residual_in_noise_units"]), 1.3);
}

}  // namespace
}  // namespace robomach
