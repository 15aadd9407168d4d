// Issue #3: 1000 load cases identified in under 0.1 s. The timed region is
// IdentifyJointStiffness on cases already read: per-case kinematics (FK and
// Jacobian of the arm), the linear start, Ceres in log-stiffness, the
// covariance and the report.
#include <benchmark/benchmark.h>

#include "robomach/identification/campaign_synth.h"
#include "robomach/identification/joint_stiffness.h"
#include "robomach/identification/test_plan.h"
#include "robomach/io/robot_config.h"

namespace {

using namespace robomach;

struct Campaign {
  std::shared_ptr<const dynamics::RobotModel> model;
  std::vector<identification::LoadCase> cases;
};

// 500 postures × 2 rope directions × 1 mass = 1000 cases, seeded.
const Campaign& ThousandCases() {
  static const Campaign c = [] {
    Campaign out;
    out.model = io::LoadRobotConfig(std::string(ROBOMACH_SOURCE_DIR) + "/config/kr210.yaml").Build();
    identification::CampaignOptions o;
    o.masses_kg = {30.0};
    const auto qs = identification::CampaignPostures(*out.model, 500, o, 1);
    std::vector<std::string> ids;
    for (size_t p = 0; p < qs.size(); ++p) ids.push_back("P" + std::to_string(p + 1));
    out.cases = identification::ToLoadCases(
        identification::SimulateCampaign(*out.model, ids, qs, out.model->joint_stiffness(), o));
    return out;
  }();
  return c;
}

void BM_Identify1000Cases(benchmark::State& state) {
  const Campaign& c = ThousandCases();
  identification::IdentificationOptions o;
  if (state.range(0) == 1) o.loss = identification::RobustLoss::kCauchy;
  for (auto _ : state) {
    auto r = identification::IdentifyJointStiffness(*c.model, c.cases, o);
    benchmark::DoNotOptimize(r.joint_stiffness.data());
    if (r.status != identification::FitStatus::kConverged) state.SkipWithError("not converged");
  }
  state.counters["cases"] = static_cast<double>(c.cases.size());
}
BENCHMARK(BM_Identify1000Cases)->Arg(0)->Arg(1)->ArgName("robust")->Unit(benchmark::kMillisecond);

void BM_Plan12Postures(benchmark::State& state) {
  const Campaign& c = ThousandCases();
  identification::PlanOptions o;
  o.num_postures = 12;
  o.p_load_tip = Eigen::Vector3d(0.15, 0.0, 0.10);
  o.p_target_tip = Eigen::Vector3d(0.0, 0.12, 0.05);
  for (auto _ : state) {
    auto plan = identification::PlanLoadTests(*c.model, o);
    benchmark::DoNotOptimize(plan.log_det_information);
  }
}
BENCHMARK(BM_Plan12Postures)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
