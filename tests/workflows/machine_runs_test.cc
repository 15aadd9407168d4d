// The machine tools' runs (issue #36: out of io into workflows): the raw
// capture's decoding (a wrong file kind is named, not decoded) and the
// ISO 230-2 evaluation's unit rule on a short-stroke axis.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "robomach/io/machine_files.h"
#include "robomach/workflows/capture_decoding.h"
#include "robomach/workflows/iso_evaluation.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using ::testing::HasSubstr;
using testing::CaptureError;
using testing::SourcePath;
using testing::TempDir;
using testing::WriteText;

MachineFile DefaultMachine() { return ReadMachineFile(SourcePath("config/machine/dmu80p.yaml")); }

// A text file or a PNG given as the raw capture decoded to a million error
// events (exit 3, "raise the sample rate"); it is named instead.
TEST(CaptureFile, TextOrAKnownBinaryKindIsNamedNotDecoded) {
  const MachineFile m = DefaultMachine();
  const auto error = [&](const std::string& path) {
    return CaptureError([&] { workflows::DecodeCaptureFile(path, m, 2e6, 250, 0, [](double, const std::int64_t*) {}); });
  };
  const std::string counts = error(SourcePath("tests/data/machine/counts_tiny.csv"));
  EXPECT_THAT(counts, HasSubstr("counts_tiny.csv: this is a CSV table; expected the raw binary capture"));
  EXPECT_THAT(counts, HasSubstr("docs/formats.md §8.2"));
  EXPECT_THAT(counts, HasSubstr("(its columns are those of the encoder counts of docs/formats.md §8.1)"));
  EXPECT_THAT(error(SourcePath("docs/img/stability-map.png")), HasSubstr("this is a PNG image; expected the raw binary capture"));
  const std::string dir = TempDir("capture_other_kinds");
  EXPECT_THAT(error(WriteText(dir + "/hello.bin", "hello world\n")), HasSubstr("this is a text file, not binary"));
  EXPECT_THAT(error(WriteText(dir + "/blank.bin", " \n")), HasSubstr("this is a text file of white space only"));
  EXPECT_THAT(error(WriteText(dir + "/pdf.bin", "%PDF-1.7\n")), HasSubstr("this is a PDF document"));
  EXPECT_THAT(error(WriteText(dir + "/gz.bin", std::string("\x1f\x8b\x08\0", 4))), HasSubstr("gzip"));
  // A real capture (every word's high byte below 0x04 for five axes) is
  // binary and decodes; an empty one keeps its own message.
  long rows = 0;
  workflows::DecodeCaptureFile(WriteText(dir + "/ok.bin", std::string("\x00\x00\x01\x00\x03\x00\x02\x00", 8)), m, 1e6, 1, 0,
                    [&](double, const std::int64_t*) { ++rows; });
  EXPECT_EQ(rows, 4);
  EXPECT_THAT(error(WriteText(dir + "/empty.bin", "")), HasSubstr("the capture is empty"));
}

// Issue #34 item 5: a short-stroke axis (targets -4..4 mm, 5 runs each way,
// a stage measured by a laser triangulation sensor) with deviations
//   up: 0.015 x + 0.02 + r_k,  down: 0.015 x - 0.02 + r_k  [mm],
//   r_k = -0.01, -0.005, 0, 0.005, 0.01  (mean 0, s = sqrt(2.5e-4 / 4)),
// so by hand the largest |mean| + 2 s is 0.08 + 2 x 0.0079057 = 0.095811 mm
// at 4 mm up: 1.2 % of the 8 mm travel, over the former 1 % limit (the
// issue's false alarm) and under the 0.25 mm floor of short strokes: no
// finding. The same runs in um under _mm still are one, both ways a file
// can carry it: deviations 1000 x (measured = target + 1000 dev) and the
// measured positions in um beside targets in mm.
TEST(IsoRuns, ShortStrokeAxisIsPlausibleAndMicrometresUnderMmAreNot) {
  const std::string dir = TempDir("iso_short_stroke");
  auto file = [&](const std::string& name, double dev_scale, double measured_scale) {
    std::ostringstream os;
    os.precision(12);
    os << "axis,target_mm,run,direction,measured_mm\n";
    const double r[5] = {-0.01, -0.005, 0.0, 0.005, 0.01};
    for (int x = -4; x <= 4; x += 2) {
      for (int up = 1; up >= 0; --up) {
        for (int k = 0; k < 5; ++k) {
          const double dev = 0.015 * x + (up ? 0.02 : -0.02) + r[k];
          os << "X," << x << ',' << k + 1 << ',' << (up ? '+' : '-') << ','
             << measured_scale * (x + dev_scale * dev) << '\n';
        }
      }
    }
    return workflows::EvaluateIsoRunsFile(WriteText(dir + "/" + name, os.str()));
  };
  const workflows::IsoEvaluation good = file("short.csv", 1.0, 1.0);
  ASSERT_EQ(good.results.size(), 1u);
  double dev = 0.0;
  for (const machine::Iso230Target& t : good.results[0].second.targets) {
    dev = std::max({dev, std::abs(t.mean_up) + 2 * t.s_up, std::abs(t.mean_down) + 2 * t.s_down});
  }
  EXPECT_NEAR(dev, 0.08 + 2.0 * std::sqrt(2.5e-4 / 4.0), 1e-9);  // rounding of the 12-digit file
  EXPECT_GT(dev, machine::kMaxPlausibleDeviationFraction * 8.0);  // the former rule's false alarm
  EXPECT_TRUE(good.unit_findings.empty()) << good.unit_findings.front();
  EXPECT_EQ(good.status(), RunStatus::kOk);
  const workflows::IsoEvaluation dev_um = file("short_dev_um.csv", 1000.0, 1.0);
  ASSERT_EQ(dev_um.unit_findings.size(), 1u);
  EXPECT_THAT(dev_um.unit_findings[0], HasSubstr("axis X: deviations up to 95.81 mm are 1.2e+03 % of the targets' "
                                                  "magnitude (8 mm"));
  EXPECT_THAT(dev_um.unit_findings[0], HasSubstr("measured values in um (or targets in m) under the _mm headers"));
  EXPECT_EQ(dev_um.status(), RunStatus::kFlagged);
  const workflows::IsoEvaluation measured_um = file("short_measured_um.csv", 1.0, 1000.0);
  ASSERT_EQ(measured_um.unit_findings.size(), 1u);
  EXPECT_THAT(measured_um.unit_findings[0], HasSubstr("measured values in um"));
}

}  // namespace
}  // namespace robomach::io
