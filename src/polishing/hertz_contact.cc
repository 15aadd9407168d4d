#include "robomach/polishing/hertz_contact.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "robomach/common/units.h"

namespace robomach::polishing {
namespace {

// (K(e) - E(e)) / e^2 without cancellation for small e (series
// pi/4 (1 + 3 e^2 / 8 + ...)).
double KminusEOverE2(double e) {
  if (e < 1e-4) return kPi / 4.0 * (1.0 + 3.0 / 8.0 * e * e);
  return (std::comp_ellint_1(e) - std::comp_ellint_2(e)) / (e * e);
}

// Ratio of curvature halves B/A (B >= A) for an ellipse of axis ratio k = b/a
// (b <= a), Johnson eq. 4.40: B/A = ((a/b)^2 E - K) / (K - E).
double CurvatureRatio(double k) {
  const double e = std::sqrt(std::max(0.0, 1.0 - k * k));
  const double E = std::comp_ellint_2(e);
  const double K = std::comp_ellint_1(e);
  const double kme = KminusEOverE2(e) * e * e;
  return (E / (k * k) - K) / kme;
}

}  // namespace

double EffectiveModulus(double modulus1_pa, double poisson1, double modulus2_pa, double poisson2) {
  return 1.0 / ((1.0 - poisson1 * poisson1) / modulus1_pa + (1.0 - poisson2 * poisson2) / modulus2_pa);
}

ContactEllipse HertzContact(const Eigen::Matrix2d& K, double force, double e_star) {
  if (!(force > 0.0) || !(e_star > 0.0) || !K.allFinite()) {
    throw std::domain_error("Hertz contact needs a positive force and modulus and a finite curvature");
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(0.5 * (K + K.transpose()));
  const double k_small = eig.eigenvalues()(0), k_large = eig.eigenvalues()(1);  // ascending
  if (!(k_small > 0.0)) {
    std::ostringstream m;
    m << "relative curvature not positive (principal values " << k_small << " and " << k_large
      << " 1/m): a concave spot sharper than the wheel, the contact is not a single Hertz ellipse";
    throw std::domain_error(m.str());
  }
  const double A = 0.5 * k_small, B = 0.5 * k_large;  // gap h = A x^2 + B y^2
  const double ratio = B / A;
  // Axis ratio k = minor/major from B/A: CurvatureRatio decreases from
  // infinity (k -> 0) to 1 (k = 1). Safeguarded secant from Johnson's
  // approximation k ~ (A/B)^(2/3) (eq. 4.43), bisection when a step leaves
  // the bracket; ~5 iterations where plain bisection needs ~50 (this runs
  // once per path row).
  double k = 1.0;
  if (ratio > 1.0 + 1e-12) {
    double lo = 1e-9, hi = 1.0;  // g(lo) > 0 > g(hi)
    auto g = [&](double x) { return CurvatureRatio(x) - ratio; };
    double x0 = std::clamp(std::pow(ratio, -2.0 / 3.0), 2e-9, 1.0 - 1e-9);
    double g0 = g(x0);
    (g0 > 0 ? lo : hi) = x0;
    double x1 = std::clamp(x0 * (g0 > 0 ? 1.02 : 0.98), lo, hi);
    for (int it = 0; it < 100; ++it) {
      const double g1 = g(x1);
      if (g1 == 0.0) {
        lo = hi = x1;
        break;
      }
      (g1 > 0 ? lo : hi) = x1;
      if (hi - lo <= 1e-15 * hi || std::abs(g1) <= 1e-14 * ratio) break;
      double x2 = (g1 != g0) ? x1 - g1 * (x1 - x0) / (g1 - g0) : 0.5 * (lo + hi);
      if (!(x2 > lo && x2 < hi)) x2 = 0.5 * (lo + hi);
      x0 = x1;
      g0 = g1;
      x1 = x2;
    }
    k = x1;
  }
  const double e = std::sqrt(std::max(0.0, 1.0 - k * k));
  // Johnson eq. 4.39 with p0 b = 3F/(2 pi a): A E* = 3F (K - E) / (2 pi e^2 a^3).
  const double major = std::cbrt(3.0 * force * KminusEOverE2(e) / (2.0 * kPi * A * e_star));
  const double minor = k * major;
  ContactEllipse c;
  c.eccentricity = e;
  c.p0 = 3.0 * force / (2.0 * kPi * major * minor);
  c.approach = c.p0 * minor * std::comp_ellint_1(e) / e_star;
  // Major axis along the smaller curvature.
  const Eigen::Vector2d d_major = eig.eigenvectors().col(0).normalized();
  const Eigen::Vector2d d_minor = eig.eigenvectors().col(1).normalized();
  if (std::abs(d_major(0)) >= std::abs(d_minor(0))) {
    c.a = major, c.b = minor, c.dir_a = d_major, c.dir_b = d_minor;
  } else {
    c.a = minor, c.b = major, c.dir_a = d_minor, c.dir_b = d_major;
  }
  if (c.dir_a(0) < 0.0) c.dir_a = -c.dir_a;
  c.dir_b = Eigen::Vector2d(-c.dir_a(1), c.dir_a(0));
  return c;
}

}  // namespace robomach::polishing
