// ParallelFor: every index once, the same results on 1 and N threads, and
// an exception of any thread reaches the caller (no std::terminate).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "robomach/common/parallel.h"

namespace robomach {
namespace {

// A deterministic per-index result that costs a little (so that threads
// really overlap): a partial sum of a series.
double Work(long i) {
  double s = 0.0;
  for (int k = 1; k <= 200; ++k) s += std::sin(static_cast<double>(i * k)) / k;
  return s;
}

TEST(ParallelFor, VisitsEveryIndexExactlyOnce) {
  for (int threads : {1, 2, 3, 8}) {
    for (long chunk : {0L, 1L, 7L, 1000L}) {
      const long begin = -5, end = 1234;
      std::vector<std::atomic<int>> visits(end - begin);
      std::mutex mu;
      std::set<int> thread_ids;
      ParallelForOptions o;
      o.threads = threads;
      o.chunk_size = chunk;
      ParallelFor(
          begin, end,
          [&](long i, int t) {
            ++visits[i - begin];
            std::lock_guard<std::mutex> lock(mu);
            thread_ids.insert(t);
          },
          o);
      for (long i = begin; i < end; ++i) {
        ASSERT_EQ(visits[i - begin].load(), 1) << "index " << i << ", " << threads << " threads, chunk " << chunk;
      }
      // Thread numbers are in [0, threads).
      EXPECT_GE(*thread_ids.begin(), 0);
      EXPECT_LT(*thread_ids.rbegin(), threads);
    }
  }
}

TEST(ParallelFor, ChunksCoverTheRangeInPiecesOfTheGivenSize) {
  std::mutex mu;
  std::vector<std::pair<long, long>> pieces;
  ParallelForOptions o;
  o.threads = 2;
  o.chunk_size = 10;
  ParallelForChunks(
      3, 48,
      [&](long first, long last, int) {
        std::lock_guard<std::mutex> lock(mu);
        pieces.emplace_back(first, last);
      },
      o);
  std::sort(pieces.begin(), pieces.end());
  const std::vector<std::pair<long, long>> expected{{3, 13}, {13, 23}, {23, 33}, {33, 43}, {43, 48}};
  EXPECT_EQ(pieces, expected);
}

TEST(ParallelFor, OneThreadAndManyThreadsGiveTheSameResults) {
  const long n = 5000;
  std::vector<double> one(n), many(n);
  ParallelForOptions o1;
  o1.threads = 1;
  ParallelFor(0, n, [&](long i, int) { one[i] = Work(i); }, o1);
  ParallelForOptions o4;
  o4.threads = 4;
  o4.chunk_size = 3;
  ParallelFor(0, n, [&](long i, int) { many[i] = Work(i); }, o4);
  // The same function of the same index: bit for bit equal.
  for (long i = 0; i < n; ++i) ASSERT_EQ(one[i], many[i]) << i;
  // And equal to a plain loop (the reference).
  for (long i = 0; i < n; i += 97) ASSERT_EQ(one[i], Work(i)) << i;
}

TEST(ParallelFor, AnExceptionOnIndexKReachesTheCaller) {
  for (int threads : {1, 2, 4}) {
    for (long k : {0L, 1L, 517L, 999L}) {
      std::atomic<long> calls{0};
      ParallelForOptions o;
      o.threads = threads;
      o.chunk_size = 4;
      try {
        ParallelFor(
            0, 1000,
            [&](long i, int) {
              ++calls;
              if (i == k) throw std::runtime_error("index " + std::to_string(i));
              Work(i);
            },
            o);
        ADD_FAILURE() << "no exception, " << threads << " threads, k = " << k;
      } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "index " + std::to_string(k));
      }
      // The others stop taking chunks: the whole range is not run after a
      // throw at the start (k = 0: at most the chunks already taken, one
      // per thread, 4 indices each).
      if (k == 0) EXPECT_LE(calls.load(), 4L * threads) << threads << " threads";
    }
  }
}

TEST(ParallelFor, OnlyTheFirstOfSeveralExceptionsIsRethrownAndAllThreadsStop) {
  // Every index throws; the caller gets one of them (a std::logic_error here,
  // whatever type), and ParallelFor returns only after every thread stopped:
  // the counter does not move after the return.
  std::atomic<long> calls{0};
  ParallelForOptions o;
  o.threads = 3;
  o.chunk_size = 1;
  EXPECT_THROW(ParallelFor(0, 100000,
                           [&](long, int) {
                             ++calls;
                             std::this_thread::sleep_for(std::chrono::microseconds(100));
                             throw std::logic_error("every index throws");
                           },
                           o),
               std::logic_error);
  const long after = calls.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(calls.load(), after);
  EXPECT_LE(after, 3);  // each thread throws on its first index, then stops
}

TEST(ParallelFor, ProgressIsCalledFromTheCallingThreadAndEndsAtTheTotal) {
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<std::pair<long, long>> reports;
  bool other_thread = false;
  ParallelForOptions o;
  o.threads = 2;
  o.chunk_size = 5;
  o.progress = [&](long done, long total) {
    if (std::this_thread::get_id() != caller) other_thread = true;
    reports.emplace_back(done, total);
  };
  ParallelFor(0, 200, [&](long, int) { std::this_thread::sleep_for(std::chrono::microseconds(500)); }, o);
  EXPECT_FALSE(other_thread);
  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(reports.back(), std::make_pair(200L, 200L));
  for (size_t j = 1; j < reports.size(); ++j) EXPECT_GE(reports[j].first, reports[j - 1].first);
}

TEST(ParallelFor, EmptyRangeCallsNothingAndBadOptionsAreRejected) {
  bool called = false;
  ParallelFor(5, 5, [&](long, int) { called = true; });
  ParallelFor(5, 2, [&](long, int) { called = true; });
  EXPECT_FALSE(called);
  ParallelForOptions o;
  o.threads = -1;
  try {
    ParallelFor(0, 3, [](long, int) {}, o);
    ADD_FAILURE() << "negative thread count accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("threads: expected >= 0"), std::string::npos) << e.what();
  }
  EXPECT_GE(ResolveThreadCount(0), 1);
  EXPECT_EQ(ResolveThreadCount(3), 3);
}

}  // namespace
}  // namespace robomach
