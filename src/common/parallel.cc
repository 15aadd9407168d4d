#include "robomach/common/parallel.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "robomach/common/errors.h"

namespace robomach {

void ParallelForOptions::Validate() const {
  if (threads < 0) {
    throw OptionError("threads", "threads: expected >= 0 (0 = all cores), got " + std::to_string(threads));
  }
  if (chunk_size < 0) {
    throw OptionError("chunk_size", "chunk_size: expected >= 0 (0 = automatic), got " + std::to_string(chunk_size));
  }
}

int ResolveThreadCount(int threads) {
  if (threads > 0) return threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void ParallelForChunks(long begin, long end,
                       const std::function<void(long first, long last, int thread)>& body,
                       const ParallelForOptions& options) {
  try {
    options.Validate();
  } catch (const OptionError& e) {
    throw OptionError(e.field(), std::string("ParallelFor: ") + e.what());
  }
  if (end <= begin) return;
  const long n = end - begin;
  const int wanted = ResolveThreadCount(options.threads);
  // About 16 chunks per thread: the last chunks to finish are short enough
  // that uneven costs (unreachable map points, cheap audit candidates) even
  // out, and one atomic increment per chunk costs nothing against the body.
  const long chunk = options.chunk_size > 0 ? options.chunk_size : std::max(1L, n / (16L * wanted));
  const long chunks = (n + chunk - 1) / chunk;
  const int threads = static_cast<int>(std::min<long>(wanted, chunks));

  std::atomic<long> next_chunk{0}, done{0};
  std::atomic<bool> failed{false};
  std::mutex mu;  // guards error and finished
  std::condition_variable cv;
  std::exception_ptr error;
  int finished = 0;
  auto record = [&](std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mu);
    if (!error) error = std::move(e);
    failed = true;
  };
  using Clock = std::chrono::steady_clock;
  constexpr auto kProgressPeriod = std::chrono::milliseconds(20);
  Clock::time_point last_report = Clock::now();
  auto report = [&]() {  // calling thread only
    if (!options.progress || Clock::now() - last_report < kProgressPeriod) return;
    last_report = Clock::now();
    options.progress(done.load(), n);
  };
  auto run = [&](int t) {
    while (!failed.load(std::memory_order_relaxed)) {
      const long c = next_chunk.fetch_add(1);
      if (c >= chunks) break;
      const long first = begin + c * chunk, last = std::min(end, first + chunk);
      try {
        body(first, last, t);
        done += last - first;
        if (t == 0) report();
      } catch (...) {
        record(std::current_exception());
      }
    }
  };

  std::vector<std::thread> pool;
  pool.reserve(static_cast<size_t>(threads - 1));
  try {
    for (int t = 1; t < threads; ++t) {
      pool.emplace_back([&, t]() {
        run(t);
        std::lock_guard<std::mutex> lock(mu);
        ++finished;
        cv.notify_all();
      });
    }
  } catch (...) {
    // No thread could be started (std::system_error): the started ones and
    // the calling thread do the work; the error is not the body's.
  }
  run(0);
  if (options.progress) {
    // The calling thread keeps reporting while the others finish.
    std::unique_lock<std::mutex> lock(mu);
    const int others = static_cast<int>(pool.size());
    while (finished < others && !cv.wait_for(lock, kProgressPeriod, [&] { return finished == others; })) {
      if (failed) continue;
      lock.unlock();
      try {
        options.progress(done.load(), n);
      } catch (...) {
        record(std::current_exception());
      }
      lock.lock();
    }
  }
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
  if (options.progress) options.progress(n, n);
}

void ParallelFor(long begin, long end, const std::function<void(long i, int thread)>& body,
                 const ParallelForOptions& options) {
  ParallelForChunks(
      begin, end,
      [&body](long first, long last, int thread) {
        for (long i = first; i < last; ++i) body(i, thread);
      },
      options);
}

}  // namespace robomach
