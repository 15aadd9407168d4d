#include <gtest/gtest.h>

#include <filesystem>

#include <opencv2/imgcodecs.hpp>

#include "robomach/report/frf_plot.h"
#include "robomach/report/plot.h"
#include "test_support.h"

namespace robomach::report {
namespace {

TEST(Ticks, LinearTicksAreNiceStepsCoveringTheRange) {
  EXPECT_EQ(LinearTicks(0.0, 10.0, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  EXPECT_EQ(LinearTicks(-180.0, 180.0, 4), (std::vector<double>{-100, 0, 100}));
  // More than three decades: decades only; up to three: 1, 2, 5 in each.
  EXPECT_EQ(LogTicks(0.6, 1000.0), (std::vector<double>{1, 10, 100, 1000}));
  EXPECT_EQ(LogTicks(1.0, 100.0), (std::vector<double>{1, 2, 5, 10, 20, 50, 100}));
}

// The PNG decodes, has the requested size and is not blank.
TEST(Figure, WritesADecodablePngOfTheRequestedSize) {
  Figure fig(2, 1, 400, 300);
  fig.title = "t";
  FrfCurve c;
  c.freq_hz = Eigen::VectorXd::LinSpaced(100, 1, 100);
  c.receptance = (1.0 / (1.0 - (c.freq_hz.array() / 30.0).square() +
                         std::complex<double>(0, 0.05) * c.freq_hz.array() / 30.0))
                     .matrix();
  c.label = "Hxx";
  FillFrfPanels({c}, {30.0}, "test", &fig.at(0, 0), &fig.at(1, 0));
  const std::string path = robomach::testing::TempDir("plot") + "/f.png";
  fig.SavePng(path);
  const cv::Mat img = cv::imread(path);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 400);
  EXPECT_EQ(img.rows, 2 * 300 + 34);
  cv::Scalar mean = cv::mean(img);
  EXPECT_LT(mean[0], 254.0);  // something was drawn
}

}  // namespace
}  // namespace robomach::report
