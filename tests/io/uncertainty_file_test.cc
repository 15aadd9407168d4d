// The parameter-uncertainty file (docs/formats.md §12): what is written reads
// back to the same doubles, and a broken file is refused at its place.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/io/uncertainty_file.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using robomach::testing::CaptureError;
using robomach::testing::TempDir;
using robomach::testing::WriteText;
using ::testing::HasSubstr;

dynamics::ParameterUncertainty Example() {
  dynamics::ParameterUncertainty u;
  u.source = "kq-identify: \"quoted\" campaign";
  u.parameters = {{"kq1_Nm_per_rad", 3288464.824435456, dynamics::UncertainScale::kInverse},
                  {"m6_kg", 30.2, dynamics::UncertainScale::kLog},
                  {"d6_m", 0.31, dynamics::UncertainScale::kLinear}};
  u.covariance.resize(3, 3);
  u.covariance << 1.5876088217617275e-17, 1e-12, 0.0, 1e-12, 4e-4, 1e-5, 0.0, 1e-5, 1e-6;
  return u;
}

TEST(UncertaintyFile, RoundTripsExactly) {
  const std::string path = TempDir("uncertainty_file") + "/u.yaml";
  WriteParameterUncertainty(path, Example());
  const dynamics::ParameterUncertainty r = ReadParameterUncertainty(path);
  const dynamics::ParameterUncertainty e = Example();
  ASSERT_EQ(r.parameters.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(r.parameters[i].name, e.parameters[i].name);
    EXPECT_EQ(r.parameters[i].value, e.parameters[i].value);  // shortest round-trip text
    EXPECT_EQ(r.parameters[i].scale, e.parameters[i].scale);
  }
  EXPECT_EQ(r.covariance, e.covariance);
  EXPECT_EQ(r.source, e.source);
}

TEST(UncertaintyFile, BrokenFilesAreRefusedAtTheirPlace) {
  const std::string dir = TempDir("uncertainty_bad");
  const std::string head =
      "parameter_uncertainty:\n"
      "  parameters:\n"
      "    - {name: a, value: 1, scale: log}\n"
      "    - {name: b, value: 2, scale: linear}\n";
  // Not positive semi-definite: correlation 2.
  std::string msg = CaptureError([&] {
    ReadParameterUncertainty(WriteText(dir + "/psd.yaml", head + "  covariance:\n    - [1, 2]\n    - [2, 1]\n"));
  });
  EXPECT_THAT(msg, HasSubstr("psd.yaml:6:"));
  EXPECT_THAT(msg, HasSubstr("negative eigenvalue"));
  msg = CaptureError([&] {
    ReadParameterUncertainty(WriteText(dir + "/row.yaml", head + "  covariance:\n    - [1, 0]\n    - [0]\n"));
  });
  EXPECT_THAT(msg, HasSubstr("row.yaml:7:"));
  EXPECT_THAT(msg, HasSubstr("expected a list of 2 numbers"));
  msg = CaptureError([&] {
    ReadParameterUncertainty(WriteText(
        dir + "/scale.yaml",
        "parameter_uncertainty:\n  parameters:\n    - {name: a, value: 1, scale: logarithmic}\n  covariance: [[1]]\n"));
  });
  EXPECT_THAT(msg, HasSubstr("scale.yaml:3:"));
  EXPECT_THAT(msg, HasSubstr("expected linear, log or inverse"));
  msg = CaptureError([&] {
    ReadParameterUncertainty(WriteText(
        dir + "/neg.yaml", "parameter_uncertainty:\n  parameters:\n    - {name: a, value: -1, scale: inverse}\n"
                           "  covariance: [[1]]\n"));
  });
  EXPECT_THAT(msg, HasSubstr("neg.yaml:3:"));
  EXPECT_THAT(msg, HasSubstr("> 0 on the inverse scale"));
  // The covariance of k [N²·m²/rad²] typed under the inverse scale: a
  // relative standard deviation of 1.5e13 %, refused naming the mistake.
  msg = CaptureError([&] {
    ReadParameterUncertainty(WriteText(
        dir + "/k2.yaml", "parameter_uncertainty:\n  parameters:\n    - {name: kq1_Nm_per_rad, value: 3e6, scale: inverse}\n"
                          "  covariance: [[2.25e10]]\n"));
  });
  EXPECT_THAT(msg, HasSubstr("k2.yaml:4:"));
  EXPECT_THAT(msg, HasSubstr("the covariance of the value itself"));
  // A weak joint (60 %) is a fit's result and is read.
  EXPECT_NO_THROW(ReadParameterUncertainty(WriteText(
      dir + "/weak.yaml", "parameter_uncertainty:\n  parameters:\n    - {name: kq6_Nm_per_rad, value: 2e5, scale: inverse}\n"
                          "  covariance: [[9e-12]]\n")));
  // A robot config given as the uncertainty file names what it is.
  msg = CaptureError([&] { ReadParameterUncertainty(testing::SourcePath("config/kr210.yaml")); });
  EXPECT_THAT(msg, HasSubstr("missing key 'parameter_uncertainty'"));
  EXPECT_THAT(msg, HasSubstr("a robot config"));
  // The same parameter in two files is not taken as independent.
  const std::string a = dir + "/a.yaml", b = dir + "/b.yaml";
  WriteParameterUncertainty(a, Example());
  WriteParameterUncertainty(b, Example());
  msg = CaptureError([&] { ReadParameterUncertainties({a, b}); });
  EXPECT_THAT(msg, HasSubstr("kq1_Nm_per_rad is in two uncertainty files"));
}

}  // namespace
}  // namespace robomach::io
