#pragma once
// kq-identify --plot: the residual of every load case against the noise and
// the outlier threshold, and measured against predicted displacement
// components. In millimetres, as the tool writes them.

#include <string>
#include <vector>

#include <Eigen/Core>

namespace robomach::report {

struct CaseResidualsMm {
  std::vector<double> norm_mm;  // |measured - predicted| per case, file order
  std::vector<bool> outlier;    // per case
  std::vector<Eigen::Vector3d> predicted_mm, measured_mm;  // per case
  double noise_sigma_mm{0.0};   // tracker noise per coordinate (1 sigma)
  double threshold_mm{0.0};     // the outlier threshold on norm_mm
};

/// Draws the two panels to a PNG. E|r| for 3 Gaussian components of sigma
/// is sigma 2 sqrt(2/pi) = 1.6 sigma: the "expected from tracker noise" line.
void SaveCaseResidualFigure(const std::string& path, const std::string& title, const CaseResidualsMm& r);

}  // namespace robomach::report
