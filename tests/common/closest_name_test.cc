// "Did you mean" (issue #35): the edit distance against the textbook values
// and against a plain recursive definition on random strings; ClosestName on
// the typos new users made (a letter off, '_' for '-', a unit suffix left
// off or changed) and on names that are not close to anything.
#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <string>
#include <vector>

#include "robomach/common/closest_name.h"

namespace robomach {
namespace {

// Optimal string alignment distance by its recursive definition.
size_t RecursiveDistance(const std::string& a, const std::string& b) {
  std::function<size_t(size_t, size_t)> d = [&](size_t i, size_t j) -> size_t {
    if (i == 0) return j;
    if (j == 0) return i;
    size_t best = std::min(d(i - 1, j) + 1, d(i, j - 1) + 1);
    best = std::min(best, d(i - 1, j - 1) + (a[i - 1] == b[j - 1] ? 0 : 1));
    if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) best = std::min(best, d(i - 2, j - 2) + 1);
    return best;
  };
  return d(a.size(), b.size());
}

TEST(ClosestName, EditDistanceHasTheTextbookValues) {
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(EditDistance("", "abc"), 3u);
  EXPECT_EQ(EditDistance("abc", "abc"), 0u);
  EXPECT_EQ(EditDistance("ab", "ba"), 1u);       // a swap is one edit
  EXPECT_EQ(EditDistance("ca", "abc"), 3u);      // OSA, not Damerau's 2
  EXPECT_EQ(EditDistance("flaw", "lawn"), 2u);
}

TEST(ClosestName, EditDistanceEqualsTheRecursiveDefinition) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> len(0, 6);
  std::uniform_int_distribution<int> letter(0, 2);
  for (int trial = 0; trial < 300; ++trial) {
    std::string a, b;
    for (int i = len(rng); i > 0; --i) a += static_cast<char>('a' + letter(rng));
    for (int i = len(rng); i > 0; --i) b += static_cast<char>('a' + letter(rng));
    ASSERT_EQ(EditDistance(a, b), RecursiveDistance(a, b)) << a << " / " << b;
    ASSERT_EQ(EditDistance(a, b), EditDistance(b, a)) << a << " / " << b;
  }
}

TEST(ClosestName, FindsTheNameANewUserMeant) {
  const std::vector<std::string> options = {"robot", "postures", "fmin-hz", "fmax-hz", "out", "plot", "modes"};
  EXPECT_EQ(ClosestName("fmax-hzz", options), "fmax-hz");   // a letter too many
  EXPECT_EQ(ClosestName("fmax_hz", options), "fmax-hz");    // '_' for '-'
  EXPECT_EQ(ClosestName("FMAX-HZ", options), "fmax-hz");    // case
  EXPECT_EQ(ClosestName("fmax", options), "fmax-hz");       // unit left off
  EXPECT_EQ(ClosestName("fmax-khz", options), "fmax-hz");   // another unit
  EXPECT_EQ(ClosestName("posture", options), "postures");
  EXPECT_EQ(ClosestName("rbot", options), "robot");
  const std::vector<std::string> keys = {"ktc_N_per_mm2", "krc_N_per_mm2", "diameter_mm", "teeth"};
  EXPECT_EQ(ClosestName("ktc_N_per_m2", keys), "ktc_N_per_mm2");
  EXPECT_EQ(ClosestName("diameter_m", keys), "diameter_mm");
  EXPECT_EQ(ClosestName("diameter", keys), "diameter_mm");
  // The other way round: the name looked for has the unit, the file's key not.
  EXPECT_EQ(ClosestName("spindle_speed_max_rpm", {"spindle_speed_max", "teeth"}), "spindle_speed_max");
}

TEST(ClosestName, SaysNothingWhenNoNameIsClose) {
  const std::vector<std::string> options = {"robot", "postures", "fmax-hz", "out"};
  EXPECT_EQ(ClosestName("speed", options), "");
  EXPECT_EQ(ClosestName("threads", options), "");
  EXPECT_EQ(ClosestName("", options), "");
  EXPECT_EQ(ClosestName("robot", {}), "");
}

}  // namespace
}  // namespace robomach
