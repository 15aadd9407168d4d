// Speed of the stability module (issue #6 targets): ZOA lobes for one
// posture with 400 speeds (< 20 ms), and a 100 × 100 map with 200 speeds
// per point (< 10 s on 2 cores; issue #23: 1 s).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <thread>

#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/region_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/stability/tool_tip_model.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/stability/lobe_uncertainty.h"
#include "robomach/stability/mode_coupling.h"
#include "robomach/stability/posture_stability.h"
#include "robomach/stability/semi_discretization.h"
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
  // How many eigensolves the mode-coupling depth search took at this posture.
  const dynamics::PostureDynamics d = ev.Evaluate(s.postures[0].q, dynamics::PostureOptions{false, true});
  const stability::PostureStability ps = stability::AnalysePosture(
      d, stability::CuttingFrameAtPosture(d.X_BT, s.cut.feed_direction_B), s.cut.process, opt);
  state.counters["mc_evals"] = ps.mode_coupling.evaluations;
  state.counters["mc_depth_mm"] = 1e3 * ps.mode_coupling.critical_depth;
}
BENCHMARK(BM_AnalysePosture200Speeds)->Unit(benchmark::kMicrosecond);

// The mode-coupling depth search alone at one posture (the modal path a
// map takes): its eigensolves are the largest part of a map point.
void BM_ModeCouplingSearchOnePosture(benchmark::State& state) {
  const Setup s;
  dynamics::PostureEvaluator ev(s.model);
  const dynamics::PostureDynamics d = ev.Evaluate(s.postures[0].q, dynamics::PostureOptions{false, true});
  const Eigen::Matrix3d R = stability::CuttingFrameAtPosture(d.X_BT, s.cut.feed_direction_B);
  const Eigen::Matrix3d Kc_B = R * stability::CuttingStiffnessPerDepth(s.cut.process) * R.transpose();
  const stability::TipModalModel modes = stability::ModalModelFromPosture(d);
  stability::ModeCouplingResult r;
  for (auto _ : state) {
    r = stability::CriticalDepthModeCouplingModal(modes, Kc_B, {});
    benchmark::DoNotOptimize(r);
  }
  state.counters["evals"] = r.evaluations;
  state.counters["depth_mm"] = 1e3 * r.critical_depth;
}
BENCHMARK(BM_ModeCouplingSearchOnePosture)->Unit(benchmark::kMicrosecond);

// The 100 × 100 map over the demo region (500 mm × 500 mm, 5.05 mm
// step), 200 speeds per point, all cores.
struct Map100x100 {
  io::RegionSpec region;
  std::vector<stability::ToolPoseTarget> targets;
  stability::MapOptions opt;
  explicit Map100x100(const Setup& s) : region(io::ReadRegionFile(Src("config/region_demo.yaml"), 6)) {
    region.size_u = region.size_v = 0.5;
    region.grid_step = 0.5 / 99.0;
    targets = region.Targets(s.cut.feed_direction_B);
    opt.seed_q = region.seed_q;
    opt.rotation = region.rotation_fixed;
    opt.analysis.spindle_speed_rad_s =
        Eigen::VectorXd::LinSpaced(200, s.cut.spindle_speed_min_rad_s, s.cut.spindle_speed_max_rad_s);
  }
};

void BM_Map100x100(benchmark::State& state) {
  const Setup s;
  const Map100x100 m(s);
  const auto& region = m.region;
  const auto& targets = m.targets;
  const auto& opt = m.opt;
  double evals = 0.0, analysed = 0.0;
  for (auto _ : state) {
    const auto pts = stability::EvaluateStabilityMap(s.model, targets, region.num_v(), region.num_u(),
                                                     s.cut.process, opt);
    benchmark::DoNotOptimize(pts.data());
    evals = analysed = 0.0;
    for (const auto& p : pts) {
      if (p.stability.mode_coupling.evaluations > 0) {
        evals += p.stability.mode_coupling.evaluations;
        analysed += 1.0;
      }
    }
  }
  state.counters["mc_evals_per_point"] = analysed > 0.0 ? evals / analysed : 0.0;
  state.counters["points"] = static_cast<double>(targets.size());
  state.counters["threads"] = std::thread::hardware_concurrency();
}
BENCHMARK(BM_Map100x100)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime()
    ->ComputeStatistics("min", [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); });

// Issue #37: the same map's safe depth, first order, with the uncertainty of
// the shipped kq-identify campaign fixture (six joint stiffnesses, full
// covariance), as stability-map --uncertainty runs it: the map of the
// estimates (dynamics::UseEstimates), then the intervals (LocalCriticalDepth
// per point: the local model at the estimates and one forward step per
// principal axis, 7 evaluations). Target: at most 3 x BM_Map100x100.
void BM_Map100x100SafeDepthFirstOrder(benchmark::State& state) {
  const Setup s;
  io::RobotConfig cfg = io::LoadRobotConfig(Src("config/kr210.yaml"));
  const dynamics::ParameterUncertainty u = io::ReadParameterUncertainty(Src("tests/data/uncertainty/kq_demo.yaml"));
  dynamics::UseEstimates(u, &cfg.parameters);
  const auto model = cfg.Build();
  const Map100x100 m(s);
  const auto& region = m.region;
  const auto& targets = m.targets;
  const auto& opt = m.opt;
  dynamics::PropagationOptions po;
  po.method = dynamics::PropagationMethod::kFirstOrder;
  for (auto _ : state) {
    const auto pts = stability::EvaluateStabilityMap(model, targets, region.num_v(), region.num_u(),
                                                     s.cut.process, opt);
    const auto iv = stability::StabilityMapIntervals(cfg.description, cfg.parameters, targets, pts, s.cut.process,
                                                     opt.analysis, u, po);
    benchmark::DoNotOptimize(iv.depth.data());
    state.counters["local_model_points"] = iv.local_model;
    state.counters["first_order_points"] = iv.first_order;
  }
}
BENCHMARK(BM_Map100x100SafeDepthFirstOrder)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// Semi-discretization lobes on the Insperger-Stepan 2004 benchmark (1 DOF,
// 922 Hz, 2 teeth) as `stability-lobes --method sd` runs them by default:
// 60 speeds over 5000-25000 rpm, depth search up to 20 mm, one thread.
// Arg(0): 0 = the automatic steps per tooth period (issue #10; 40 per
// period of the mode, at least 40), 30 = the old fixed default; Arg(1):
// radial immersion in percent.
void BM_SdLobesInspergerStepan60Speeds(benchmark::State& state) {
  stability::TipModalModel m;
  m.omega_rad_s = Eigen::VectorXd::Constant(1, HzToRadPerSec(922.0));
  m.zeta = Eigen::VectorXd::Constant(1, 0.011);
  m.p = Matrix3Xd::Zero(3, 1);
  m.p(0, 0) = 1.0 / std::sqrt(0.03993);
  stability::MillingProcess p;
  p.teeth = 2;
  p.radial_immersion = state.range(1) / 100.0;
  p.direction = stability::MillingDirection::kDown;
  p.coefficients = {6e8, 2e8, 0.0};
  stability::SdOptions o;
  o.steps_per_period = static_cast<int>(state.range(0));
  o.max_depth = 0.02;
  const Eigen::VectorXd speeds = Eigen::VectorXd::LinSpaced(60, RpmToRadPerSec(5000.0), RpmToRadPerSec(25000.0));
  for (auto _ : state) {
    benchmark::DoNotOptimize(stability::SdLobes(m, p, speeds, o, 1).data());
  }
}
BENCHMARK(BM_SdLobesInspergerStepan60Speeds)
    ->Args({30, 100})
    ->Args({0, 100})
    ->Args({30, 5})
    ->Args({0, 5})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

// The same for the demo posture P1 of the KR210 (3 dominant modes of the
// robot model, config/cut_demo.yaml: 4 teeth, 6000-24000 rpm), as in
// `stability-lobes --robot ... --method sd`: 60 speeds, one thread.
void BM_SdLobesKr210Posture60Speeds(benchmark::State& state) {
  const Setup s;
  dynamics::PostureEvaluator ev(s.model);
  const dynamics::PostureDynamics d = ev.Evaluate(s.postures[0].q);
  const Eigen::Matrix3d R = stability::CuttingFrameAtPosture(d.X_BT, s.cut.feed_direction_B);
  const auto modes = stability::DominantModes(stability::ModalModelFromPosture(d).Rotated(R), 3);
  stability::SdOptions o;
  o.steps_per_period = static_cast<int>(state.range(0));
  const Eigen::VectorXd speeds =
      Eigen::VectorXd::LinSpaced(60, s.cut.spindle_speed_min_rad_s, s.cut.spindle_speed_max_rad_s);
  for (auto _ : state) {
    benchmark::DoNotOptimize(stability::SdLobes(modes, s.cut.process, speeds, o, 1).data());
  }
  state.counters["steps_at_min_speed"] =
      stability::SdStepsPerPeriod(modes, s.cut.process, s.cut.spindle_speed_min_rad_s, o);
}
BENCHMARK(BM_SdLobesKr210Posture60Speeds)->Arg(30)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(3);

// The SD of a measured tap test as `stability-lobes --frf --method sd
// --threads 1` runs it (issue #34: 30 s of its 44 s): the modes of
// tests/tap_test_synth.h (1074, 1961, 2617 Hz, zeta 0.03, modal masses
// 0.439, 0.198, 0.185 kg) fitted along x and y of a symmetric tool (6 modes,
// automatic steps: capped at a 400-row monodromy matrix), the cut of
// tests/data/stability/cut_tap_lobe0.yaml (4 teeth, a/D 0.5, down-milling,
// Ktc 1800, Krc 650 N/mm^2), 60 speeds over 22000-32000 rpm, one thread.
void BM_SdLobesTapTest60Speeds(benchmark::State& state) {
  const double f[3] = {1074.0, 1961.0, 2617.0}, mass[3] = {0.4393, 0.1976, 0.1850};
  stability::TipModalModel m;
  m.omega_rad_s.resize(6);
  m.zeta = Eigen::VectorXd::Constant(6, 0.03);
  m.p = Matrix3Xd::Zero(3, 6);
  for (int d = 0; d < 2; ++d) {
    for (int k = 0; k < 3; ++k) {
      m.omega_rad_s(3 * d + k) = HzToRadPerSec(f[k]);
      m.p(d, 3 * d + k) = 1.0 / std::sqrt(mass[k]);
    }
  }
  stability::MillingProcess p;
  p.teeth = 4;
  p.radial_immersion = 0.5;
  p.direction = stability::MillingDirection::kDown;
  p.coefficients = {1800e6, 650e6, 300e6};
  const stability::SdOptions o;
  const Eigen::VectorXd speeds = Eigen::VectorXd::LinSpaced(60, RpmToRadPerSec(22000.0), RpmToRadPerSec(32000.0));
  for (auto _ : state) {
    benchmark::DoNotOptimize(stability::SdLobes(m, p, speeds, o, 1).data());
  }
  state.counters["steps_at_min_speed"] = stability::SdStepsPerPeriod(m, p, speeds(0), o);
}
BENCHMARK(BM_SdLobesTapTest60Speeds)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
