#include "robomach/stability/zoa_lobes.h"

#include <cmath>
#include <complex>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/stability/lobes_workflow.h"
#include "robomach/stability/mode_coupling.h"
#include "robomach/stability/posture_stability.h"
#include "robomach/stability/stability_map.h"
#include "robomach/stability/tool_tip_model.h"
#include "stability/internal/batch_atan2.h"

namespace robomach::stability {
namespace {

using cd = std::complex<double>;

// The batched atan2 (libmvec's where configure found it) against std::atan2
// over every quadrant, odd lengths (the scalar tail) and the magnitudes of
// ZOA eigenvalues (1e-12..1e-2). libmvec's atan2 is within a few ulp; the
// bound is 8 eps·π = 5.6e-15 absolute, about 8 ulp of results near π.
TEST(BatchAtan2, MatchesStdAtan2WithinAFewUlp) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-12.0, -2.0);
  for (const long n : {0L, 1L, 2L, 7L, 1201L}) {
    std::vector<double> y(n), x(n), got(n);
    for (long i = 0; i < n; ++i) {
      y[i] = u(rng) * std::pow(10.0, e(rng));
      x[i] = u(rng) * std::pow(10.0, e(rng));
    }
    internal::BatchAtan2(y.data(), x.data(), got.data(), n);
    for (long i = 0; i < n; ++i) {
      ASSERT_NEAR(got[i], std::atan2(y[i], x[i]), 8.0 * std::numeric_limits<double>::epsilon() * kPi)
          << "y " << y[i] << ", x " << x[i];
    }
  }
  std::cout << "BatchAtan2: " << (internal::BatchAtan2IsVectorised() ? "libmvec" : "std::atan2") << "\n";
}

// A 1-DOF structure flexible only along the feed x: Φ_C = diag(G, 0). Then
// Φ_C H0 = [[G h_xx, G h_xy], [0, 0]] has the eigenvalues G h_xx and 0, so
// (1) reduces to the orthogonal-cutting (turning) problem with the force
// coefficient K_f = h_xx [Tlusty 2000]:
//   a_lim = −1 / (2 K_f Re G),  ω_c T = ε + 2πk,  ε = 3π + 2ψ,  ψ = arg G,
// whose absolute minimum is a_min = 2 k ζ (1 + ζ) / K_f at ω = ω_n √(1+2ζ).
struct TurningCase {
  double m = 2.0, fn_hz = 600.0, zeta = 0.03;
  MillingProcess process;
  double k() const { return m * std::pow(HzToRadPerSec(fn_hz), 2); }
  double Kf() const { return AverageDirectionalMatrix(process)(0, 0); }
  TurningCase() {
    process.teeth = 3;
    // Half-immersion up-milling: h_xx = N(2K_t + πK_r)/(8π) > 0, so the
    // feed-direction mode gives the classic lobes above resonance.
    process.radial_immersion = 0.5;
    process.direction = MillingDirection::kUp;
    process.coefficients = {7e8, 2.1e8, 0.0};
  }
  std::vector<Eigen::Matrix2cd> Phi(const Eigen::VectorXd& f) const {
    std::vector<Eigen::Matrix2cd> out;
    const double wn = HzToRadPerSec(fn_hz), c = 2.0 * zeta * m * wn;
    for (Eigen::Index i = 0; i < f.size(); ++i) {
      const double w = HzToRadPerSec(f(i));
      Eigen::Matrix2cd P = Eigen::Matrix2cd::Zero();
      P(0, 0) = 1.0 / cd(k() - m * w * w, c * w);
      out.push_back(P);
    }
    return out;
  }
};

TEST(ZoaLobes, OneDofLobePointsMatchTurningClosedForm) {
  const TurningCase tc;
  const Eigen::VectorXd f = LogFrequencyGrid(300.0, 1500.0, 4000);
  const auto Phi = tc.Phi(f);
  ZoaOptions opt;
  opt.max_lobe_index = 5;
  const ZoaLobes lobes = ComputeZoaLobes(f, Phi, tc.process, opt);
  int checked = 0;
  for (const LobeCurve& c : lobes.curves()) {
    for (size_t i = 0; i < c.chatter_freq_hz.size(); ++i) {
      const cd G = Phi[i](0, 0);
      const bool closed_form_exists = G.real() < 0.0;
      if (c.branch == 1 || !closed_form_exists) continue;  // branch 1 is the zero eigenvalue
      const double a = -1.0 / (2.0 * tc.Kf() * G.real());
      const double psi = std::atan2(G.imag(), G.real());  // in (−π, −π/2)
      const double eps = 3.0 * kPi + 2.0 * psi;
      const double w = HzToRadPerSec(f(i));
      const double speed = 2.0 * kPi * w / (tc.process.teeth * (eps + 2.0 * kPi * c.lobe_index));
      // Both are a few flops on the same G: rounding only, ~1e-15
      // relative; 1e-12 leaves three orders of margin.
      ASSERT_NEAR(c.critical_depth[i], a, 1e-12 * a) << "f = " << f(i);
      ASSERT_NEAR(c.spindle_speed_rad_s[i], speed, 1e-12 * speed) << "f = " << f(i);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

TEST(ZoaLobes, OneDofMinimumDepthIsTwoKZetaOnePlusZetaOverKf) {
  const TurningCase tc;
  const Eigen::VectorXd f = LogFrequencyGrid(300.0, 1500.0, 20000);
  const ZoaLobes lobes = ComputeZoaLobes(f, tc.Phi(f), tc.process);
  double min_depth = INFINITY;
  for (const LobeCurve& c : lobes.curves()) {
    for (double a : c.critical_depth) {
      if (std::isfinite(a)) min_depth = std::min(min_depth, a);
    }
  }
  const double a_min = 2.0 * tc.k() * tc.zeta * (1.0 + tc.zeta) / tc.Kf();
  // a(ω) ∝ 1/|Re G| is smooth with its minimum at ω* = ω_n √(1+2ζ); the
  // nearest line is within half a log step r/2, r = ln(5)/19999 = 8.0e-5.
  // With x = (ω/ω_n)² − 1, −k Re G ≈ x/(x² + 4ζ²) peaks at x = 2ζ with
  // curvature −1/(2(2ζ)³), so a/a_min − 1 ≈ δx²/(8ζ²) = (δω/ω)²/(2ζ²)
  // = (4.0e-5)²/(1.8e-3) ≈ 9e-7 (plus O(ζ) corrections); 1e-5 leaves a
  // factor 10. Every curve point is ≥ a_min (it is the minimum).
  EXPECT_GE(min_depth, a_min * (1.0 - 1e-12));
  EXPECT_LE(min_depth, a_min * (1.0 + 1e-5));
}

// The envelope At() interpolates linearly between grid lines; at the
// speeds of the curve points themselves it must return them (within the
// minimum over lobes, which can only be lower).
TEST(ZoaLobes, EnvelopeAtCurveSpeedsReturnsTheLowestCurve) {
  const TurningCase tc;
  const Eigen::VectorXd f = LogFrequencyGrid(300.0, 1500.0, 3000);
  ZoaOptions opt;
  opt.max_lobe_index = 3;
  const ZoaLobes lobes = ComputeZoaLobes(f, tc.Phi(f), tc.process, opt);
  const LobeCurve c = lobes.curves()[1];  // branch 0, lobe 1
  int n = 0;
  for (size_t i = 0; i < c.spindle_speed_rad_s.size(); i += 97) {
    if (!std::isfinite(c.critical_depth[i])) continue;
    const LobePoint p = lobes.At(c.spindle_speed_rad_s[i]);
    ASSERT_EQ(p.status, LobeStatus::kOk);
    EXPECT_LE(p.critical_depth, c.critical_depth[i] * (1.0 + 1e-12));
    ++n;
  }
  EXPECT_GT(n, 5);
  // A speed no lobe of the grid reaches is reported, not invented.
  const LobePoint none = lobes.At(1e-3);
  EXPECT_EQ(none.status, LobeStatus::kNotCovered);
}

// One vocabulary (issue #36): every value of the stability enums the files
// and summaries name goes through its name and back, and a name that is not
// one is refused.
TEST(StabilityNames, RoundTripThroughTheirNames) {
  for (LobeStatus s : {LobeStatus::kOk, LobeStatus::kNotCovered, LobeStatus::kStableUpToMax,
                       LobeStatus::kUnstableAtZero}) {
    EXPECT_EQ(ParseLobeStatus(ToString(s)), s) << ToString(s);
  }
  EXPECT_THROW(ParseLobeStatus("not covered"), std::invalid_argument);
  for (ModeCouplingStatus s : {ModeCouplingStatus::kFound, ModeCouplingStatus::kStableUpToMax,
                               ModeCouplingStatus::kUnstableAtZero}) {
    EXPECT_EQ(ParseModeCouplingStatus(ToString(s)), s) << ToString(s);
  }
  EXPECT_THROW(ParseModeCouplingStatus("found"), std::invalid_argument);
  for (Mechanism m : {Mechanism::kModeCoupling, Mechanism::kRegenerative, Mechanism::kNone}) {
    EXPECT_EQ(ParseMechanism(ToString(m)), m) << ToString(m);
  }
  EXPECT_THROW(ParseMechanism("chatter"), std::invalid_argument);
  for (PointStatus s : {PointStatus::kOk, PointStatus::kUnreachable, PointStatus::kJointLimits,
                        PointStatus::kNearSingular, PointStatus::kOtherConfiguration}) {
    EXPECT_EQ(ParsePointStatus(ToString(s)), s) << ToString(s);
  }
  EXPECT_THROW(ParsePointStatus("singular"), std::invalid_argument);
  for (LobeMethod m : {LobeMethod::kZoa, LobeMethod::kSd, LobeMethod::kBoth}) {
    EXPECT_EQ(ParseLobeMethod(ToString(m)), m) << ToString(m);
  }
  EXPECT_THROW(ParseLobeMethod("ZOA"), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::stability
