// WriteRowsInParallel writes exactly what a sequential loop writes.
#include "robomach/io/parallel_rows.h"

#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>

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

}  // namespace
}  // namespace robomach::io
