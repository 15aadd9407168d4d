// Compensation as the 840D sl applies it (formats.md §8.4, seed 002 eqs. (2)-(5)),
// checked against hand-computed values.
#include "robomach/machine/compensation.h"

#include <gtest/gtest.h>

#include <random>

namespace robomach::machine {
namespace {

constexpr int kX = 0, kY = 1, kZ = 2;

// X pitch table: 0, 50, 100 mm -> 0, +2.1, +1.0 µm.
EncoderCompensation XPitch() { return {kX, {0.0, 0.05, {0.0, 2.1e-6, 1.0e-6}}}; }
// Sag of Z as a function of X measured: 0, 400, 800 mm -> 0, -1.2, -0.4 µm.
CrossAxisCompensation ZSagOverX() { return {kX, kZ, {0.0, 0.4, {0.0, -1.2e-6, -0.4e-6}}}; }

std::array<double, 3> Real(const Compensation& c, double t, std::array<double, 3> m) {
  std::array<double, 3> r{};
  c.MeasuredToReal(t, m.data(), r.data());
  return r;
}

// Tolerances: the values are sums of a few doubles of ~1 m and ~1e-6 m, so
// exact to a few ulps of 1 m (2.2e-16 m); 1e-15 m = 1e-12 mm.
constexpr double kTol = 1e-15;

TEST(Compensation, InterpolatesLinearlyBetweenPoints) {
  const Compensation c(3, {XPitch()}, {}, {});
  // 25 mm is halfway between 0 and 2.1 µm; 75 mm halfway between 2.1 and 1.0.
  EXPECT_NEAR(Real(c, 0, {0.025, 0, 0})[kX], 0.025 + 1.05e-6, kTol);
  EXPECT_NEAR(Real(c, 0, {0.075, 0, 0})[kX], 0.075 + 1.55e-6, kTol);
  // 60 mm: 2.1 + 0.2 (1.0 - 2.1) = 1.88 µm.
  EXPECT_NEAR(Real(c, 0, {0.060, 0, 0})[kX], 0.060 + 1.88e-6, kTol);
  // On a point, the point's value.
  EXPECT_NEAR(Real(c, 0, {0.050, 0, 0})[kX], 0.050 + 2.1e-6, kTol);
}

TEST(Compensation, HoldsEndValuesOutsideTheTable) {
  const Compensation c(3, {XPitch()}, {}, {});
  EXPECT_NEAR(Real(c, 0, {-0.010, 0, 0})[kX], -0.010 + 0.0, kTol);
  EXPECT_NEAR(Real(c, 0, {0.300, 0, 0})[kX], 0.300 + 1.0e-6, kTol);
}

TEST(Compensation, SignConventionRealIsMeasuredPlusValue) {
  // A table value is real minus measured: a scale that reads 2.1 µm short at
  // 50 mm has a real position 2.1 µm beyond its reading.
  const Compensation c(3, {XPitch()}, {}, {});
  const auto r = Real(c, 0, {0.050, 0, 0});
  EXPECT_GT(r[kX], 0.050);
  EXPECT_NEAR(r[kX] - 0.050, 2.1e-6, kTol);
}

TEST(Compensation, SagTakesBaseAxisMeasuredAndAddsToCompensatedAxis) {
  const Compensation c(3, {}, {ZSagOverX()}, {});
  // X at 400 mm bends Z by -1.2 µm whatever Z is; X and Y are untouched.
  for (double z : {-0.8, -0.1, 0.0}) {
    const auto r = Real(c, 0, {0.400, -0.2, z});
    EXPECT_NEAR(r[kZ], z - 1.2e-6, kTol);
    EXPECT_EQ(r[kX], 0.400);
    EXPECT_EQ(r[kY], -0.2);
  }
  // Z's own position is not the input: Z at 400 mm with X at 0 gets nothing.
  EXPECT_EQ(Real(c, 0, {0.0, 0.0, 0.400})[kZ], 0.400);
}

TEST(Compensation, TemperatureSwitchesInTime) {
  TemperatureCompensation t{kY, {{10.0, 1e-6, 0.0, 0.0}, {20.0, 3e-6, 1e-5, -0.5}}};
  const Compensation c(3, {}, {}, {t});
  const std::array<double, 3> m{0.1, -0.3, -0.2};
  // Before the first row: no temperature compensation.
  EXPECT_EQ(Real(c, 9.999, m)[kY], -0.3);
  // First row from t = 10 s (inclusive) up to 20 s.
  EXPECT_NEAR(Real(c, 10.0, m)[kY], -0.3 + 1e-6, kTol);
  EXPECT_NEAR(Real(c, 19.999, m)[kY], -0.3 + 1e-6, kTol);
  // Second row: K0 + tan(beta) (P - P0) = 3 µm + 1e-5 (-0.3 + 0.5) = 5 µm.
  EXPECT_NEAR(Real(c, 20.0, m)[kY], -0.3 + 5e-6, kTol);
  EXPECT_NEAR(Real(c, 1e6, m)[kY], -0.3 + 5e-6, kTol);
  // Other axes untouched.
  EXPECT_EQ(Real(c, 20.0, m)[kX], 0.1);
}

TEST(Compensation, ContributionsAdd) {
  TemperatureCompensation t{kX, {{0.0, 1e-6, 2e-6, 0.0}}};
  const Compensation c(3, {XPitch()}, {{kX, kX, {0.0, 0.1, {5e-7, 5e-7}}}}, {t});
  // 50 mm: 2.1 µm pitch + 0.5 µm cross + 1 µm + 2e-6 * 0.05 m = 0.1 µm.
  EXPECT_NEAR(Real(c, 0.0, {0.05, 0, 0})[kX], 0.05 + 3.7e-6, kTol);
}

TEST(Compensation, MeasuredToRealToMeasuredRoundTripsTo1e12Millimetre) {
  TemperatureCompensation tx{kX, {{0.0, 1e-6, 1.2e-5, 0.2}, {5.0, 2e-6, 1.5e-5, 0.2}}};
  TemperatureCompensation tz{kZ, {{1.0, -3e-6, -8e-6, -0.4}}};
  // A Y table with 21 points of random values, and the Z sag over X.
  std::mt19937 rng(11);
  std::normal_distribution<double> um(0.0, 3e-6);
  CompensationTable ty{-1.05, 0.05, {}};
  for (int i = 0; i < 22; ++i) ty.values.push_back(um(rng));
  const Compensation c(3, {XPitch(), {kY, ty}}, {ZSagOverX()}, {tx, tz});
  std::uniform_real_distribution<double> x(-0.1, 0.9), y(-1.1, 0.05), z(-0.9, 0.05), t(-1.0, 10.0);
  for (int i = 0; i < 2000; ++i) {
    const std::array<double, 3> m{x(rng), y(rng), z(rng)};
    const double ts = t(rng);
    const auto r = Real(c, ts, m);
    std::array<double, 3> back{};
    c.RealToMeasured(ts, r.data(), back.data());
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(back[a], m[a], 1e-15) << "axis " << a;
  }
}

TEST(Compensation, RejectsBadTables) {
  EXPECT_THROW(Compensation(3, {{kX, {0.0, 0.0, {1.0}}}}, {}, {}), std::invalid_argument);
  EXPECT_THROW(Compensation(3, {{kX, {0.0, 1.0, {}}}}, {}, {}), std::invalid_argument);
  EXPECT_THROW(Compensation(3, {{5, {0.0, 1.0, {0.0}}}}, {}, {}), std::invalid_argument);
  EXPECT_THROW(Compensation(3, {}, {}, {{kX, {{1.0, 0, 0, 0}, {1.0, 0, 0, 0}}}}), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::machine
