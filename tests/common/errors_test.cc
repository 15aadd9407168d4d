#include <gtest/gtest.h>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"

namespace robomach {
namespace {

TEST(InputError, MessageStartsWithTheLocation) {
  EXPECT_STREQ(InputError({"a.csv", 17, 0}, "column fy_N: bad").what(), "a.csv:17: column fy_N: bad");
  EXPECT_STREQ(InputError({"r.yaml", 3, 24}, "x").what(), "r.yaml:3:24: x");
  EXPECT_STREQ(InputError({"r.urdf", 0, 0}, "x").what(), "r.urdf: x");
  EXPECT_EQ(InputError({"r.urdf", 0, 0}, "x").message(), "x");
}

TEST(Units, ConversionsAreExactInverses) {
  EXPECT_DOUBLE_EQ(DegToRad(180.0), kPi);
  EXPECT_DOUBLE_EQ(RpmToRadPerSec(60.0), 2 * kPi);
  EXPECT_DOUBLE_EQ(RadPerSecToHz(HzToRadPerSec(922.0)), 922.0);
  EXPECT_DOUBLE_EQ(MmToM(12.5), 0.0125);
}

}  // namespace
}  // namespace robomach
