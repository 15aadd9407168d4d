// FillModalFitPanels: what the magnitude panel shows.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "robomach/report/modal_fit_plot.h"

namespace robomach::report {
namespace {

// A 1-DOF receptance (k = 1e6 N/m, 50 Hz, ζ = 0.03) whose |H| stays within
// 1e-9..3e-5 m/N on 1-500 Hz, with a noise floor of 1e-16 m/N: the axis
// stops at 1e-3 x the smallest measured |H|, so the floor is cut off
// instead of stretching the axis over ten decades. Every line usable: the
// legend does not list "measured, not used".
TEST(ModalFitPanels, TinyNoiseFloorDoesNotSetTheMagnitudeAxis) {
  const int n = 500;
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(n, 1.0, 500.0);
  Eigen::VectorXcd h(n);
  double h_min = INFINITY;
  for (int i = 0; i < n; ++i) {
    const double r = f(i) / 50.0;
    h(i) = 1e-6 / std::complex<double>(1.0 - r * r, 0.06 * r);
    h_min = std::min(h_min, std::abs(h(i)));
  }
  const dynamics::Frf frf = dynamics::Frf::FromSamples(f, h);
  calibration::FrfNoise noise;
  noise.usable.assign(n, 1);
  noise.floor_m_per_N = Eigen::VectorXd::Constant(n, 1e-16);
  noise.usable_bands = {{f(0), f(n - 1)}};
  Figure fig(2, 1, 600, 300);
  FillModalFitPanels(frf, noise, calibration::ModalFitResult{}, "t", &fig.at(0, 0), &fig.at(1, 0));
  const Axes& mag = fig.at(0, 0);
  ASSERT_TRUE(std::isfinite(mag.y_min));
  EXPECT_DOUBLE_EQ(mag.y_min, 1e-3 * h_min);
  std::vector<PlacedLegend> legends;
  fig.EncodePng(nullptr, &legends);
  ASSERT_GE(legends.size(), 1u);
  for (const std::string& e : legends[0].entries) EXPECT_EQ(e.find("not used"), std::string::npos) << e;
  // A floor within three decades of the data leaves the axis to the data.
  noise.floor_m_per_N.setConstant(1e-10);
  Figure fig2(2, 1, 600, 300);
  FillModalFitPanels(frf, noise, calibration::ModalFitResult{}, "t", &fig2.at(0, 0), &fig2.at(1, 0));
  EXPECT_TRUE(std::isnan(fig2.at(0, 0).y_min));
}

}  // namespace
}  // namespace robomach::report
