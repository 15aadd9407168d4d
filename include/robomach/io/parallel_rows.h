#pragma once
// Text output of many rows on two threads: rows are formatted in parallel
// into per-thread buffers and written in order. For the tools whose time is
// mostly number formatting (axis-acquire: 6.7 million 17-digit numbers for a
// 60 s, 8 kHz record).

#include <functional>
#include <ostream>
#include <string>

namespace robomach::io {

/// Calls format(i, &buffer) for i in [begin, end) (each call appends row i),
/// split over `threads` threads in contiguous stretches, and writes the
/// stretches to `out` in order. `format` must be safe to call concurrently
/// for different rows. An exception of any call is rethrown after all
/// threads finished; nothing of the failed stretch is written then.
void WriteRowsInParallel(std::ostream& out, long begin, long end,
                         const std::function<void(long, std::string*)>& format, int threads = 2);

}  // namespace robomach::io
