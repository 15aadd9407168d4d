// The default system against check values computed by an independent
// implementation (Pinocchio CRBA + SciPy generalized eigensolver) of exactly
// this model: tests/data/kr210_reference.yaml, `check_values`.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::SourcePath;

struct Reference {
  std::string pose;
  Eigen::VectorXd q;
  std::vector<double> freq_hz, tcp_m, compliance;
};

std::vector<Reference> LoadReference() {
  const YAML::Node root = YAML::LoadFile(SourcePath("tests/data/kr210_reference.yaml"));
  std::vector<Reference> out;
  for (const auto& kv : root["check_values"]) {
    Reference r;
    r.pose = kv.first.as<std::string>();
    const auto q_deg = root["postures_deg"][r.pose].as<std::vector<double>>();
    r.q.resize(6);
    for (int j = 0; j < 6; ++j) r.q(j) = DegToRad(q_deg[j]);
    r.freq_hz = kv.second["natural_frequencies_hz"].as<std::vector<double>>();
    r.tcp_m = kv.second["tcp_position_m"].as<std::vector<double>>();
    r.compliance = kv.second["static_compliance_xx_yy_zz_m_per_N"].as<std::vector<double>>();
    out.push_back(r);
  }
  return out;
}

std::shared_ptr<const RobotModel> DefaultModel(const std::string& config = "config/kr210.yaml") {
  io::RobotConfig cfg = io::LoadRobotConfig(SourcePath(config));
  return cfg.Build();
}

// The reference values carry 7 to 9 significant digits, so rounding alone is
// below 1e-7 relative; the issue asks for 1e-6 relative. The TCP position is
// compared absolutely (a zero coordinate has no relative error): its digits
// are 1e-9 m.
constexpr double kRelTol = 1e-6;
constexpr double kPosTol_m = 1e-8;

class Kr210Reference : public ::testing::TestWithParam<std::string> {};

TEST_P(Kr210Reference, ReproducesIndependentCheckValuesAtAllPostures) {
  const auto model = DefaultModel(GetParam());
  const auto refs = LoadReference();
  ASSERT_EQ(refs.size(), 5u);
  PostureEvaluator ev(model);
  for (const Reference& r : refs) {
    const PostureDynamics d = ev.Evaluate(r.q);
    ASSERT_EQ(d.modes.size(), r.freq_hz.size()) << r.pose;
    for (size_t k = 0; k < r.freq_hz.size(); ++k) {
      EXPECT_NEAR(d.modes[k].freq_hz, r.freq_hz[k], kRelTol * r.freq_hz[k])
          << r.pose << " mode " << k + 1;
    }
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(d.X_BT.translation()(a), r.tcp_m[a], kPosTol_m) << r.pose << " tcp " << a;
      EXPECT_NEAR(d.static_compliance(a, a), r.compliance[a], kRelTol * r.compliance[a])
          << r.pose << " compliance " << a;
    }
  }
}

// The same robot as a URDF and as a modified-DH table (config/kr210_dh.yaml)
// must give the same answers.
INSTANTIATE_TEST_SUITE_P(UrdfAndDh, Kr210Reference,
                         ::testing::Values("config/kr210.yaml", "config/kr210_dh.yaml"));

}  // namespace
}  // namespace robomach::dynamics
