// common's ParallelFor (issue #21 item 3, issue #23 item 3):
// - a batch of 10,000 postures on 1 and 2 threads (the target: the
//   2-thread rate at least 1.8x the 1-thread rate), one model copy and one
//   PostureEvaluator per thread (KDL joints cache their last pose);
// - the cost of one call with an empty body: threads started per call (what
//   ParallelFor does) against a fixed pool woken by a condition variable
//   (written here only to compare), to choose between the two.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <random>
#include <thread>

#include "robomach/common/parallel.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/io/robot_config.h"

namespace {

using namespace robomach;

double Min(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

std::shared_ptr<const dynamics::RobotModel> Model() {
  static const auto model =
      io::LoadRobotConfig(std::string(ROBOMACH_SOURCE_DIR) + "/config/kr210.yaml").Build();
  return model;
}

// The postures of bench_posture's BM_Batch10000Postures: P1 ± 0.5 rad.
std::vector<Eigen::VectorXd> Postures() {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::VectorXd> qs(10000);
  for (auto& q : qs) {
    q.resize(6);
    q << 0.0, -1.5707963, 1.5707963, 0.0, 0.7853982, 0.0;
    for (int j = 0; j < 6; ++j) q(j) += 0.5 * u(rng);
  }
  return qs;
}

// Arg: threads. Everything of each posture (as BM_Batch10000Postures).
void BM_Batch10000PosturesThreads(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const auto qs = Postures();
  std::vector<std::unique_ptr<dynamics::PostureEvaluator>> evs;
  for (int t = 0; t < threads; ++t) {
    evs.push_back(std::make_unique<dynamics::PostureEvaluator>(
        dynamics::RobotModel::Build(Model()->description(), Model()->parameters())));
  }
  ParallelForOptions po;
  po.threads = threads;
  for (auto _ : state) {
    ParallelFor(0, static_cast<long>(qs.size()),
                [&](long i, int t) { benchmark::DoNotOptimize(evs[t]->Evaluate(qs[i])); }, po);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(qs.size()));
}
BENCHMARK(BM_Batch10000PosturesThreads)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->ComputeStatistics("min", Min);

// Arg: 1 = ParallelFor (threads per call), 0 = a fixed pool of one extra
// thread; both run two indices with an empty body on 2 threads.
class TinyPool {
 public:
  TinyPool() : worker_([this] { Loop(); }) {}
  ~TinyPool() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      stop_ = true;
    }
    cv_.notify_all();
    worker_.join();
  }
  void Run2(const std::function<void(int)>& f) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      job_ = &f;
      ++generation_;
      busy_ = true;
    }
    cv_.notify_all();
    f(0);
    std::unique_lock<std::mutex> lock(mu_);
    done_cv_.wait(lock, [&] { return !busy_; });
  }

 private:
  void Loop() {
    long seen = 0;
    std::unique_lock<std::mutex> lock(mu_);
    for (;;) {
      cv_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      const auto* f = job_;
      lock.unlock();
      (*f)(1);
      lock.lock();
      busy_ = false;
      done_cv_.notify_all();
    }
  }
  std::mutex mu_;
  std::condition_variable cv_, done_cv_;
  const std::function<void(int)>* job_{nullptr};
  long generation_{0};
  bool busy_{false}, stop_{false};
  std::thread worker_;
};

void BM_ParallelForCallOverhead(benchmark::State& state) {
  std::atomic<long> sink{0};
  if (state.range(0) == 1) {
    ParallelForOptions po;
    po.threads = 2;
    for (auto _ : state) ParallelFor(0, 2, [&](long i, int) { sink += i; }, po);
  } else {
    TinyPool pool;
    const std::function<void(int)> f = [&](int i) { sink += i; };
    for (auto _ : state) pool.Run2(f);
  }
  benchmark::DoNotOptimize(sink.load());
}
BENCHMARK(BM_ParallelForCallOverhead)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond)->UseRealTime()->ComputeStatistics("min", Min);

}  // namespace

BENCHMARK_MAIN();
