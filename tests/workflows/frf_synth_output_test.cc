// frf-synth's output file (workflows/frf_synth.h, issue #36): the format
// follows the extension, another extension is an OptionError naming the
// option, and UFF58 (which has no field for the averages) is written with
// a warning that names the averages option, the tool's or Python's.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/errors.h"
#include "robomach/io/frf_files.h"
#include "robomach/workflows/frf_synth.h"
#include "test_support.h"

namespace robomach::workflows {
namespace {

using ::testing::HasSubstr;
using robomach::testing::TempDir;

TEST(FrfSynthOutputFormat, FollowsTheExtensionInAnyCase) {
  EXPECT_EQ(FrfSynthOutputFormat("a.csv", "--out", true), FrfFileFormat::kCsv);
  EXPECT_EQ(FrfSynthOutputFormat("a.CSV", "--out", true), FrfFileFormat::kCsv);
  EXPECT_EQ(FrfSynthOutputFormat("a.uff", "--out", true), FrfFileFormat::kUff58);
  EXPECT_EQ(FrfSynthOutputFormat("dir/a.UNV", "--out", true), FrfFileFormat::kUff58);
  EXPECT_EQ(FrfSynthOutputFormat("a.uf", "--out", true), FrfFileFormat::kUff58);
  EXPECT_EQ(FrfSynthOutputFormat("-", "--out", true), FrfFileFormat::kCsv);  // standard output
}

TEST(FrfSynthOutputFormat, AnotherExtensionNamesTheOptionAndThePath) {
  try {
    FrfSynthOutputFormat("plot.png", "--out", true);
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "--out");
    EXPECT_STREQ(e.what(),
                 "--out plot.png: expected a file name ending in .csv (the FRF CSV of docs/formats.md §3) or .uff, "
                 ".unv (UFF58), or '-' for standard output (CSV)");
  }
  // Without standard output (Python), "-" is refused and not offered.
  try {
    FrfSynthOutputFormat("-", "out", false);
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "out");
    EXPECT_STREQ(e.what(),
                 "out -: expected a file name ending in .csv (the FRF CSV of docs/formats.md §3) or .uff, .unv "
                 "(UFF58)");
  }
}

FrfSynthRun SmallRun(bool coherence, int averages) {
  FrfSynthRun run;
  run.hammer.coherence = coherence;
  run.hammer.averages = averages;
  Eigen::VectorXd f(3), c(3);
  Eigen::VectorXcd h(3);
  f << 10.0, 20.0, 30.0;
  h << 1e-7, std::complex<double>(2e-7, -1e-7), 5e-8;
  c << 0.99, 0.95, 0.9;
  run.frfs.Insert({"P1", Axis::kX, Axis::kX}, dynamics::Frf::FromSamples(f, h, c));
  return run;
}

std::vector<Message> Write(const FrfSynthRun& run, const FrfSynthOptions& o, const std::string& path) {
  std::vector<Message> said;
  WriteFrfSynthOutput(run, o, path, FrfSynthOutputFormat(path, "--out", true), io::FrfQuantity::kReceptance,
                      [&](const Message& m) { said.push_back(m); });
  return said;
}

TEST(WriteFrfSynthOutput, Uff58WithCoherenceOfSeveralImpactsWarnsNamingTheAveragesOption) {
  const std::string dir = TempDir("frf_synth_output");
  FrfSynthOptions tool;
  tool.names["averages"] = "--averages";
  const std::string uff = dir + "/h.uff";
  const std::vector<Message> said = Write(SmallRun(true, 8), tool, uff);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_EQ(said[0].kind, Message::Kind::kWarning);
  EXPECT_EQ(said[0].text,
            "UFF58 has no field for the number of averages: give --averages 8 to the tools that read " + uff);
  EXPECT_TRUE(std::filesystem::exists(uff));
  EXPECT_EQ(io::ReadFrfFile(uff, "P1").frfs.size(), 1);
  // Python names the keyword (no entry in names: the field's own name).
  const std::vector<Message> py = Write(SmallRun(true, 8), FrfSynthOptions{}, dir + "/p.uff");
  ASSERT_EQ(py.size(), 1u);
  EXPECT_THAT(py[0].text, HasSubstr("give averages 8 to the tools"));
}

TEST(WriteFrfSynthOutput, CsvCarriesTheAveragesAndNoWarning) {
  const std::string dir = TempDir("frf_synth_output_csv");
  const std::string csv = dir + "/h.csv";
  EXPECT_TRUE(Write(SmallRun(true, 8), FrfSynthOptions{}, csv).empty());
  std::ifstream in(csv);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr("# averages: 8"));
  // UFF58 without coherence, or of one impact: nothing to warn about.
  EXPECT_TRUE(Write(SmallRun(false, 8), FrfSynthOptions{}, dir + "/a.uff").empty());
  EXPECT_TRUE(Write(SmallRun(true, 1), FrfSynthOptions{}, dir + "/b.uff").empty());
}

}  // namespace
}  // namespace robomach::workflows
