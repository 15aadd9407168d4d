#include "robomach/stability/milling.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "robomach/common/units.h"

namespace robomach::stability {

CuttingCoefficients CuttingCoefficients::FromKsBeta(double Ks, double beta_rad) {
  return {Ks * std::sin(beta_rad), Ks * std::cos(beta_rad), 0.0};
}

void MillingProcess::Validate() const {
  if (teeth < 1) {
    throw std::invalid_argument("teeth: expected a whole number >= 1, got " + std::to_string(teeth));
  }
  if (!(radial_immersion > 0.0 && radial_immersion <= 1.0)) {
    throw std::invalid_argument("radial_immersion: expected a value in (0, 1], got " +
                                std::to_string(radial_immersion));
  }
  const auto& c = coefficients;
  if (!(std::isfinite(c.Kt) && c.Kt > 0.0)) {
    throw std::invalid_argument("tangential cutting coefficient: expected a finite value > 0");
  }
  if (!std::isfinite(c.Kr) || !std::isfinite(c.Ka)) {
    throw std::invalid_argument("radial and axial cutting coefficients must be finite");
  }
}

double MillingProcess::entry_angle() const {
  return direction == MillingDirection::kUp ? 0.0 : std::acos(2.0 * radial_immersion - 1.0);
}

double MillingProcess::exit_angle() const {
  return direction == MillingDirection::kUp ? std::acos(1.0 - 2.0 * radial_immersion) : kPi;
}

Eigen::Matrix<double, 3, 2> DirectionalMatrixAt(const MillingProcess& p, double spindle_speed_rad_s,
                                                double t) {
  const double st = p.entry_angle(), ex = p.exit_angle();
  const auto& c = p.coefficients;
  Eigen::Matrix<double, 3, 2> H = Eigen::Matrix<double, 3, 2>::Zero();
  for (int j = 0; j < p.teeth; ++j) {
    double phi = std::fmod(spindle_speed_rad_s * t + 2.0 * kPi * j / p.teeth, 2.0 * kPi);
    if (phi < 0.0) phi += 2.0 * kPi;
    if (phi < st || phi > ex) continue;
    const double s = std::sin(phi), co = std::cos(phi);
    H(0, 0) += s * (c.Kt * co + c.Kr * s);
    H(0, 1) += co * (c.Kt * co + c.Kr * s);
    H(1, 0) += s * (-c.Kt * s + c.Kr * co);
    H(1, 1) += co * (-c.Kt * s + c.Kr * co);
    H(2, 0) += c.Ka * s;
    H(2, 1) += c.Ka * co;
  }
  return H;
}

namespace {

// Antiderivative of the single-tooth matrix h(φ) of (2) in closed form.
Eigen::Matrix<double, 3, 2> Antiderivative(const CuttingCoefficients& c, double phi) {
  const double c2 = std::cos(2.0 * phi), s2 = std::sin(2.0 * phi);
  Eigen::Matrix<double, 3, 2> I;
  I(0, 0) = 0.25 * (-c.Kt * c2 + c.Kr * (2.0 * phi - s2));
  I(0, 1) = 0.25 * (c.Kt * (2.0 * phi + s2) - c.Kr * c2);
  I(1, 0) = 0.25 * (-c.Kt * (2.0 * phi - s2) - c.Kr * c2);
  I(1, 1) = 0.25 * (c.Kt * c2 + c.Kr * (2.0 * phi + s2));
  I(2, 0) = -c.Ka * std::cos(phi);
  I(2, 1) = c.Ka * std::sin(phi);
  return I;
}

}  // namespace

Eigen::Matrix<double, 3, 2> MeanDirectionalMatrix(const MillingProcess& p, double psi0, double psi1) {
  const double st = p.entry_angle(), ex = p.exit_angle();
  Eigen::Matrix<double, 3, 2> sum = Eigen::Matrix<double, 3, 2>::Zero();
  const double len = psi1 - psi0;
  if (!(len > 0.0)) return DirectionalMatrixAt(p, 1.0, psi0);
  for (int j = 0; j < p.teeth; ++j) {
    double lo = psi0 + 2.0 * kPi * j / p.teeth;
    const double shift = 2.0 * kPi * std::floor(lo / (2.0 * kPi));
    lo -= shift;
    const double hi = lo + len;
    // [lo, hi] has lo in [0, 2π); it meets the engagement windows
    // [st + 2πm, ex + 2πm] for m = 0, 1, ... up to hi.
    for (int m = 0; st + 2.0 * kPi * m <= hi; ++m) {
      const double a = std::max(lo, st + 2.0 * kPi * m);
      const double b = std::min(hi, ex + 2.0 * kPi * m);
      if (b > a) sum += Antiderivative(p.coefficients, b) - Antiderivative(p.coefficients, a);
    }
  }
  return sum / len;
}

Eigen::Matrix<double, 3, 2> AverageDirectionalMatrix(const MillingProcess& p) {
  return MeanDirectionalMatrix(p, 0.0, 2.0 * kPi / p.teeth);
}

Eigen::Matrix3d CuttingStiffnessPerDepth(const MillingProcess& p) {
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
  K.leftCols<2>() = AverageDirectionalMatrix(p);
  return K;
}

}  // namespace robomach::stability
