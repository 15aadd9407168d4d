#pragma once
// The one parallel loop of the library (issue #21 item 3, issue #22 item 5):
// index ranges cut into chunks, taken by a set of threads in turn, and the
// first exception of any thread rethrown in the caller.

#include <functional>
#include <string>

#include "robomach/common/progress.h"

namespace robomach {

struct ParallelForOptions {
  /// Threads, the calling thread included; 0 = std::thread::hardware_concurrency()
  /// (at least 1). Never more threads than chunks are started.
  int threads{0};
  /// Indices per chunk; 0 = automatic: about 16 chunks per thread, so that
  /// uneven costs even out at the end. A chunk is the unit of work a thread
  /// takes at a time (one atomic increment); chunk c is [begin + c·chunk_size,
  /// begin + (c + 1)·chunk_size) ∩ [begin, end).
  long chunk_size{0};
  /// If set, called on the calling thread with (indices finished, total)
  /// about every 20 ms while the loop runs, and once with (total, total) at
  /// the end of a loop that did not throw.
  ProgressCallback progress;
  /// @throws OptionError naming the field, its value and the bound
  /// ("threads: expected >= 0 (0 = all cores), got -1"): threads >= 0,
  /// chunk_size >= 0.
  void Validate() const;
};

/// The thread count `threads` stands for (0 = hardware_concurrency, at least 1).
int ResolveThreadCount(int threads);

/// Calls body(first, last, thread) for the chunks of [begin, end), each chunk
/// exactly once. `thread` in [0, threads) names the thread running the call
/// (0 = the calling thread), so that a caller can keep one workspace per
/// thread; which chunk runs on which thread is not deterministic, so results
/// must depend only on the index (write result i into slot i).
///
/// Exceptions: the first exception thrown by any call is captured; from then
/// on no thread takes a new chunk (the chunks already running finish), and
/// once every thread has stopped it is rethrown in the caller. Nothing ever
/// calls std::terminate because a body threw.
///
/// Threads are started per call (std::thread) and joined before the return.
/// That costs about 0.1 ms per call on the loaded 2-core development
/// machine, against a few µs for a fixed pool (bench/bench_parallel.cc,
/// BM_ParallelForCallOverhead), but every caller in the library spends
/// milliseconds to seconds per call (map points, SD speeds, plan
/// evaluations, audit candidate fits, row formatting), so no global state is
/// worth it. A body may itself call ParallelFor (the threads multiply; no
/// pool to deadlock on).
/// @throws OptionError if the options are invalid (Validate's, its message
///   prefixed with "ParallelFor: ").
void ParallelForChunks(long begin, long end,
                       const std::function<void(long first, long last, int thread)>& body,
                       const ParallelForOptions& options = {});

/// ParallelForChunks calling body(i, thread) for every i of each chunk.
void ParallelFor(long begin, long end, const std::function<void(long i, int thread)>& body,
                 const ParallelForOptions& options = {});

}  // namespace robomach
