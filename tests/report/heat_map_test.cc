#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "robomach/report/heat_map.h"

namespace robomach::report {
namespace {

HeatMap Table() {
  HeatMap m;
  m.title = "t";
  m.x_label = "model mode";
  m.y_label = "posture";
  m.colorbar_label = "error [%]";
  m.x0 = m.y0 = 0.0;
  m.nx = 3;
  m.ny = 2;
  m.values = {-4.0, NAN, 1.0, 2.5, 0.0, -1.0};
  m.x_tick_labels = {"1", "2", "3"};
  m.y_tick_labels = {"P1", "a-long-posture-id"};
  m.first_row_at_top = true;
  m.annotate = true;
  m.symmetric_range = true;
  m.width_px = 700;
  m.height_px = 300;
  return m;
}

cv::Mat Decode(const std::vector<unsigned char>& png) { return cv::imdecode(png, cv::IMREAD_COLOR); }

// Maps that cannot be drawn are rejected with the field named, not drawn
// with a division by a zero extent or cells read past `values`.
TEST(HeatMap, RejectsMapsThatCannotBeDrawn) {
  const auto rejects = [](HeatMap m, const std::string& field) {
    try {
      EncodeHeatMapPng(m);
      ADD_FAILURE() << "accepted a map with bad " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  HeatMap m = Table();
  m.nx = 0;
  rejects(m, "nx");
  m = Table();
  m.dy = 0.0;
  rejects(m, "dy");
  m = Table();
  m.values.pop_back();
  rejects(m, "values");
  m = Table();
  m.marks = {1};
  rejects(m, "marks");
  m = Table();
  m.height_px = 151;
  rejects(m, "height_px");
  EXPECT_FALSE(EncodeHeatMapPng(Table()).empty());
}

// Categorical, annotated maps decode at the requested size; stacked maps
// are one below the other at the widest width.
TEST(HeatMap, CategoricalAnnotatedMapsRenderAndStack) {
  const HeatMap a = Table();
  const cv::Mat one = Decode(EncodeHeatMapPng(a));
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(one.cols, 700);
  EXPECT_EQ(one.rows, 300);
  HeatMap b = Table();
  b.width_px = 500;
  b.height_px = 250;
  const cv::Mat two = Decode(EncodeHeatMapsPng({a, b}));
  ASSERT_FALSE(two.empty());
  EXPECT_EQ(two.cols, 700);
  EXPECT_EQ(two.rows, 550);
  EXPECT_LT(cv::mean(two)[0], 254.0);  // something was drawn
}

// first_row_at_top puts row 0 at the top: the top-left cell of the plot area
// has row 0's colour. With a symmetric range, −4 is the darkest value
// (viridis' dark end), so row 0 column 0 is darker than row 1 column 0 (2.5).
TEST(HeatMap, FirstRowAtTopDrawsRowZeroAbove) {
  HeatMap m = Table();
  m.annotate = false;
  const cv::Mat img = Decode(EncodeHeatMapPng(m));
  // Plot area: top 60 px margin, bottom 90; left margin from the widest label.
  const int top = 60, ph = 300 - 60 - 90;
  int x = -1;
  for (int c = 0; c < img.cols && x < 0; ++c) {  // first coloured column in the top row band
    const cv::Vec3b p = img.at<cv::Vec3b>(top + ph / 4, c);
    if (!(p[0] == p[1] && p[1] == p[2])) x = c + 5;
  }
  ASSERT_GE(x, 0);
  const cv::Vec3b upper = img.at<cv::Vec3b>(top + ph / 4, x), lower = img.at<cv::Vec3b>(top + 3 * ph / 4, x);
  EXPECT_LT(upper[0] + upper[1] + upper[2], lower[0] + lower[1] + lower[2]);
}

// range_min/range_max fix the colour scale (stability-map draws the depth
// and the safe depth on one): a single cell of 2 on [0, 4] takes viridis'
// middle colour (OpenCV's own map at 128), not the end colour its own range
// gives (a single value is the bottom of its own range).
TEST(HeatMap, FixedRangeSetsTheColourScale) {
  HeatMap m;
  m.title = "t";
  m.nx = m.ny = 1;
  m.values = {2.0};
  m.width_px = 400;
  m.height_px = 300;
  auto cell = [&](const HeatMap& map) {
    const cv::Mat img = Decode(EncodeHeatMapPng(map));
    const int y = 60 + (300 - 60 - 90) / 2;
    for (int c = 0; c < img.cols; ++c) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, c);
      if (!(p[0] == p[1] && p[1] == p[2])) return img.at<cv::Vec3b>(y, c + 10);
    }
    return cv::Vec3b(0, 0, 0);
  };
  auto viridis = [](int level) {
    cv::Mat one(1, 1, CV_8UC1, cv::Scalar(level)), out;
    cv::applyColorMap(one, out, cv::COLORMAP_VIRIDIS);
    return out.at<cv::Vec3b>(0, 0);
  };
  auto near = [](cv::Vec3b a, cv::Vec3b b) {
    return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]) <= 6;
  };
  EXPECT_FALSE(near(cell(m), viridis(128)));
  m.range_min = 0.0;
  m.range_max = 4.0;
  EXPECT_TRUE(near(cell(m), viridis(128)));
  m.range_max = 1.0;  // beyond the range: the end colour
  EXPECT_TRUE(near(cell(m), viridis(255)));
}

}  // namespace
}  // namespace robomach::report
