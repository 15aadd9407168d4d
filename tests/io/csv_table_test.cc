#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/io/csv_table.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using robomach::testing::CaptureError;
using ::testing::HasSubstr;

TEST(CsvTable, ReadsMetadataCommentsQuotedCellsAndColumnsByName) {
  const CsvTable t = CsvTable::Parse(
      "\xEF\xBB\xBF# quantity: Accelerance\r\n# a free comment\r\nb,a,\"c d\"\r\n2, 1.5e-3 ,\"x,y\"\r\n\r\n+4,-0,z\r\n",
      "t.csv");
  EXPECT_EQ(t.metadata().at("quantity"), "Accelerance");
  ASSERT_EQ(t.num_rows(), 2);
  EXPECT_EQ(t.line(0), 4);
  EXPECT_EQ(t.line(1), 6);
  EXPECT_DOUBLE_EQ(t.Number(0, "a"), 1.5e-3);
  EXPECT_DOUBLE_EQ(t.Number(1, "b"), 4.0);
  EXPECT_EQ(t.Text(0, "c d"), "x,y");
  EXPECT_EQ(t.UnknownColumns({"a", "b"}), std::vector<std::string>{"c d"});
}

TEST(CsvTable, NumberErrorsNameFileLineColumnAndWhatWasFound) {
  const CsvTable t = CsvTable::Parse("fx_N,fy_N,fz_N\n1,2,3\n1,\"12,5\",3\n1,nan,3\n1,,3\n", "tracker.csv");
  EXPECT_EQ(CaptureError([&] { t.Number(1, "fy_N"); }),
            "tracker.csv:3: column fy_N: expected a number, got \"12,5\" (decimal comma?)");
  EXPECT_EQ(CaptureError([&] { t.Number(2, "fy_N"); }),
            "tracker.csv:4: column fy_N: expected a number, got \"nan\" (nan and inf are not allowed)");
  EXPECT_EQ(CaptureError([&] { t.Number(3, "fy_N"); }),
            "tracker.csv:5: column fy_N: expected a number, got an empty cell (cell 2 of 3 in the row, after 1 "
            "commas)");
  EXPECT_EQ(CaptureError([&] { t.Number(0, "mass_kg"); }),
            "tracker.csv:1: missing required column 'mass_kg'; the header has: fx_N,fy_N,fz_N");
}

TEST(CsvTable, AMissingColumnNamesTheCloseOneAndASemicolonHeaderIsNamed) {
  const CsvTable t = CsvTable::Parse("pose_id,q1deg,q2_deg\nP1,0,0\n", "p.csv");
  EXPECT_EQ(CaptureError([&] { t.RequireColumn("q1_deg"); }),
            "p.csv:1: missing required column 'q1_deg' (the header has 'q1deg' (column 2): mistyped?); the header "
            "has: pose_id,q1deg,q2_deg");
  // Nothing close: no guess.
  EXPECT_EQ(t.CloseColumn("force_N"), "");
  // A spreadsheet's ';' (German or French locale) and a tab-separated export.
  EXPECT_THAT(CaptureError([] { CsvTable::Parse("pose_id;q1_deg;q2_deg\nP1;0,5;0\n", "s.csv"); }),
              HasSubstr("s.csv:1: the header 'pose_id;q1_deg;q2_deg' is separated by semicolons; robomach's CSV "
                        "files separate cells with commas"));
  EXPECT_THAT(CaptureError([] { CsvTable::Parse("pose_id\tq1_deg\nP1\t0\n", "t.csv"); }),
              HasSubstr("t.csv:1: the header 'pose_id\tq1_deg' is separated by tabs"));
}

TEST(CsvTable, StructuralErrors) {
  EXPECT_THAT(CaptureError([] { CsvTable::Parse("# only a comment\n", "e.csv"); }),
              HasSubstr("e.csv: no header row found"));
  EXPECT_THAT(CaptureError([] { CsvTable::Parse("a,b\n1,2,3\n", "w.csv"); }),
              HasSubstr("w.csv:2: expected at most 2 cells as in the header, got 3"));
  EXPECT_THAT(CaptureError([] { CsvTable::Parse("a,a\n", "d.csv"); }),
              HasSubstr("d.csv:1: header: column 'a' appears twice"));
  EXPECT_THAT(CaptureError([] { CsvTable::Parse("a\n\"open\n", "q.csv"); }),
              HasSubstr("q.csv:2: unterminated quoted cell"));
  EXPECT_THAT(CaptureError([] { CsvTable::ReadFile("/nonexistent/x.csv"); }),
              HasSubstr("/nonexistent/x.csv: cannot open file"));
}

TEST(ParseFiniteNumber, AcceptsDecimalAndExponentFormsOnly) {
  double v = 0;
  EXPECT_TRUE(ParseFiniteNumber("1.2e-07", &v));
  EXPECT_DOUBLE_EQ(v, 1.2e-7);
  EXPECT_TRUE(ParseFiniteNumber(" -3 ", &v));
  EXPECT_DOUBLE_EQ(v, -3.0);
  for (const char* bad : {"", "inf", "-inf", "nan", "1,5", "1.5x", "0x10", "1e999"}) {
    EXPECT_FALSE(ParseFiniteNumber(bad, &v)) << bad;
  }
}

}  // namespace
}  // namespace robomach::io
