// The error-pattern part of the model-audit report on a hand-made
// ErrorPatterns: JSON keys and nulls, unit conversion at the boundary
// (joint angles in degrees), 1-based mode numbers, and PNGs that decode.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgcodecs.hpp>

#include "robomach/common/units.h"
#include "robomach/io/number_format.h"
#include "robomach/report/audit_patterns_report.h"

namespace robomach::report {
namespace {

audit::ErrorPatterns Sample() {
  audit::ErrorPatterns p;
  audit::ErrorTrends& t = p.trends;
  t.pose_ids = {"P1", "P2", "P3"};
  t.n = 3;
  t.critical_correlation = 0.997;
  t.error_before = Eigen::Vector3d(0.1, 0.2, 0.3);
  audit::Trend q;
  q.descriptor = "q2";
  q.unit = "rad";
  q.values = Eigen::Vector3d(-kPi / 2, -kPi / 4, 0.0);
  q.correlation_before = 0.999;
  q.significant_before = true;
  audit::Trend reach;
  reach.descriptor = "reach";
  reach.unit = "m";
  reach.values = Eigen::Vector3d(2.0, 2.0, 2.0);  // no spread: r undefined
  t.trends = {q, reach};
  audit::ModeErrorMap& m = p.mode_map;
  m.pose_ids = t.pose_ids;
  m.modes = {1, 3};
  m.freq_error = Eigen::MatrixXd::Constant(3, 2, NAN);
  m.peak_error = Eigen::MatrixXd::Constant(3, 2, NAN);
  m.match = Eigen::MatrixXi::Constant(3, 2, -1);
  calibration::ModeMatch mm;
  mm.key = {"P2", Axis::kY, Axis::kY};
  mm.model_mode = 2;
  mm.model_freq_hz = 11.0;
  mm.measured_freq_hz = 10.0;
  mm.model_peak = 1e-6;
  mm.measured_peak = 2e-6;
  m.matches = {mm};
  m.match(1, 1) = 0;
  m.freq_error(1, 1) = mm.freq_error();
  m.peak_error(1, 1) = mm.peak_error();
  audit::UnmatchedMode um;
  um.key = {"P3", Axis::kX, Axis::kX};
  um.freq_hz = 64.3;
  um.model_mode = 3;
  um.relative_visibility = 0.4;
  p.unmatched_model = {um};
  audit::UnmatchedMode ms;
  ms.key = {"P1", Axis::kY, Axis::kY};
  ms.freq_hz = 400.0;
  ms.measured_mode = 7;
  ms.relative_visibility = 0.01;
  p.unmatched_measured = {ms};
  return p;
}

TEST(AuditPatternsReport, JsonKeysUnitsAndNulls) {
  const AuditPatternsReport r = MakeAuditPatternsReport(Sample(), 0.05, "test");
  ASSERT_EQ(r.trends.size(), 2u);
  EXPECT_EQ(r.trends[0]["descriptor"], "q2");
  EXPECT_EQ(r.trends[0]["unit"], "deg");  // converted at the boundary
  EXPECT_EQ(r.trends[0]["n"], 3);
  EXPECT_EQ(r.trends[0]["significant"], true);
  EXPECT_DOUBLE_EQ(r.trends[0]["correlation"].get<double>(), 0.999);
  EXPECT_TRUE(r.trends[1]["correlation"].is_null());
  EXPECT_TRUE(r.trends[0]["correlation_after"].is_null());  // no candidate accepted
  // Degrees: −π/2 rad = −90°, exactly up to one rounding.
  EXPECT_NEAR(r.posture_descriptors["P1"]["q2_deg"].get<double>(), -90.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.posture_descriptors["P3"]["reach_m"].get<double>(), 2.0);
  // The map: nulls where no match, the relative errors where matched.
  EXPECT_EQ(r.mode_error_map["modes"], nlohmann::json({1, 3}));
  EXPECT_EQ(r.mode_error_map["poses"], nlohmann::json({"P1", "P2", "P3"}));
  EXPECT_TRUE(r.mode_error_map["freq_error_rel"][0][0].is_null());
  EXPECT_NEAR(r.mode_error_map["freq_error_rel"][1][1].get<double>(), 0.1, 1e-15);   // 11/10 − 1
  EXPECT_NEAR(r.mode_error_map["peak_error_rel"][1][1].get<double>(), -0.5, 1e-15);  // 1/2 − 1
  // Unmatched: model modes numbered from 1, directions as "xx".
  ASSERT_EQ(r.unmatched_model_modes.size(), 1u);
  EXPECT_EQ(r.unmatched_model_modes[0]["model_mode"], 4);
  EXPECT_EQ(r.unmatched_model_modes[0]["direction"], "xx");
  EXPECT_EQ(r.unmatched_model_modes[0]["pose"], "P3");
  ASSERT_EQ(r.unmatched_measured_modes.size(), 1u);
  EXPECT_DOUBLE_EQ(r.unmatched_measured_modes[0]["frequency_hz"].get<double>(), 400.0);
  EXPECT_EQ(r.unmatched_measured_modes[0]["direction"], "yy");
}

TEST(AuditPatternsReport, CsvRowsAndPngs) {
  const AuditPatternsReport r = MakeAuditPatternsReport(Sample(), 0.05, "test");
  EXPECT_EQ(r.trends_csv.substr(0, r.trends_csv.find('\n')),
            "descriptor,unit,n,critical_correlation,correlation_before,significant_before,correlation_after,"
            "significant_after");
  EXPECT_NE(r.trends_csv.find("\nreach,m,3,0.997,,no,,\n"), std::string::npos) << r.trends_csv;
  // One row per posture and mode; an empty cell keeps its pose and mode.
  EXPECT_NE(r.mode_errors_csv.find("\nP1,1,,,,,,,,\n"), std::string::npos) << r.mode_errors_csv;
  // The relative error as the CSV writer prints any double (round-trip form
  // of 11/10 − 1, which is not exactly 0.1).
  EXPECT_NE(r.mode_errors_csv.find("\nP2,3,y,y,11,10," + io::FormatDouble(11.0 / 10.0 - 1.0) + ",1e-06,2e-06,-0.5\n"),
            std::string::npos)
      << r.mode_errors_csv;
  EXPECT_NE(r.unmatched_modes_csv.find("\nmodel,P3,x,x,4,64.3,"), std::string::npos) << r.unmatched_modes_csv;
  EXPECT_NE(r.posture_descriptors_csv.find("pose_id,error_before,error_after,q2_deg,reach_m\n"), std::string::npos);
  for (const auto* png : {&r.trends_png, &r.mode_error_map_png}) {
    ASSERT_FALSE(png->empty());
    EXPECT_FALSE(cv::imdecode(*png, cv::IMREAD_COLOR).empty());
  }
  EXPECT_NE(r.html.find("trends.png"), std::string::npos);
  EXPECT_NE(r.html.find("mode_error_map.png"), std::string::npos);
}

// trends.png draws only descriptors that vary over the postures (issue #35:
// ten near-identical panels): reach has no spread here (r undefined), so
// one row with q2; no candidate, so one column (620 x 300 px + the title).
TEST(AuditPatternsReport, TrendsPngDrawsOnlyDescriptorsThatVary) {
  const AuditPatternsReport r = MakeAuditPatternsReport(Sample(), 0.05, "test");
  EXPECT_EQ(r.trends_png_descriptors, std::vector<std::string>{"q2"});
  const cv::Mat img = cv::imdecode(r.trends_png, cv::IMREAD_COLOR);
  EXPECT_EQ(img.cols, 620);
  EXPECT_EQ(img.rows, 300 + 34);
  EXPECT_NE(r.html.find("against q2 (the strongest correlations; the table has them all)"), std::string::npos)
      << r.html;
}

}  // namespace
}  // namespace robomach::report
