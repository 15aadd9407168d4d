// The taper contact stiffness of the spindle–toolholder interface
// (src/dynamics/internal/taper_contact.h) against hand calculations, the
// integral over a uniformly pressed cone, and a static solve.
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "dynamics/internal/taper_contact.h"
#include "robomach/common/units.h"

namespace robomach::dynamics::internal {
namespace {

// Hand calculation for the seed's HSK-E32 numbers (config/kr210.yaml):
// α = atan(0.05) = 0.0499584 rad; R₁ = 12.0035 mm, R₂ = R₁ − 16 mm·0.05 =
// 11.2035 mm; A = π (R₁ + R₂) L / cos α = 1.167968e-3 m²;
// p = 5000 / (A (sin α + 0.15 cos α)) = 2.143143e7 Pa;
// k_n = 3262540 · p^0.604 = 8.73999e10 N/m³; k_n A = 1.0208e8 N/m — the
// seed's "order 1e8 N/m" with p in Pa and k_n per unit area (N/m³). The
// hand numbers carry 7 digits, so 1e-6 relative.
TEST(TaperContact, PressureAndUnitStiffnessMatchHandCalculation) {
  const TaperContact tc = ComputeTaperContact({});
  EXPECT_NEAR(tc.half_angle_rad, 0.0499584, 1e-7);
  EXPECT_NEAR(tc.contact_area_m2, 1.167968e-3, 1e-6 * 1.167968e-3);
  EXPECT_NEAR(tc.pressure_Pa, 2.143143e7, 1e-6 * 2.143143e7);
  EXPECT_NEAR(tc.normal_stiffness_N_per_m3, 8.73999e10, 1e-5 * 8.73999e10);  // 6 digits given
  EXPECT_NEAR(tc.tangential_stiffness_N_per_m3, 0.5 * tc.normal_stiffness_N_per_m3, 1.0);
  // The condensed lateral stiffness is of the order the seed reports.
  EXPECT_GT(tc.K_master(0, 0), 3e7);
  EXPECT_LT(tc.K_master(0, 0), 3e8);
}

// Polynomials in the depth z as coefficient vectors (c₀ + c₁ z + ...).
using Poly = Eigen::VectorXd;
Poly Mul(const Poly& a, const Poly& b) {
  Poly c = Poly::Zero(a.size() + b.size() - 1);
  for (int i = 0; i < a.size(); ++i) c.segment(i, b.size()) += a(i) * b;
  return c;
}
double Integral(const Poly& p, double L) {  // ∫₀ᴸ p dz
  double s = 0.0;
  for (int i = 0; i < p.size(); ++i) s += p(i) * std::pow(L, i + 1) / (i + 1);
  return s;
}
double DerivativeAt(const Poly& p, double z) {
  double s = 0.0;
  for (int i = 1; i < p.size(); ++i) s += i * p(i) * std::pow(z, i - 1);
  return s;
}

// A rigid shank turns the condensation into Σ Tᵢᵀ kᵢ Tᵢ, the midpoint-rule
// sum of the stiffness per unit depth of a uniformly pressed cone. That
// integral in closed form: with r(z) = R₁ − z tan α and the ring stiffness
// (3) per unit depth a r, b r², e r³ (a = π/cos α (k_n cos²α + k_t sin²α +
// k_t), b = π/cos α sin α cos α (k_n − k_t), e = π/cos α (k_n sin²α +
// k_t cos²α)), and w = u − z θ,
//   K_uu = ∫ a r,  K_uθ = ∫ (b r² − z a r),  K_θθ = ∫ (z² a r − 2 z b r² + e r³).
// The integrands are cubics, for which the midpoint rule with N elements
// errs by exactly (h²/24)(f'(L) − f'(0)) (h = L/N; the h⁴ term needs f⁗).
// Removing that known error leaves rounding only: 1e-12 relative.
TEST(TaperContact, RigidShankSumEqualsConeIntegralWithMidpointError) {
  for (int N : {1, 6, 40}) {
    TaperContactOptions o;
    o.elements = N;
    o.shank_modulus_Pa = std::numeric_limits<double>::infinity();
    const TaperContact tc = ComputeTaperContact(o);
    const double al = tc.half_angle_rad, s = std::sin(al), c = std::cos(al);
    const double kn = tc.normal_stiffness_N_per_m3, kt = tc.tangential_stiffness_N_per_m3;
    const double a = kPi / c * (kn * c * c + kt * s * s + kt);
    const double b = kPi / c * s * c * (kn - kt);
    const double e = kPi / c * (kn * s * s + kt * c * c);
    const double L = o.length_m, h = L / N;
    const Poly r = (Poly(2) << 0.5 * o.large_diameter_m, -std::tan(al)).finished();
    const Poly z = (Poly(2) << 0.0, 1.0).finished();
    const Poly f_uu = a * r;
    const Poly f_ut = b * Mul(r, r) - a * Mul(z, r);
    const Poly f_tt = a * Mul(Mul(z, z), r) - 2.0 * b * Mul(z, Mul(r, r)) + e * Mul(r, Mul(r, r));
    auto midpoint = [&](const Poly& f) {
      return Integral(f, L) - h * h / 24.0 * (DerivativeAt(f, L) - DerivativeAt(f, 0.0));
    };
    EXPECT_NEAR(tc.K_plane(0, 0), midpoint(f_uu), 1e-12 * Integral(f_uu, L)) << N;
    EXPECT_NEAR(tc.K_plane(0, 1), midpoint(f_ut), 1e-12 * std::abs(Integral(f_ut, L))) << N;
    EXPECT_NEAR(tc.K_plane(1, 1), midpoint(f_tt), 1e-12 * Integral(f_tt, L)) << N;
    // And the sum converges to the integral itself as N grows (O(h²)).
    if (N == 40) EXPECT_NEAR(tc.K_plane(1, 1), Integral(f_tt, L), 1e-3 * Integral(f_tt, L));
  }
}

// Guyan's condensation is exact for statics: the 2×2 compliance at the gauge
// line from a static solve of the full system with unit loads there (slave
// nodes unloaded) is K_plane⁻¹. The full system's condition number is about
// (beam stiffness EI/h³ ≈ 1e11)/(ring stiffness ≈ 1e7) ≈ 1e4, so the two
// routes agree to ~1e4·eps ≈ 2e-12; 1e-9 relative leaves margin.
TEST(TaperContact, GuyanCondensationEqualsStaticSolve) {
  const TaperContact tc = ComputeTaperContact({});
  const int n = static_cast<int>(tc.K_full.rows());
  ASSERT_EQ(n, 2 * 7);
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(n, 2);
  F(0, 0) = 1.0;
  F(1, 1) = 1.0;
  const Eigen::MatrixXd X = tc.K_full.ldlt().solve(F);
  const Eigen::Matrix2d C = X.topRows<2>();
  const Eigen::Matrix2d C_guyan = tc.K_plane.inverse();
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      EXPECT_NEAR(C(i, j), C_guyan(i, j), 1e-9 * std::sqrt(C_guyan(i, i) * C_guyan(j, j)));
    }
  }
  // Positive definite and symmetric in both planes, with the y–z plane the
  // mirror of the x–z plane (θ_x = −θ_y for the same lateral motion).
  EXPECT_EQ(Eigen::LLT<Eigen::Matrix4d>(tc.K_master).info(), Eigen::Success);
  EXPECT_DOUBLE_EQ(tc.K_master(1, 1), tc.K_master(0, 0));
  EXPECT_DOUBLE_EQ(tc.K_master(2, 2), tc.K_master(3, 3));
  EXPECT_DOUBLE_EQ(tc.K_master(1, 2), -tc.K_master(0, 3));
}

// An elastic shank is a spring in series with the contact: softer than the
// rigid-shank limit, and the difference falls as 1/E (first order in the
// shank compliance), so multiplying E by 10 divides it by ≈ 10 (between 8
// and 12 allows for the second-order term, which is ≈ the first-order one
// times the compliance ratio ≈ 1e-2 here).
TEST(TaperContact, ElasticShankConvergesToRigidAsOneOverModulus) {
  TaperContactOptions o;
  o.shank_modulus_Pa = std::numeric_limits<double>::infinity();
  const Eigen::Matrix2d Kr = ComputeTaperContact(o).K_plane;
  o.shank_modulus_Pa = 2.1e11;
  const Eigen::Matrix2d K1 = ComputeTaperContact(o).K_plane;
  o.shank_modulus_Pa = 2.1e12;
  const Eigen::Matrix2d K2 = ComputeTaperContact(o).K_plane;
  EXPECT_LT(K1(1, 1), Kr(1, 1));
  EXPECT_LT(K1(0, 0), Kr(0, 0));
  const double ratio = (Kr(1, 1) - K1(1, 1)) / (Kr(1, 1) - K2(1, 1));
  EXPECT_GT(ratio, 8.0);
  EXPECT_LT(ratio, 12.0);
}

TEST(TaperContact, RejectsBadOptionsWithTheirName) {
  TaperContactOptions o;
  o.drawbar_force_N = -1.0;
  EXPECT_THROW(ComputeTaperContact(o), std::invalid_argument);
  o = {};
  o.elements = 0;
  try {
    ComputeTaperContact(o);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("elements"), std::string::npos);
  }
}

}  // namespace
}  // namespace robomach::dynamics::internal
