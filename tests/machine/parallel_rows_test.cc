// WriteRowsInParallel writes exactly what a sequential loop writes.
#include "robomach/io/parallel_rows.h"

#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <vector>

namespace robomach::io {
namespace {

TEST(WriteRowsInParallel, SameTextAsSequentialForAnySplit) {
  auto format = [](long i, std::string* b) { *b += std::to_string(i * 7919 % 1000) + "," + std::to_string(i) + "\n"; };
  for (long n : {0L, 1L, 2L, 3L, 1000L, 1001L}) {
    std::string expected;
    for (long i = 5; i < 5 + n; ++i) format(i, &expected);
    for (int threads : {1, 2, 3, 8}) {
      std::ostringstream out;
      WriteRowsInParallel(out, 5, 5 + n, format, threads);
      EXPECT_EQ(out.str(), expected) << n << " rows, " << threads << " threads";
    }
  }
}

TEST(WriteRowsInParallel, RethrowsAndWritesNothing) {
  std::ostringstream out;
  EXPECT_THROW(WriteRowsInParallel(out, 0, 100,
                                   [](long i, std::string* b) {
                                     if (i == 77) throw std::runtime_error("row 77");
                                     *b += "x\n";
                                   }),
               std::runtime_error);
  EXPECT_EQ(out.str(), "");
}

// The pipeline: prepare runs chunk after chunk in order (a sequential stage
// may carry state from one chunk to the next), and the text is what one
// sequential loop writes, for any chunk size, slot count and thread count.
TEST(WritePipelined, SameTextAsSequentialAndPreparesInOrder) {
  for (long rows : {0L, 1L, 7L, 1000L, 1001L}) {
    std::string expected;
    long running = 0;
    for (long i = 0; i < rows; ++i) {
      running += i % 13;
      expected += std::to_string(i) + ":" + std::to_string(running) + "\n";
    }
    for (long chunk : {1L, 3L, 64L, 5000L}) {
      for (int slots : {1, 2, 6}) {
        for (int threads : {1, 2, 3}) {
          std::vector<std::vector<long>> store(static_cast<size_t>(slots), std::vector<long>(static_cast<size_t>(chunk)));
          long state = 0, next_first = 0;
          bool in_order = true;
          std::ostringstream out;
          WritePipelined(
              out, rows, chunk, slots,
              [&](long first, long last, int slot) {
                in_order = in_order && first == next_first;
                next_first = last;
                for (long i = first; i < last; ++i) {
                  state += i % 13;  // carried from chunk to chunk
                  store[static_cast<size_t>(slot)][static_cast<size_t>(i - first)] = state;
                }
              },
              [&](long first, long last, int slot, std::string* text) {
                for (long i = first; i < last; ++i) {
                  *text += std::to_string(i) + ":" + std::to_string(store[static_cast<size_t>(slot)][static_cast<size_t>(i - first)]) + "\n";
                }
              },
              threads);
          EXPECT_TRUE(in_order);
          EXPECT_EQ(next_first, rows);
          EXPECT_EQ(out.str(), expected) << rows << " rows, chunk " << chunk << ", " << slots << " slots, " << threads
                                         << " threads";
        }
      }
    }
  }
}

TEST(WritePipelined, RethrowsFromEitherStageAndStops) {
  for (int threads : {1, 2}) {
    std::ostringstream out;
    long prepared = 0;
    EXPECT_THROW(WritePipelined(
                     out, 10000, 10, 4,
                     [&](long first, long, int) {
                       prepared = first;
                       if (first == 500) throw std::runtime_error("prepare 500");
                     },
                     [](long first, long last, int, std::string* t) { t->append(static_cast<size_t>(last - first), 'x'); },
                     threads),
                 std::runtime_error);
    EXPECT_EQ(prepared, 500);
    EXPECT_LE(out.str().size(), 500u);
    std::ostringstream out2;
    EXPECT_THROW(WritePipelined(
                     out2, 10000, 10, 4, [](long, long, int) {},
                     [](long first, long last, int, std::string* t) {
                       if (first == 300) throw std::invalid_argument("format 300");
                       t->append(static_cast<size_t>(last - first), 'x');
                     },
                     threads),
                 std::invalid_argument);
    EXPECT_LE(out2.str().size(), 300u);
  }
}

}  // namespace
}  // namespace robomach::io
