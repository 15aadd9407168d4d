#include "robomach/audit/correlation.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "robomach/common/units.h"

namespace robomach::audit {

double PearsonCorrelation(const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  if (x.size() != y.size()) {
    throw std::invalid_argument("PearsonCorrelation: x has " + std::to_string(x.size()) + " entries, y has " +
                                std::to_string(y.size()));
  }
  if (x.size() < 2) return NAN;
  // Two passes (centre first): the one-pass Σxy − n x̄ȳ cancels badly for
  // descriptors with a large mean and a small spread (a height of 1.5 m ± 5 mm).
  const Eigen::ArrayXd dx = x.array() - x.mean(), dy = y.array() - y.mean();
  const double sxx = dx.square().sum(), syy = dy.square().sum();
  if (!(sxx > 0.0) || !(syy > 0.0)) return NAN;
  return (dx * dy).sum() / std::sqrt(sxx * syy);
}

namespace {

// P(|T| ≤ t) for Student's t with ν degrees of freedom, written in
// r = sin θ = t / √(ν + t²) (see the header).
double TwoSidedProbability(double r, int nu) {
  const double c = std::sqrt(std::max(0.0, 1.0 - r * r)), c2 = c * c;
  if (nu % 2 == 1) {
    double term = c, sum = nu > 1 ? c : 0.0;  // the series is empty for ν = 1
    for (int k = 2; k <= nu - 2; k += 2) {
      term *= c2 * k / (k + 1.0);  // 2·4⋯k / (1·3⋯(k+1)) c^(k+1)
      sum += term;
    }
    return 2.0 / kPi * (std::asin(r) + r * sum);
  }
  double term = 1.0, sum = 1.0;
  for (int k = 1; k <= nu - 3; k += 2) {
    term *= c2 * k / (k + 1.0);  // 1·3⋯k / (2·4⋯(k+1)) c^(k+1)
    sum += term;
  }
  return r * sum;
}

}  // namespace

double CriticalCorrelation(int n, double alpha) {
  if (!(alpha > 0.0 && alpha < 1.0)) {
    throw std::invalid_argument("CriticalCorrelation: alpha must be in (0, 1), got " + std::to_string(alpha));
  }
  if (n < 3) return NAN;
  const int nu = n - 2;
  double lo = 0.0, hi = 1.0;
  while (hi - lo > 1e-14) {
    const double mid = 0.5 * (lo + hi);
    (TwoSidedProbability(mid, nu) < 1.0 - alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace robomach::audit
