#include "robomach/io/parallel_rows.h"

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace robomach::io {

void WriteRowsInParallel(std::ostream& out, long begin, long end,
                         const std::function<void(long, std::string*)>& format, int threads) {
  if (end <= begin) return;
  threads = std::max(1, std::min<int>(threads, static_cast<int>(end - begin)));
  std::vector<std::string> buffers(threads);
  std::vector<std::exception_ptr> errors(threads);
  const long per = (end - begin + threads - 1) / threads;
  auto work = [&](int t) {
    try {
      const long a = begin + t * per, b = std::min(end, a + per);
      buffers[t].reserve(static_cast<size_t>(std::max(0L, b - a)) * 300);
      for (long i = a; i < b; ++i) format(i, &buffers[t]);
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& th : pool) th.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  for (const auto& b : buffers) out.write(b.data(), static_cast<std::streamsize>(b.size()));
}

}  // namespace robomach::io
