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

/// A three-stage pipeline over rows [0, rows) in chunks of `chunk_rows`:
///  1. prepare(first, last, slot): called for chunk after chunk in order, one
///     at a time (a sequential stage, e.g. a tracker that follows the path);
///  2. format(first, last, slot, &text): appends the chunk's text; different
///     chunks are formatted at the same time on different threads;
///  3. the texts are written to `out` in chunk order.
/// Every thread takes whatever stage has work (the sequential stage first),
/// so reading ahead, computing and formatting overlap. `slot` in [0, slots)
/// names the caller's storage for one chunk in flight: chunk c uses slot
/// c % slots, which is reused only after chunk c's text was written, so
/// memory stays constant. An exception of a callback stops the pipeline
/// (chunks already written stay written: write into an atomic file) and is
/// rethrown after every thread stopped.
void WritePipelined(std::ostream& out, long rows, long chunk_rows, int slots,
                    const std::function<void(long first, long last, int slot)>& prepare,
                    const std::function<void(long first, long last, int slot, std::string* text)>& format,
                    int threads = 2);

}  // namespace robomach::io
