#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <opencv2/core.hpp>
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


// Coloured pixels in a box of the image: a curve (Okabe-Ito colours, their
// antialiased edges blended with white) has channels that differ by tens;
// the grey labels, grey marker lines, black text and the light grey grid
// have r = g = b. A spread of 25 is far above the 0-1 of a grey pixel and
// below the ~40 that a curve's edge pixel still has at a quarter of its colour.
int ColouredPixels(const cv::Mat& img, const PlacedLabel& l) {
  int n = 0;
  for (int y = l.y; y < l.y + l.height; ++y) {
    for (int x = l.x; x < l.x + l.width; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      const int hi = std::max({p[0], p[1], p[2]}), lo = std::min({p[0], p[1], p[2]});
      n += hi - lo > 25;
    }
  }
  return n;
}

// Three direct FRFs with the modes of frf-predict's posture P3 (issue #35:
// labels overlapped there, and on model-audit's worst FRF "10.4 Hz" read
// "1.4 Hz" under a curve): two modes 0.4 Hz apart near 10 Hz, peaks that
// reach the top of the panel under the labels' old fixed rows.
FrfCurve ThreeModeCurve(const std::string& label, int colour, const std::vector<double>& f_hz,
                        const std::vector<double>& k_N_per_m) {
  FrfCurve c;
  c.freq_hz = Eigen::VectorXd::LinSpaced(2000, 0.5, 500.0);
  c.receptance = Eigen::VectorXcd::Zero(c.freq_hz.size());
  for (size_t m = 0; m < f_hz.size(); ++m) {
    const Eigen::ArrayXd r = c.freq_hz.array() / f_hz[m];
    c.receptance.array() += (1.0 / k_N_per_m[m]) / (1.0 - r.square() + std::complex<double>(0, 0.04) * r);
  }
  c.label = label;
  c.color = PaletteColor(colour);
  return c;
}

std::vector<FrfCurve> P3LikeCurves() {
  return {ThreeModeCurve("Hxx", 0, {10.5, 39.1, 88.7}, {5e6, 4e6, 5e6}),
          ThreeModeCurve("Hyy", 1, {10.1, 53.3, 250.9}, {1.5e6, 3e6, 8e7}),
          ThreeModeCurve("Hzz", 2, {10.1, 39.1}, {2e6, 2e6})};
}

TEST(Figure, MarkerLabelsCrossNoCurveNoOtherLabelAndNoOtherMarkerLine) {
  const std::vector<double> modes_hz = {10.1, 10.5, 39.1, 53.3, 88.7, 250.9};
  for (const auto [w, h] : {std::pair{760, 380}, std::pair{600, 300}, std::pair{900, 380}}) {
    Figure fig(1, 2, w, h);
    FillFrfPanels(P3LikeCurves(), modes_hz, "P3", &fig.at(0, 0), &fig.at(0, 1));
    std::vector<PlacedLabel> labels;
    const cv::Mat img = cv::imdecode(fig.EncodePng(&labels), cv::IMREAD_COLOR);
    ASSERT_FALSE(img.empty());
    // Every mode labelled once, in the magnitude panel (the phase panel's
    // markers carry no text).
    ASSERT_EQ(labels.size(), modes_hz.size()) << w << "x" << h;
    PlacedLabel whole_panel;
    whole_panel.width = w, whole_panel.height = h;
    ASSERT_GT(ColouredPixels(img, whole_panel), 1000) << "the check sees the curves";
    for (size_t i = 0; i < labels.size(); ++i) {
      const PlacedLabel& a = labels[i];
      SCOPED_TRACE(a.text + " in " + std::to_string(w) + "x" + std::to_string(h));
      EXPECT_EQ(a.panel, 0);
      EXPECT_TRUE(a.clear);
      EXPECT_EQ(ColouredPixels(img, a), 0) << "a curve crosses the label's box";
      // Beside its own line, 3 px away, left or right.
      EXPECT_TRUE(a.x == a.line_x + 3 || a.x + a.width == a.line_x - 3) << a.x << " " << a.line_x;
      for (size_t j = 0; j < labels.size(); ++j) {
        if (j == i) continue;
        const PlacedLabel& b = labels[j];
        const cv::Rect ra(a.x, a.y, a.width, a.height), rb(b.x, b.y, b.width, b.height);
        EXPECT_TRUE((ra & rb).empty()) << "overlaps " << b.text;
        // Another mode's line may cross the label only where the lines are
        // closer than a label is wide (53.3 and 88.7 Hz are 49 px apart on
        // the 760 px panel, the label 55 px wide); then it is flagged and
        // drawn on white. With 900 px there is room for every label.
        if (b.line_x >= a.x && b.line_x < a.x + a.width) {
          EXPECT_TRUE(a.over_marker_line) << "crosses the line of " << b.text << " unflagged";
          EXPECT_NE(w, 900) << "crosses the line of " << b.text;
        }
      }
    }
  }
}

// A panel filled by a curve has no clear place: the label is still drawn,
// flagged, on a white ground that no curve crosses.
TEST(Figure, LabelWithoutAClearPlaceIsFlaggedAndDrawnOnWhite) {
  Figure fig(1, 1, 500, 300);
  Axes& ax = fig.at(0, 0);
  Series zigzag;
  zigzag.color = PaletteColor(0);
  zigzag.thickness = 3;
  for (int i = 0; i <= 400; ++i) {
    zigzag.x.push_back(i);
    zigzag.y.push_back(i % 2);
  }
  ax.series.push_back(zigzag);
  ax.markers.push_back({200.0, "123.4 Hz"});
  std::vector<PlacedLabel> labels;
  const cv::Mat img = cv::imdecode(fig.EncodePng(&labels), cv::IMREAD_COLOR);
  ASSERT_EQ(labels.size(), 1u);
  EXPECT_FALSE(labels[0].clear);
  EXPECT_EQ(ColouredPixels(img, labels[0]), 0);
}

// 120 modes 3 Hz apart on a 600 x 200 px panel (frf-modes on
// dataset58_FRF.unv: 31 modes, the labels were drawn over each other): no
// two labels overlap, labels that find no room are left out, and the
// strongest keep theirs.
TEST(Figure, CrowdedMarkerLabelsNeverOverlapAndTheStrongestAreKept) {
  Figure fig(1, 1, 600, 200);
  Axes& ax = fig.at(0, 0);
  Series line;
  line.color = PaletteColor(0);
  for (int i = 0; i <= 100; ++i) {
    line.x.push_back(300.0 + 4.0 * i);
    line.y.push_back(std::sin(0.3 * i));
  }
  ax.series.push_back(line);
  ax.x_min = 300.0;
  ax.x_max = 700.0;
  const int n = 120;
  for (int k = 0; k < n; ++k) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.1f Hz", 310.0 + 3.0 * k);
    // Priorities in a scrambled order; mode 17 (361 Hz) is the strongest.
    ax.markers.push_back({310.0 + 3.0 * k, text, {120, 120, 120}, k == 17 ? 100.0 : static_cast<double>((k * 7) % 11)});
  }
  std::vector<PlacedLabel> labels;
  fig.EncodePng(&labels);
  ASSERT_GT(labels.size(), 0u);
  EXPECT_LT(labels.size(), static_cast<size_t>(n)) << "120 labels in ~10 rows of ~8 cannot all be placed";
  bool strongest = false;
  for (size_t i = 0; i < labels.size(); ++i) {
    strongest = strongest || labels[i].text == "361.0 Hz";
    for (size_t j = i + 1; j < labels.size(); ++j) {
      const cv::Rect a(labels[i].x, labels[i].y, labels[i].width, labels[i].height);
      const cv::Rect b(labels[j].x, labels[j].y, labels[j].width, labels[j].height);
      EXPECT_TRUE((a & b).empty()) << labels[i].text << " overlaps " << labels[j].text;
    }
  }
  EXPECT_TRUE(strongest) << "the label of the strongest mode (361.0 Hz) was left out";
}

// The legend lists only series with a point to draw ("measured, not used"
// with every line used has none), and leaves the preferred corner for the
// one that hides the fewest curve pixels when the preferred one hides some.
TEST(Figure, LegendListsSeriesWithPointsAndAvoidsTheData) {
  Figure fig(1, 1, 500, 300);
  Axes& ax = fig.at(0, 0);
  Series unused, used;
  unused.label = "measured, not used";
  used.label = "measured, usable";
  used.color = PaletteColor(0);
  used.thickness = 3;
  // A curve through the top right corner (the default legend corner) only:
  // y rises steeply at the right end.
  for (int i = 0; i <= 100; ++i) {
    unused.x.push_back(i);
    unused.y.push_back(NAN);
    used.x.push_back(i);
    used.y.push_back(i < 70 ? 0.0 : (i - 70) / 30.0);
  }
  ax.series = {unused, used};
  ax.y_min = 0.0;
  ax.y_max = 1.0;
  std::vector<PlacedLegend> legends;
  fig.EncodePng(nullptr, &legends);
  ASSERT_EQ(legends.size(), 1u);
  EXPECT_EQ(legends[0].entries, std::vector<std::string>{"measured, usable"});
  // Not top right any more: the box starts in the left half or the lower half.
  const bool left = legends[0].x < 200, low = legends[0].y > 150;
  EXPECT_TRUE(left || low) << legends[0].x << "," << legends[0].y;
  // With no curve in the top right corner the legend stays there.
  ax.series[1].y.assign(ax.series[1].y.size(), 0.0);
  fig.EncodePng(nullptr, &legends);
  ASSERT_EQ(legends.size(), 1u);
  EXPECT_GT(legends[0].x, 250);
  EXPECT_LT(legends[0].y, 150);
}

}  // namespace
}  // namespace robomach::report
