#pragma once

// Hertzian elliptic contact of two elastic bodies (K. L. Johnson, Contact
// Mechanics, 1985, §4.2, eqs. 4.39-4.40, with complete elliptic integrals).

#include <Eigen/Core>

namespace robomach::polishing {

/// 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2  [Pa] (formats.md §7).
double EffectiveModulus(double modulus1_pa, double poisson1, double modulus2_pa, double poisson2);

/// The contact ellipse. Semi-axes `a` and `b` lie along unit directions
/// `dir_a`, `dir_b` of the 2-D frame the relative curvature was given in;
/// `a` is the axis nearer that frame's x axis (tool x), whatever its length.
struct ContactEllipse {
  double a{0.0}, b{0.0};        // semi-axes [m]
  Eigen::Vector2d dir_a{1, 0};  // unit, in the input frame
  Eigen::Vector2d dir_b{0, 1};
  double p0{0.0};               // peak pressure 3F / (2 pi a b) [Pa]
  double approach{0.0};         // mutual approach delta of distant points [m]
  double eccentricity{0.0};     // e = sqrt(1 - (minor/major)^2)
};

/// Contact ellipse for the relative curvature tensor `K` (symmetric, 1/m;
/// the sum of both bodies' curvature tensors in one tangent frame, convex
/// positive, so that the initial gap is h = 1/2 x^T K x) under normal force
/// `force` [N] with effective modulus `e_star` [Pa].
/// @throws std::domain_error if K is not positive definite (a concave spot
///   sharper than the convex body: the contact is not a single ellipse) or
///   force/modulus are not positive.
ContactEllipse HertzContact(const Eigen::Matrix2d& K, double force, double e_star);

}  // namespace robomach::polishing
