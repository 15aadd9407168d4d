// HtmlEscape: the five characters that can break element content or a
// quoted attribute become entities, everything else (UTF-8 included) stays.
#include <gtest/gtest.h>

#include "robomach/report/html.h"
#include "robomach/report/json.h"

namespace robomach::report {
namespace {

TEST(HtmlEscape, EscapesMarkupAndQuotes) {
  EXPECT_EQ(HtmlEscape("<a title=\"Kass & Raftery's\">x</a>"),
            "&lt;a title=&quot;Kass &amp; Raftery&#39;s&quot;&gt;x&lt;/a&gt;");
}

TEST(HtmlEscape, LeavesOtherTextAlone) {
  const std::string text = "tool_flexibility: ζ = 0.05, 1.2e-07 m/N — P1 xx";
  EXPECT_EQ(HtmlEscape(text), text);
  EXPECT_EQ(HtmlEscape(""), "");
  // Already-escaped text is escaped again (the caller passes plain text).
  EXPECT_EQ(HtmlEscape("&amp;"), "&amp;amp;");
}

// A warning quoting a Latin-1 file header ("m/s" + 0xB2) in a summary:
// nlohmann::json refuses to dump invalid UTF-8 (type_error 316), which
// ended the run; the byte is written \xB2 and the output parses back.
TEST(DumpJson, EscapesBytesThatAreNotUtf8) {
  nlohmann::json j;
  j["warnings"] = {"unit (1/N)*(m/s\xB2)", "m/s\xC2\xB2 stays"};
  j["caf\xE9"] = 1;
  std::string text;
  ASSERT_NO_THROW(text = DumpJson(j));
  const nlohmann::json back = nlohmann::json::parse(text);
  EXPECT_EQ(back["warnings"][0], "unit (1/N)*(m/s\\xB2)");
  EXPECT_EQ(back["warnings"][1], "m/s\xC2\xB2 stays");
  EXPECT_EQ(back["caf\\xE9"], 1);
  EXPECT_TRUE(back.contains("robomach_version"));
}

}  // namespace
}  // namespace robomach::report
