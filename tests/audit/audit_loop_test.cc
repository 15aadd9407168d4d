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

}  // namespace
}  // namespace robomach
