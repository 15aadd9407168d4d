// HtmlEscape: the five characters that can break element content or a
// quoted attribute become entities, everything else (UTF-8 included) stays.
#include <gtest/gtest.h>

#include "robomach/report/html.h"

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

}  // namespace
}  // namespace robomach::report
