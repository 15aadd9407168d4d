#include "robomach/drilling/drill_forces.h"

#include <cmath>
#include <complex>
#include <stdexcept>

#include <gtest/gtest.h>

namespace robomach::drilling {
namespace {

DrillingMaterial TestMaterial() {
  DrillingMaterial m;
  m.shear_stress_thrust = 700e6;
  m.shear_stress_torque = 900e6;
  m.kienzle_exponent = 0.3;
  m.reference_chip_thickness = 0.1e-3;
  return m;
}

// Composite 5-point Gauss-Legendre quadrature of one lip integrand over
// [a, b]: a second, independent integration of the same dF/dr.
LipIntegrand GaussLegendre(const DrillGeometry& d, const DrillingMaterial& m, double f, double a,
                           double b, int panels) {
  static const double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640,
                              0.9061798459386640};
  static const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                              0.2369268850561891, 0.2369268850561891};
  LipIntegrand s;
  const double hw = (b - a) / panels;
  for (int k = 0; k < panels; ++k) {
    const double c = a + (k + 0.5) * hw;
    for (int j = 0; j < 5; ++j) {
      const LipIntegrand g = LipForcePerRadius(d, m, f, c + 0.5 * hw * x[j], true);
      s.thrust += 0.5 * hw * w[j] * g.thrust;
      s.torque += 0.5 * hw * w[j] * g.torque;
      s.radial += 0.5 * hw * w[j] * g.radial;
    }
  }
  return s;
}

TEST(DrillForces, StandardDrillAnglesMatchHandComputation) {
  // 118 deg point, 30 deg helix, web 0.18 D (the default drill). Formula
  // (C1) evaluated separately (Python, math module): at r = D/2,
  // w = asin(0.18) = 10.36976 deg and g = 29.18287 deg. This checks the
  // coding of (C1), not the formula itself; the textbook range (about +30 deg
  // at the corner, about -30 deg near the chisel) checks that.
  const DrillGeometry d;
  const LipElementAngles a = ComputeLipElementAngles(d, 0.1e-3, d.radius(), false);
  EXPECT_NEAR(RadToDeg(a.web_angle), 10.36976, 1e-5);
  EXPECT_NEAR(RadToDeg(a.static_rake), 29.18287, 1e-5);
  // The rake falls towards the web, to about -30 deg near the chisel edge.
  const LipElementAngles inner = ComputeLipElementAngles(d, 0.1e-3, d.chisel_half_length() * 1.01,
                                                         false);
  EXPECT_LT(RadToDeg(inner.static_rake), -25.0);
}

TEST(DrillForces, ElementSumConvergesToDirectQuadrature) {
  const DrillGeometry d;
  const DrillingMaterial m = TestMaterial();
  const double f = 0.1e-3;
  // Reference: 5-point Gauss-Legendre on 400 panels (error ~ (h)^10 f^(10),
  // far below 1e-10 relative for this smooth integrand on [r_c, R]).
  const LipIntegrand ref = GaussLegendre(d, m, f, d.chisel_half_length(), d.radius(), 400);
  const LipIntegrand ref2 = GaussLegendre(d, m, f, d.chisel_half_length(), d.radius(), 800);
  ASSERT_NEAR(ref.thrust, ref2.thrust, 1e-12 * std::abs(ref.thrust));
  ForceModelOptions o60{.num_elements = 60}, o120{.num_elements = 120},
      o100{.num_elements = 100}, o2000{.num_elements = 2000};
  const LipIntegrand e60 = IntegrateLip(d, m, f, d.radius(), o60);
  const LipIntegrand e120 = IntegrateLip(d, m, f, d.radius(), o120);
  const LipIntegrand e2000 = IntegrateLip(d, m, f, d.radius(), o2000);
  // The midpoint rule is second order: halving the element size divides
  // the error by 4 (3.5..4.5 allows for the next term of the expansion).
  const double r_th = (e60.thrust - ref.thrust) / (e120.thrust - ref.thrust);
  const double r_tq = (e60.torque - ref.torque) / (e120.torque - ref.torque);
  EXPECT_GT(r_th, 3.5);
  EXPECT_LT(r_th, 4.5);
  EXPECT_GT(r_tq, 3.5);
  EXPECT_LT(r_tq, 4.5);
  // Second order with the leading error of 60 elements at 1.2e-3 (thrust)
  // and 1.7e-3 (radial; the r / sqrt(r^2 - w_t^2) factor is steep near r_c):
  // the default 100 elements are within (60/100)^2 * 1.7e-3 = 6e-4, 2000
  // within (60/2000)^2 * 1.7e-3 = 1.5e-6.
  const LipIntegrand e100 = IntegrateLip(d, m, f, d.radius(), o100);
  EXPECT_NEAR(e100.thrust, ref.thrust, 7e-4 * ref.thrust);
  EXPECT_NEAR(e100.torque, ref.torque, 7e-4 * ref.torque);
  EXPECT_NEAR(e100.radial, ref.radial, 7e-4 * ref.radial);
  EXPECT_NEAR(e2000.thrust, ref.thrust, 2e-6 * ref.thrust);
  EXPECT_NEAR(e2000.torque, ref.torque, 2e-6 * ref.torque);
}

TEST(DrillForces, ZeroHelixZeroWebIsOrthogonalCuttingClosedForm) {
  DrillGeometry d;
  d.helix_angle = 0.0;
  d.web_thickness_ratio = 0.0;
  DrillingMaterial m = TestMaterial();
  m.chisel = ChiselModel::kNone;
  const double f = 0.12e-3;
  // Zero web and helix: w = i = 0, rake 0 everywhere (static, no feed
  // angle), so every element is orthogonal cutting with Merchant-type angles
  // beta = 30 deg, phi = 45 - 15 = 30 deg:
  //   F_c / (tau b h) = cos 30 / (sin 30 cos 60) = 2 sqrt(3),
  //   F_t / (tau b h) = sin 30 / (sin 30 cos 60) = 2,
  // with b = dr / sin p, h = (f/2) sin p. Two lips:
  //   T = 2 K_TQ s h 2 sqrt(3) R^2 / (2 sin p),  F = 2 K_TH s h 2 R.
  const double p = d.half_point_angle();
  const double R = d.radius();
  const double h = 0.5 * f * std::sin(p);
  const double s = std::pow(h / m.reference_chip_thickness, -m.kienzle_exponent);
  const double T = 2.0 * m.shear_stress_torque * s * h * 2.0 * std::sqrt(3.0) * R * R /
                   (2.0 * std::sin(p));
  const double F = 2.0 * m.shear_stress_thrust * s * h * 2.0 * R;
  DrillState st{.feed_per_rev = f, .penetration = 1.0};
  const DrillForces out = ComputeDrillForces(d, m, st, {.num_elements = 7, .dynamic_rake = false});
  // Midpoint rule on integrands constant (thrust) and linear (torque) in r is
  // exact; only rounding remains.
  EXPECT_NEAR(out.thrust, F, 1e-12 * F);
  EXPECT_NEAR(out.torque, T, 1e-12 * T);
  EXPECT_TRUE(out.fully_engaged);
  // And the force scales exactly as f^(1-m) (Kienzle).
  st.feed_per_rev = 2.0 * f;
  const DrillForces twice = ComputeDrillForces(d, m, st, {.num_elements = 7, .dynamic_rake = false});
  EXPECT_NEAR(twice.thrust / out.thrust, std::pow(2.0, 1.0 - m.kienzle_exponent), 1e-12);
}

TEST(DrillForces, SeedChiselScalingMultipliesTheLips) {
  const DrillGeometry d;
  DrillingMaterial m = TestMaterial();
  const DrillState st{.feed_per_rev = 0.1e-3, .penetration = 5e-3};
  m.chisel = ChiselModel::kNone;
  const DrillForces lips = ComputeDrillForces(d, m, st);
  m.chisel = ChiselModel::kSeedScaling;
  const DrillForces seed = ComputeDrillForces(d, m, st);
  EXPECT_NEAR(seed.thrust, 2.5 * lips.thrust, 1e-12 * seed.thrust);
  EXPECT_NEAR(seed.torque, 1.67 * lips.torque, 1e-12 * seed.torque);
  m.chisel = ChiselModel::kOrthogonal;
  const DrillForces orth = ComputeDrillForces(d, m, st);
  // The chisel edge adds thrust (large negative rake) but little torque
  // (short arm): the classic picture (chisel ~ 40-60 % of thrust, < 15 % of torque).
  EXPECT_GT(orth.thrust / lips.thrust, 1.3);
  EXPECT_LT(orth.torque / lips.torque, 1.15);
}

TEST(DrillForces, EntryFollowsEngagedRadius) {
  const DrillGeometry d;
  const DrillingMaterial m = TestMaterial();
  const double wt = d.web_half_thickness(), rc = d.chisel_half_length(), R = d.radius();
  // Full engagement after d_full = (sqrt(R^2 - wt^2) - sqrt(rc^2 - wt^2)) / tan p.
  const double d_full =
      (std::sqrt(R * R - wt * wt) - std::sqrt(rc * rc - wt * wt)) / std::tan(d.half_point_angle());
  EXPECT_NEAR(EngagedRadius(d, d_full), R, 1e-12);
  EXPECT_LT(EngagedRadius(d, 0.99 * d_full), R);
  EXPECT_NEAR(EngagedRadius(d, 0.0), rc, 1e-15);
  double last = -1.0;
  for (int k = 0; k <= 20; ++k) {
    const DrillForces fk =
        ComputeDrillForces(d, m, {.feed_per_rev = 0.1e-3, .penetration = 1.2 * d_full * k / 20});
    EXPECT_GE(fk.thrust, last) << k;
    last = fk.thrust;
  }
  const DrillForces full = ComputeDrillForces(d, m, {.feed_per_rev = 0.1e-3, .penetration = d_full});
  const DrillForces deeper =
      ComputeDrillForces(d, m, {.feed_per_rev = 0.1e-3, .penetration = 3 * d_full});
  EXPECT_DOUBLE_EQ(full.thrust, deeper.thrust);
}

TEST(DrillForces, TiltedDrillImbalancePointsToShortLipAtSpindleFrequency) {
  const DrillGeometry d;
  const DrillingMaterial m = TestMaterial();
  const double tilt = DegToRad(1.0);
  // Law of sines in the triangle of seed eq. 7: with B = 90 deg - p and
  // C = 180 deg - tilt - B, r_q = R cos p / cos(p - tilt).
  const double p = d.half_point_angle();
  EXPECT_NEAR(TiltedLipRadius(d, d.radius(), tilt), d.radius() * std::cos(p) / std::cos(p - tilt),
              1e-15);
  // No tilt, no imbalance.
  const DrillForces straight = ComputeDrillForces(d, m, {.penetration = 5e-3, .spindle_angle = 0.3});
  EXPECT_LT(straight.radial.norm(), 1e-9 * straight.thrust);
  // Tilted: at spindle angle 0 lip 1 (full) lies along +x_d, the short lip
  // along -x_d; both are pushed towards the axis, the full one harder, so
  // the net force points along -x_d with magnitude radial_full - radial_short.
  const DrillForces at0 = ComputeDrillForces(d, m, {.penetration = 5e-3, .tilt = tilt});
  const LipIntegrand full = IntegrateLip(d, m, 0.1e-3, d.radius(), {});
  const LipIntegrand shorter = IntegrateLip(d, m, 0.1e-3, at0.short_lip_radius, {});
  EXPECT_LT(at0.radial.x(), 0.0);
  EXPECT_NEAR(at0.radial.x(), -(full.radial - shorter.radial), 1e-9 * full.radial);
  EXPECT_NEAR(at0.radial.y(), 0.0, 1e-9 * full.radial);
  // Over two spindle revolutions sampled 64 times each, the x component is a
  // pure 1x sinusoid: its DFT has all energy in bin 2 (= 1 per revolution).
  const int n = 128;
  std::vector<std::complex<double>> X(n / 2, 0.0);
  for (int k = 0; k < n; ++k) {
    const double psi = 2.0 * kPi * 2.0 * k / n;
    const double fx = ComputeDrillForces(d, m, {.penetration = 5e-3, .tilt = tilt,
                                                .spindle_angle = psi}).radial.x();
    for (int b = 0; b < n / 2; ++b) X[b] += fx * std::polar(1.0, -2.0 * kPi * b * k / n);
  }
  const double peak = std::abs(X[2]);
  EXPECT_NEAR(peak, 0.5 * n * (full.radial - shorter.radial), 1e-9 * n * full.radial);
  for (int b = 0; b < n / 2; ++b) {
    if (b != 2) EXPECT_LT(std::abs(X[b]), 1e-9 * peak) << "bin " << b;
  }
  // A larger tilt gives a shorter second lip and a larger imbalance.
  const DrillForces more = ComputeDrillForces(d, m, {.penetration = 5e-3, .tilt = 2 * tilt});
  EXPECT_GT(more.radial.norm(), at0.radial.norm());
  EXPECT_LT(more.thrust, at0.thrust);
}

TEST(DrillForces, RejectsInvalidInputWithFieldName) {
  DrillGeometry d;
  d.diameter = -1.0;
  try {
    ComputeDrillForces(d, TestMaterial(), {});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("diameter"), std::string::npos);
  }
  DrillingMaterial m = TestMaterial();
  m.kienzle_exponent = 1.2;
  EXPECT_THROW(ComputeDrillForces(DrillGeometry{}, m, {}), std::invalid_argument);
}

// One vocabulary (issue #36): each chisel model goes through its name and
// back, and a name that is not one is refused.
TEST(ChiselModel, RoundTripsThroughItsName) {
  for (ChiselModel m : {ChiselModel::kSeedScaling, ChiselModel::kOrthogonal, ChiselModel::kNone}) {
    EXPECT_EQ(ParseChiselModel(ToString(m)), m) << ToString(m);
  }
  EXPECT_THROW(ParseChiselModel("seed-scaling"), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::drilling
