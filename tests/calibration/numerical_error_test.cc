// Issue #22, item 5: the fit's residual code treats a NumericalError at a
// trial point as an infeasible point (Ceres shortens the step), and lets any
// other exception (a bug, bad input) out of Calibrate instead of turning it
// into "step rejected".
//
// A test-only effect scales the joint stiffness; above a threshold it throws,
// as a numerical failure or as a programming error. The data come from the
// same model at a scale beyond the threshold, so the fit must try points
// there.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/errors.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::calibration {
namespace {

enum class Fault { kNone, kNumerical, kBug };
Fault g_fault = Fault::kNone;
constexpr double kThreshold = 1.2;  // scales above this throw g_fault

class FaultyStiffnessEffect final : public dynamics::Effect {
 public:
  std::string name() const override { return "test_faulty_stiffness"; }
  std::string description() const override { return "test only: joint stiffness times a scale"; }
  std::vector<dynamics::ParameterSpec> parameters() const override {
    return {{"scale", "1", 1.0, 0.5, 4.0, true, "joint stiffness factor"}};
  }
  void Contribute(const dynamics::EffectContext& ctx, std::span<const double> values, int,
                  dynamics::AssembledSystem* sys) const override {
    if (values[0] > kThreshold) {
      if (g_fault == Fault::kNumerical) throw NumericalError("test: not positive definite above the threshold");
      if (g_fault == Fault::kBug) throw std::logic_error("test: a programming error above the threshold");
    }
    const int n = ctx.model.num_joints();
    sys->K.topLeftCorner(n, n) *= values[0];
  }
};

struct FaultSetup {
  dynamics::RobotDescription desc;
  dynamics::ParameterSet start;
  PostureMap postures;
  dynamics::FrfSet measured;
};

FaultSetup MakeSetup() {
  static const bool registered = [] {
    dynamics::EffectRegistry::Instance().Register([] { return std::make_shared<const FaultyStiffnessEffect>(); });
    return true;
  }();
  (void)registered;
  io::RobotConfig cfg = io::LoadRobotConfig(testing::SourcePath("config/kr210.yaml"));
  FaultSetup s;
  s.desc = cfg.description;
  s.desc.effects.push_back({"test_faulty_stiffness", {}});
  s.start = dynamics::DefaultParameters(s.desc);
  for (const auto& spec : cfg.parameters.specs()) s.start.Set(spec.name, cfg.parameters.Get(spec.name));
  const io::Posture p = io::ReadPostureFile(testing::SourcePath("config/postures_demo.csv"), 6).front();
  s.postures[p.id] = p.q;
  dynamics::ParameterSet truth = s.start;
  truth.Set("test_faulty_stiffness.scale", 1.5);
  g_fault = Fault::kNone;
  VirtualHammerOptions o;  // noise-free, xx and yy
  o.fmin_hz = 5.0;
  o.fmax_hz = 60.0;
  s.measured = SynthesizeHammerTest(dynamics::RobotModel::Build(s.desc, truth), {{p.id, p.q}}, o);
  return s;
}

CalibrationOptions Options() {
  CalibrationOptions o;
  o.objective = Objective::kWholeCurve;
  o.free_parameters = {"test_faulty_stiffness.scale"};
  o.extra_starts = false;
  o.max_iterations = 30;
  return o;
}

// Without faults the fit reaches the truth: the trial points do cross the
// threshold, so the two tests below exercise the catch.
TEST(NumericalErrorInFit, ReferenceFitCrossesTheThreshold) {
  const FaultSetup s = MakeSetup();
  g_fault = Fault::kNone;
  const CalibrationResult r = Calibrate(s.desc, s.start, s.postures, s.measured, {}, Options());
  // Noise-free data from the same model: 1e-3 is far looser than the
  // fit's tolerance and far tighter than the threshold's distance (0.3).
  EXPECT_NEAR(r.parameters.Get("test_faulty_stiffness.scale"), 1.5, 1e-3) << r.message;
}

TEST(NumericalErrorInFit, NumericalTroubleAtTrialPointsIsNotAnException) {
  const FaultSetup s = MakeSetup();
  g_fault = Fault::kNumerical;
  CalibrationResult r;
  ASSERT_NO_THROW(r = Calibrate(s.desc, s.start, s.postures, s.measured, {}, Options()));
  EXPECT_LE(r.parameters.Get("test_faulty_stiffness.scale"), kThreshold);
  dynamics::ParameterSet beyond = s.start;
  beyond.Set("test_faulty_stiffness.scale", 1.5);
  EXPECT_EQ(WholeCurveMisfit(s.desc, beyond, s.postures, s.measured, 0.0, 1e9),
            std::numeric_limits<double>::infinity());
  g_fault = Fault::kNone;
}

TEST(NumericalErrorInFit, ProgrammingErrorPropagates) {
  const FaultSetup s = MakeSetup();
  g_fault = Fault::kBug;
  EXPECT_THROW(Calibrate(s.desc, s.start, s.postures, s.measured, {}, Options()), std::logic_error);
  dynamics::ParameterSet beyond = s.start;
  beyond.Set("test_faulty_stiffness.scale", 1.5);
  EXPECT_THROW(WholeCurveMisfit(s.desc, beyond, s.postures, s.measured, 0.0, 1e9), std::logic_error);
  g_fault = Fault::kNone;
}

}  // namespace
}  // namespace robomach::calibration
