#pragma once

// Pearson correlation and its 5 %-significance threshold, for the trends of
// a model's error against posture descriptors (issue #5 §2.2). With the few
// postures of a hammer-test campaign a correlation is only indicative; the
// threshold says how large |r| must be before it means anything at all.

#include <Eigen/Core>

namespace robomach::audit {

/// Pearson's sample correlation coefficient
/// <pre>
///   r = Σ (x_i − x̄)(y_i − ȳ) / √(Σ (x_i − x̄)² · Σ (y_i − ȳ)²)        (1)
/// </pre>
/// NaN if there are fewer than 2 points or x or y does not vary (r is
/// undefined then, not zero).
/// @throws std::invalid_argument if x and y differ in size.
double PearsonCorrelation(const Eigen::VectorXd& x, const Eigen::VectorXd& y);

/// The smallest |r| of n points that a two-sided t-test rejects "no
/// correlation" with at level `alpha`. Under that hypothesis (and normal
/// scatter) t = r √ν / √(1 − r²), ν = n − 2, follows Student's t with ν
/// degrees of freedom, so the threshold is r_c = t_c / √(ν + t_c²) with
/// t_c the 1 − alpha/2 quantile. Substituting sin θ = r, cos θ = √(1 − r²)
/// into the closed forms of P(|T| ≤ t) for integer ν
/// [Abramowitz & Stegun 1964, §26.7] gives it directly in r:
/// <pre>
///   ν = 1:     A = 2θ/π
///   ν odd:     A = 2/π [θ + r (c + 2/3 c³ + … + (2·4⋯(ν−3))/(1·3⋯(ν−2)) c^(ν−2))]
///   ν even:    A = r [1 + 1/2 c² + … + (1·3⋯(ν−3))/(2·4⋯(ν−2)) c^(ν−2)]
/// </pre>
/// with θ = asin r, c = cos θ; A increases with r, and r_c solves
/// A = 1 − alpha (bisection to 1e-14).
/// Returns NaN for n < 3 (no degrees of freedom left).
/// @throws std::invalid_argument unless 0 < alpha < 1.
///
/// - [Abramowitz & Stegun 1964] M. Abramowitz, I. A. Stegun, Handbook of
///   Mathematical Functions, NBS Applied Mathematics Series 55, 1964.
double CriticalCorrelation(int n, double alpha = 0.05);

}  // namespace robomach::audit
