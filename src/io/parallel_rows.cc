#include "robomach/io/parallel_rows.h"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "robomach/common/parallel.h"

namespace robomach::io {

void WriteRowsInParallel(std::ostream& out, long begin, long end,
                         const std::function<void(long, std::string*)>& format, int threads) {
  if (end <= begin) return;
  threads = std::max(1, std::min<int>(threads, static_cast<int>(end - begin)));
  // One contiguous stretch per thread, formatted into its own buffer.
  const long per = (end - begin + threads - 1) / threads;
  std::vector<std::string> buffers(static_cast<size_t>((end - begin + per - 1) / per));
  ParallelForOptions po;
  po.threads = threads;
  po.chunk_size = per;
  ParallelForChunks(
      begin, end,
      [&](long a, long b, int) {
        std::string& buffer = buffers[static_cast<size_t>((a - begin) / per)];
        buffer.reserve(static_cast<size_t>(b - a) * 300);
        for (long i = a; i < b; ++i) format(i, &buffer);
      },
      po);
  for (const auto& b : buffers) out.write(b.data(), static_cast<std::streamsize>(b.size()));
}

}  // namespace robomach::io

namespace robomach::io {

void WritePipelined(std::ostream& out, long rows, long chunk_rows, int slots,
                    const std::function<void(long, long, int)>& prepare,
                    const std::function<void(long, long, int, std::string*)>& format, int threads) {
  if (rows <= 0) return;
  chunk_rows = std::max(1L, chunk_rows);
  slots = std::max(1, slots);
  threads = std::max(1, threads);
  const long chunks = (rows + chunk_rows - 1) / chunk_rows;
  enum class State { kFree, kPrepared, kFormatting, kFormatted };
  std::vector<State> state(static_cast<size_t>(slots), State::kFree);
  std::vector<std::string> text(static_cast<size_t>(slots));  // kept between chunks: no new pages
  std::mutex mu;
  std::condition_variable cv;
  long next_prepare = 0, next_format = 0, next_write = 0;
  bool preparing = false, writing = false;
  std::exception_ptr error;
  auto first_of = [&](long c) { return c * chunk_rows; };
  auto last_of = [&](long c) { return std::min(rows, (c + 1) * chunk_rows); };
  auto slot_of = [&](long c) { return static_cast<int>(c % slots); };
  auto worker = [&] {
    std::unique_lock<std::mutex> lock(mu);
    while (!error && next_write < chunks) {
      try {
        if (!preparing && next_prepare < chunks && state[slot_of(next_prepare)] == State::kFree) {
          const long c = next_prepare;
          preparing = true;
          lock.unlock();
          prepare(first_of(c), last_of(c), slot_of(c));
          lock.lock();
          state[slot_of(c)] = State::kPrepared;
          ++next_prepare;
          preparing = false;
        } else if (!writing && state[slot_of(next_write)] == State::kFormatted) {
          const long c = next_write;
          writing = true;
          lock.unlock();
          std::string& t = text[slot_of(c)];
          out.write(t.data(), static_cast<std::streamsize>(t.size()));
          t.clear();
          lock.lock();
          state[slot_of(c)] = State::kFree;
          ++next_write;
          writing = false;
        } else if (next_format < next_prepare) {
          const long c = next_format++;
          state[slot_of(c)] = State::kFormatting;
          lock.unlock();
          format(first_of(c), last_of(c), slot_of(c), &text[slot_of(c)]);
          lock.lock();
          state[slot_of(c)] = State::kFormatted;
        } else {
          cv.wait(lock);
          continue;
        }
      } catch (...) {
        if (!lock.owns_lock()) lock.lock();
        if (!error) error = std::current_exception();
      }
      cv.notify_all();
    }
    cv.notify_all();
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace robomach::io
