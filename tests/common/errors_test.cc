#include <gtest/gtest.h>
#include <stdexcept>

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

// A Latin-1 header byte (0xE9 "é", 0xB2 "²") is not UTF-8 and is written
// \xHH; valid UTF-8 ("²" = C2 B2, "µ" = C2 B5, a 4-byte emoji) is kept.
// The ill-formed sequences of the Unicode Standard's Table 3-7: a cut
// sequence, an overlong "/" (C0 AF), a surrogate (ED A0 80) and a code
// point above U+10FFFF (F4 90 80 80) are escaped byte by byte.
TEST(EscapeInvalidUtf8, EscapesLatin1AndIllFormedBytesAndKeepsUtf8) {
  EXPECT_EQ(EscapeInvalidUtf8("caf\xE9 m/s\xB2"), "caf\\xE9 m/s\\xB2");
  EXPECT_EQ(EscapeInvalidUtf8("m/s\xC2\xB2, \xC2\xB5m, \xF0\x9F\x94\xA8"), "m/s\xC2\xB2, \xC2\xB5m, \xF0\x9F\x94\xA8");
  EXPECT_EQ(EscapeInvalidUtf8("a\xC2"), "a\\xC2");
  EXPECT_EQ(EscapeInvalidUtf8("\xC0\xAF"), "\\xC0\\xAF");
  EXPECT_EQ(EscapeInvalidUtf8("\xED\xA0\x80"), "\\xED\\xA0\\x80");
  EXPECT_EQ(EscapeInvalidUtf8("\xF4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80");
  EXPECT_EQ(EscapeInvalidUtf8(""), "");
  // An InputError quoting a header escapes it in what() and message().
  const InputError e({"h.uff", 11, 0}, "unit \"m/s\xB2\"");
  EXPECT_STREQ(e.what(), "h.uff:11: unit \"m/s\\xB2\"");
  EXPECT_EQ(e.message(), "unit \"m/s\\xB2\"");
}

TEST(Units, ConversionsAreExactInverses) {
  EXPECT_DOUBLE_EQ(DegToRad(180.0), kPi);
  EXPECT_DOUBLE_EQ(RpmToRadPerSec(60.0), 2 * kPi);
  EXPECT_DOUBLE_EQ(RadPerSecToHz(HzToRadPerSec(922.0)), 922.0);
  EXPECT_DOUBLE_EQ(MmToM(12.5), 0.0125);
}

// AtLocation: the check's message after the file location and the prefix;
// other exceptions pass untouched; the value comes back.
TEST(AtLocation, GivesTheChecksErrorItsFileLocation) {
  const SourceLocation where{"cut.yaml", 7, 18};
  EXPECT_EQ(AtLocation(where, "feed_direction: ", [] { return 42; }), 42);
  try {
    AtLocation(where, "feed_direction: ", []() -> int { throw std::invalid_argument("expected x, y or z"); });
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "cut.yaml:7:18: feed_direction: expected x, y or z");
    EXPECT_EQ(e.where().line, 7);
  }
  // Another type than the one asked for is not the check's: it passes.
  EXPECT_THROW(AtLocation(where, "", [] { throw std::domain_error("elsewhere"); }), std::domain_error);
  EXPECT_THROW(AtLocation<std::domain_error>(where, "", [] { throw std::domain_error("x"); }), InputError);
}

}  // namespace
}  // namespace robomach
