#include "robomach/polishing/hertz_contact.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "robomach/common/units.h"

namespace robomach::polishing {
namespace {

// Johnson eq. 4.22: a = (3 F R / (4 E*))^(1/3), p0 = 3F/(2 pi a^2), delta = a^2/R.
TEST(HertzContact, SphereOnFlatClosedForm) {
  const double R = 0.05, F = 2.0;
  const double e_star = EffectiveModulus(10e6, 0.47, 200e9, 0.3);
  EXPECT_NEAR(e_star, 1.0 / ((1 - 0.47 * 0.47) / 10e6 + (1 - 0.09) / 200e9), 1e-6);
  const ContactEllipse c = HertzContact(Eigen::Matrix2d::Identity() / R, F, e_star);
  const double a = std::cbrt(3 * F * R / (4 * e_star));
  EXPECT_NEAR(c.a / a, 1.0, 1e-9);
  EXPECT_NEAR(c.b / a, 1.0, 1e-9);
  EXPECT_NEAR(c.p0 / (3 * F / (2 * kPi * a * a)), 1.0, 1e-9);
  EXPECT_NEAR(c.approach / (a * a / R), 1.0, 1e-9);
}

// Displacement of the surface under the Hertz pressure, by direct
// integration of Boussinesq's point-load solution u = p dA / (pi E* r),
// in polar coordinates about the field point (the 1/r cancels against r dr).
// Along each ray the pressure is p0 sqrt(quadratic); its integral is done by
// the substitution s = m + h sin(phi). Trapezoidal rule in the angle (the
// integrand is smooth and periodic for an interior point).
double Displacement(const ContactEllipse& c, double e_star, double x, double y) {
  const int n = 4000;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double th = 2 * kPi * k / n;
    // In elliptic units: X/a = ax + bx s, Y/b = ay + by s.
    const double ax = x / c.a, ay = y / c.b, bx = std::cos(th) / c.a, by = std::sin(th) / c.b;
    const double A = bx * bx + by * by, B = 2 * (ax * bx + ay * by), C = ax * ax + ay * ay - 1.0;
    const double disc = std::sqrt(B * B - 4 * A * C);
    const double s_lo = (-B - disc) / (2 * A), s_hi = (-B + disc) / (2 * A);  // s_lo < 0 < s_hi
    const double m = 0.5 * (s_lo + s_hi), h = 0.5 * (s_hi - s_lo);
    const double phi0 = std::asin(std::clamp(-m / h, -1.0, 1.0));
    // integral_0^{s_hi} sqrt(A (s_hi - s)(s - s_lo)) ds
    const double I = std::sqrt(A) * h * h *
                     ((kPi / 4) - (phi0 / 2 + std::sin(2 * phi0) / 4));
    sum += I;
  }
  return c.p0 * sum * (2 * kPi / n) / (kPi * e_star);
}

// An elliptic contact (a wheel of radius 50 mm, crown 200 mm, on a saddle-free
// doubly curved spot, principal axes at 30 degrees to the frame): inside the
// ellipse the elastic displacement plus the initial gap is one constant, the
// approach delta (gap equation, Johnson eq. 4.37), and the pressure integrates
// back to the force.
TEST(HertzContact, EllipticCaseSatisfiesGapEquationAndForce) {
  const double F = 2.0, e_star = EffectiveModulus(10e6, 0.47, 200e9, 0.3);
  const Eigen::Matrix2d Rot = Eigen::Rotation2Dd(0.52).toRotationMatrix();
  const Eigen::Matrix2d K = Rot * Eigen::Vector2d(1 / 0.05 + 5.0, 1 / 0.2 + 2.0).asDiagonal() * Rot.transpose();
  const ContactEllipse c = HertzContact(K, F, e_star);
  EXPECT_GT(c.eccentricity, 0.8);
  // The ellipse axes are K's principal directions; `a` nearer x.
  EXPECT_NEAR(std::abs(c.dir_a.dot(Rot.col(0))), 1.0, 1e-12);
  EXPECT_GT(std::abs(c.dir_a(0)), std::abs(c.dir_b(0)));
  EXPECT_LT(c.a, c.b);  // larger curvature along the axis nearer x: the short one
  for (auto [fx, fy] : {std::pair{0.0, 0.0}, {0.3, 0.2}, {-0.5, 0.6}, {0.7, -0.1}, {0.05, -0.9}}) {
    const double X = fx * c.a, Y = fy * c.b;  // ellipse axes
    const Eigen::Vector2d p = X * c.dir_a + Y * c.dir_b;
    const double gap = 0.5 * p.dot(K * p);
    const double u = Displacement(c, e_star, X, Y);
    EXPECT_NEAR((u + gap) / c.approach, 1.0, 1e-6) << fx << "," << fy;
  }
  // Force: integral of p over the ellipse (polar midpoint rule in the
  // normalised coordinates, radial integral of sqrt(1 - r^2) r dr = 1/3).
  double f = 0.0;
  const int nr = 20000;
  for (int i = 0; i < nr; ++i) {
    const double r = (i + 0.5) / nr;
    f += std::sqrt(1 - r * r) * r / nr;
  }
  f *= 2 * kPi * c.a * c.b * c.p0;
  EXPECT_NEAR(f / F, 1.0, 1e-5);
}

TEST(HertzContact, RejectsNonConvexRelativeCurvature) {
  Eigen::Matrix2d K;
  K << 20.0, 0.0, 0.0, -3.0;
  EXPECT_THROW(HertzContact(K, 2.0, 1e7), std::domain_error);
}

}  // namespace
}  // namespace robomach::polishing
