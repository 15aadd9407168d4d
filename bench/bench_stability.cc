// Speed of the stability module (issue #6 targets): ZOA lobes for one
// posture with 400 speeds (< 20 ms), and a 100 × 100 map with 200 speeds
// per point (< 10 s on 2 cores).
#include <benchmark/benchmark.h>

#include <thread>

#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/region_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/stability/mode_coupling.h"
#include "robomach/stability/posture_stability.h"
#include "robomach/stability/stability_map.h"
#include "robomach/stability/tool_tip_model.h"
#include "robomach/stability/zoa_lobes.h"

namespace {

using namespace robomach;

std::string Src(const std::string& p) { return std::string(ROBOMACH_SOURCE_DIR) + "/" + p; }

struct Setup {
  std::shared_ptr<const dynamics::RobotModel> model = io::LoadRobotConfig(Src("config/kr210.yaml")).Build();
  io::CutSpec cut = io::ReadCutFile(Src("config/cut_demo.yaml"));
  std::vector<io::Posture> postures = io::ReadPostureFile(Src("config/postures_demo.csv"), 6);
};

// Everything after the posture is known: modes, the oriented FRF on the
// lobe grid, the ZOA curves and the envelope at 400 speeds.
void BM_ZoaLobesOnePosture400Speeds(benchmark::State& state) {
  const Setup s;
  dynamics::PostureEvaluator ev(s.model);
  const Eigen::VectorXd speeds =
      Eigen::VectorXd::LinSpaced(400, s.cut.spindle_speed_min_rad_s, s.cut.spindle_speed_max_rad_s);
  const int lines = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const dynamics::PostureDynamics d = ev.Evaluate(s.postures[0].q);
    const Eigen::Matrix3d R = stability::CuttingFrameAtPosture(d.X_BT, s.cut.feed_direction_B);
    const auto modes = stability::ModalModelFromPosture(d);
    const Eigen::VectorXd f =
        stability::LobeFrequencyGrid(modes, s.cut.process.teeth, s.cut.spindle_speed_max_rad_s, lines);
    const auto Phi = stability::OrientInCuttingPlane(dynamics::Receptance(d, f), R);
    stability::ZoaOptions zo;
    zo.min_spindle_speed_rad_s = s.cut.spindle_speed_min_rad_s;
    const auto lobes = stability::ComputeZoaLobes(f, Phi, s.cut.process, zo);
    benchmark::DoNotOptimize(lobes.At(speeds));
  }
}
BENCHMARK(BM_ZoaLobesOnePosture400Speeds)->Arg(1200)->Arg(4000)->Unit(benchmark::kMillisecond);

// One map point without IK: posture evaluation and both mechanisms.
void BM_AnalysePosture200Speeds(benchmark::State& state) {
  const Setup s;
  dynamics::PostureEvaluator ev(s.model);
  stability::PostureStabilityOptions opt;
  opt.spindle_speed_rad_s =
      Eigen::VectorXd::LinSpaced(200, s.cut.spindle_speed_min_rad_s, s.cut.spindle_speed_max_rad_s);
  for (auto _ : state) {
    const dynamics::PostureDynamics d = ev.Evaluate(s.postures[0].q, dynamics::PostureOptions{false, true});
    const Eigen::Matrix3d R = stability::CuttingFrameAtPosture(d.X_BT, s.cut.feed_direction_B);
    benchmark::DoNotOptimize(stability::AnalysePosture(d, R, s.cut.process, opt));
  }
}
BENCHMARK(BM_AnalysePosture200Speeds)->Unit(benchmark::kMicrosecond);

// The 100 × 100 map over the demo region (500 mm × 500 mm, 5.05 mm
// step), 200 speeds per point, all cores.
void BM_Map100x100(benchmark::State& state) {
  const Setup s;
  io::RegionSpec region = io::ReadRegionFile(Src("config/region_demo.yaml"), 6);
  region.size_u = region.size_v = 0.5;
  region.grid_step = 0.5 / 99.0;
  const auto targets = region.Targets(s.cut.feed_direction_B);
  stability::MapOptions opt;
  opt.seed_q = region.seed_q;
  opt.rotation = region.rotation_fixed;
  opt.analysis.spindle_speed_rad_s =
      Eigen::VectorXd::LinSpaced(200, s.cut.spindle_speed_min_rad_s, s.cut.spindle_speed_max_rad_s);
  for (auto _ : state) {
    const auto pts = stability::EvaluateStabilityMap(s.model, targets, region.num_v(), region.num_u(),
                                                     s.cut.process, opt);
    benchmark::DoNotOptimize(pts.data());
  }
  state.counters["points"] = static_cast<double>(targets.size());
  state.counters["threads"] = std::thread::hardware_concurrency();
}
BENCHMARK(BM_Map100x100)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
