// The calibration report: Table 3 rows and the JSON summary from hand-made
// comparisons whose errors are known exactly.
#include <gtest/gtest.h>

#include <fstream>

#include "robomach/io/csv_table.h"
#include "robomach/report/calibration_report.h"
#include "test_support.h"

namespace robomach::report {
namespace {

calibration::ModeMatch Match(double f_meas, double f_model, double a_meas, double a_model) {
  calibration::ModeMatch m;
  m.key = {"P1", Axis::kY, Axis::kY};
  m.measured = 0;
  m.model_mode = 1;
  m.measured_freq_hz = f_meas;
  m.model_freq_hz = f_model;
  m.measured_peak = a_meas;
  m.model_peak = a_model;
  m.model_shape_T = Eigen::Vector3d(0.0, 1.0, 0.0);
  return m;
}

// Relative errors are model / measured − 1: 101/100 − 1 = 1 % and
// 0.97e-6/1e-6 − 1 = −3 %, exact up to one rounding of the division and the
// ×100 (≤ 1e-13 % here).
TEST(CalibrationReport, Table3RowsCarryErrorsBeforeAndAfter) {
  const std::string dir = robomach::testing::TempDir("calibration_report");
  TableSet s;
  s.label = "fit";
  s.before.matches = {Match(100.0, 104.0, 1e-6, 1.5e-6)};
  s.after.matches = {Match(100.0, 101.0, 1e-6, 0.97e-6)};
  WriteTable3Csv(dir + "/t.csv", {s});
  const io::CsvTable t = io::CsvTable::ReadFile(dir + "/t.csv");
  ASSERT_EQ(t.num_rows(), 1);
  EXPECT_EQ(t.Text(0, "pose_id"), "P1");
  EXPECT_EQ(t.Text(0, "response"), "y");
  EXPECT_EQ(t.Number(0, "model_mode"), 2.0);
  EXPECT_NEAR(t.Number(0, "freq_error_pct"), 1.0, 1e-12);
  EXPECT_NEAR(t.Number(0, "freq_error_before_pct"), 4.0, 1e-12);
  EXPECT_NEAR(t.Number(0, "peak_error_pct"), -3.0, 1e-12);
  EXPECT_NEAR(t.Number(0, "peak_error_before_pct"), 50.0, 1e-12);
  EXPECT_EQ(t.Number(0, "uy"), 1.0);

  calibration::CalibrationResult r;
  r.status = calibration::FitStatus::kConverged;
  r.estimates.push_back({"m6_kg", "kg", 29.05, 31.0, 0.1, false, false, "frequencies"});
  const nlohmann::json j = CalibrationSummaryJson(r, {}, {s});
  EXPECT_EQ(j["status"], "converged");
  EXPECT_EQ(j["objective"], "modal-two-stage");
  EXPECT_EQ(j["parameters"][0]["name"], "m6_kg");
  EXPECT_DOUBLE_EQ(j["parameters"][0]["std_dev"].get<double>(), 0.1);
  EXPECT_NEAR(j["sets"]["fit"]["max_abs_freq_error"]["after"].get<double>(), 0.01, 1e-15);
  EXPECT_NEAR(j["sets"]["fit"]["postures"]["P1"]["max_abs_peak_error"]["before"].get<double>(), 0.5, 1e-15);
  WriteTable3Markdown(dir + "/t.md", {s}, "test");
  std::ifstream md(dir + "/t.md");
  const std::string text((std::istreambuf_iterator<char>(md)), {});
  EXPECT_NE(text.find("| P1 | yy | 2 | 100.000 | 101.000 | 1.00 | 4.00 |"), std::string::npos) << text;
}

}  // namespace
}  // namespace robomach::report
