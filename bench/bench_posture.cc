// Speed of the foundation. Issue #2 targets on this 2-core machine: one
// posture's evaluation (M_q, J, modes) <= 10 µs, a 2000-line modal FRF
// <= 100 µs, and a 10,000-posture batch. Issue #23 (against a C++ program on
// Pinocchio 4.1, same model and work): MqJModes at P1 <= 3.2 µs (Pinocchio
// 3.17 µs; 4.45 µs with every other output, MqJModesAllOutputs here), the
// 2000-line 3×3 modal FRF <= 30 µs (Pinocchio 30.5 µs).
//
// Measure on a shared machine with
//   bench_posture --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
// and quote the median and min (the CPU column) with the load (uptime).
#include <benchmark/benchmark.h>

#include <random>

#include <Eigen/Eigenvalues>

#include "dynamics/internal/modal_sum.h"
#include "dynamics/internal/rigid_chain.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/robot_config.h"

namespace {

using namespace robomach;

std::shared_ptr<const dynamics::RobotModel> Model() {
  static const auto model =
      io::LoadRobotConfig(std::string(ROBOMACH_SOURCE_DIR) + "/config/kr210.yaml").Build();
  return model;
}

Eigen::VectorXd P1() {
  Eigen::VectorXd q(6);
  q << 0.0, -1.5707963, 1.5707963, 0.0, 0.7853982, 0.0;
  return q;
}

// What the peer computes: CRBA, kinematics and the tool-tip Jacobian, the
// 6×6 modes; into a reused PostureDynamics (no allocation).
void BM_EvaluatePosture_MqJModes(benchmark::State& state) {
  dynamics::PostureEvaluator ev(Model());
  dynamics::PostureOptions opts;
  opts.cartesian = false;
  opts.jacobian_condition = false;
  opts.static_compliance = false;
  opts.modal_masses = false;
  opts.damping_ratios = false;
  const Eigen::VectorXd q = P1();
  dynamics::PostureDynamics d;
  for (auto _ : state) {
    ev.Evaluate(q, opts, &d);
    benchmark::DoNotOptimize(d.modes.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_EvaluatePosture_MqJModes);

// The same plus every other output MqJModes gave before issue #23: pose,
// cond J, static compliance, modal masses, damping ratios (not Cartesian).
void BM_EvaluatePosture_MqJModesAllOutputs(benchmark::State& state) {
  dynamics::PostureEvaluator ev(Model());
  const dynamics::PostureOptions opts{.cartesian = false, .modes = true};
  const Eigen::VectorXd q = P1();
  dynamics::PostureDynamics d;
  for (auto _ : state) {
    ev.Evaluate(q, opts, &d);
    benchmark::DoNotOptimize(d.modes.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_EvaluatePosture_MqJModesAllOutputs);

// The call BM_EvaluatePosture_MqJModes made before issue #23 (a new
// PostureDynamics per posture), for comparison with earlier figures.
void BM_EvaluatePosture_MqJModesByValue(benchmark::State& state) {
  dynamics::PostureEvaluator ev(Model());
  const dynamics::PostureOptions opts{.cartesian = false, .modes = true};
  const Eigen::VectorXd q = P1();
  for (auto _ : state) benchmark::DoNotOptimize(ev.Evaluate(q, opts));
}
BENCHMARK(BM_EvaluatePosture_MqJModesByValue);

void BM_EvaluatePosture_Everything(benchmark::State& state) {
  dynamics::PostureEvaluator ev(Model());
  const Eigen::VectorXd q = P1();
  for (auto _ : state) benchmark::DoNotOptimize(ev.Evaluate(q));
}
BENCHMARK(BM_EvaluatePosture_Everything);

// Where MqJModes' time goes (the peer: CRBA 0.47 µs, kinematics and Jacobian
// 0.83 µs, eigensolve 2.1 µs, 1.6 µs as one standard symmetric problem).
void BM_Breakdown_PoseJacobianMassMatrix(benchmark::State& state) {
  dynamics::internal::RigidChain rc(Model()->chain().kdl());
  const Eigen::VectorXd q = P1();
  Eigen::Isometry3d X;
  Matrix6Xd J(6, 6);
  Eigen::MatrixXd M(6, 6);
  for (auto _ : state) {
    rc.Compute(q.data(), &X, J, M);
    benchmark::DoNotOptimize(M.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Breakdown_PoseJacobianMassMatrix);

void BM_Breakdown_ReducedEigensolve(benchmark::State& state) {
  const auto d = dynamics::EvaluatePosture(Model(), P1());
  const Vector6d s = d.system.K.diagonal().cwiseSqrt().cwiseInverse();
  const Matrix6d A = s.asDiagonal() * d.system.M * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Matrix6d> es;
  for (auto _ : state) {
    es.compute(A, Eigen::ComputeEigenvectors);
    benchmark::DoNotOptimize(es.eigenvectors().data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Breakdown_ReducedEigensolve);

// A new result vector per call (what callers of ReceptanceModal get).
void BM_ModalFrf2000Lines(benchmark::State& state) {
  const auto d = dynamics::EvaluatePosture(Model(), P1());
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0);
  state.SetLabel(dynamics::internal::ModalSumUsesAvx2() ? "avx2" : "baseline");
  for (auto _ : state) benchmark::DoNotOptimize(dynamics::ReceptanceModal(d, f));
}
BENCHMARK(BM_ModalFrf2000Lines);

// Into a reused vector: the modal sum alone.
void BM_ModalFrf2000Lines_Reused(benchmark::State& state) {
  const auto d = dynamics::EvaluatePosture(Model(), P1());
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0);
  std::vector<Eigen::Matrix3cd> H;
  state.SetLabel(dynamics::internal::ModalSumUsesAvx2() ? "avx2" : "baseline");
  for (auto _ : state) {
    dynamics::ReceptanceModal(d, f, &H);
    benchmark::DoNotOptimize(H.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ModalFrf2000Lines_Reused);

// The kernel at the x86-64 baseline (SSE2), as on a CPU without AVX2.
void BM_ModalFrf2000Lines_BaselineKernel(benchmark::State& state) {
  const auto d = dynamics::EvaluatePosture(Model(), P1());
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0);
  const int nm = static_cast<int>(d.modes.size());
  std::vector<double> w2(nm), c(nm), P(6 * nm);
  dynamics::internal::PackModes(d.modes, w2.data(), c.data(), P.data());
  std::vector<Eigen::Matrix3cd> H(f.size());
  for (auto _ : state) {
    dynamics::internal::RealModalSum(nm, w2.data(), c.data(), P.data(), f.data(), f.size(),
                                     reinterpret_cast<std::complex<double>*>(H.data()),
                                     dynamics::internal::SimdLevel::kBaseline);
    benchmark::DoNotOptimize(H.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ModalFrf2000Lines_BaselineKernel);

void BM_DirectFrf2000Lines(benchmark::State& state) {
  const auto d = dynamics::EvaluatePosture(Model(), P1());
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0);
  for (auto _ : state) benchmark::DoNotOptimize(dynamics::ReceptanceDirect(d.system, f));
}
BENCHMARK(BM_DirectFrf2000Lines);

void BM_Batch10000Postures(benchmark::State& state) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::VectorXd> qs(10000);
  for (auto& q : qs) {
    q = P1();
    for (int j = 0; j < 6; ++j) q(j) += 0.5 * u(rng);
  }
  dynamics::PostureEvaluator ev(Model());
  for (auto _ : state) {
    for (const auto& q : qs) benchmark::DoNotOptimize(ev.Evaluate(q));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(qs.size()));
}
BENCHMARK(BM_Batch10000Postures)->Unit(benchmark::kMillisecond);

// The same batch into one reused PostureDynamics.
void BM_Batch10000Postures_Reused(benchmark::State& state) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::VectorXd> qs(10000);
  for (auto& q : qs) {
    q = P1();
    for (int j = 0; j < 6; ++j) q(j) += 0.5 * u(rng);
  }
  dynamics::PostureEvaluator ev(Model());
  dynamics::PostureDynamics d;
  for (auto _ : state) {
    for (const auto& q : qs) {
      ev.Evaluate(q, {}, &d);
      benchmark::DoNotOptimize(d.modes.data());
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(qs.size()));
}
BENCHMARK(BM_Batch10000Postures_Reused)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
