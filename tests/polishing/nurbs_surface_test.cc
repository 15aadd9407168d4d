#include "robomach/polishing/nurbs_surface.h"

#include <cmath>

#include <Eigen/Dense>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "polishing/test_surfaces.h"
#include "test_support.h"

namespace robomach::polishing {
namespace {

using ::testing::HasSubstr;

// An exact rational circle: every point at distance R from the axis, the
// circumferential curvature 1/R and the axial curvature 0 (to 1e-9, far
// below any geometric tolerance), the normal radial and outward.
TEST(NurbsSurface, ExactCylinderCurvature) {
  const double R = 0.03;
  const NurbsSurface cyl = testing::Cylinder(R, 0.05);
  for (double u : {0.0, 0.07, 0.25, 0.31, 0.5, 0.62, 0.875, 1.0}) {
    for (double v : {0.0, 0.4, 1.0}) {
      const SurfaceDerivatives d = cyl.Evaluate(u, v);
      EXPECT_NEAR(std::hypot(d.S.x(), d.S.y()), R, 1e-15) << u;
      const SurfaceCurvature c = PrincipalCurvatures(d);
      EXPECT_NEAR(c.k1 * R, 1.0, 1e-9) << "u " << u;
      EXPECT_NEAR(c.k2 * R, 0.0, 1e-9) << "u " << u;
      const Eigen::Vector3d radial(d.S.x(), d.S.y(), 0.0);
      EXPECT_NEAR(c.normal.dot(radial.normalized()), 1.0, 1e-12);
      EXPECT_NEAR(std::abs(c.d2.z()), 1.0, 1e-9);  // straight generator
      EXPECT_NEAR(c.d1.z(), 0.0, 1e-9);
    }
  }
  // Flipped normal: the inside of the cylinder is concave.
  EXPECT_NEAR(PrincipalCurvatures(cyl.Evaluate(0.3, 0.5), true).k2 * R, -1.0, 1e-9);
}

TEST(NurbsSurface, ExactSphereIsUmbilic) {
  const double R = 0.04;
  const NurbsSurface s = testing::SphereOctant(R);
  for (double u : {0.1, 0.5, 0.9}) {
    for (double v : {0.0, 0.3, 0.7}) {
      const SurfaceDerivatives d = s.Evaluate(u, v);
      EXPECT_NEAR(d.S.norm(), R, 1e-15);
      const SurfaceCurvature c = PrincipalCurvatures(d);
      EXPECT_NEAR(std::abs(c.k1) * R, 1.0, 1e-9);
      EXPECT_NEAR(std::abs(c.k2) * R, 1.0, 1e-9);
      // Normal along +-radius; the curvature sign follows it (convex if outward).
      const double dir = c.normal.dot(d.S.normalized());
      EXPECT_NEAR(std::abs(dir), 1.0, 1e-12);
      EXPECT_GT(c.k1 * dir, 0.0);
    }
  }
}

// Analytic first and second derivatives against central differences of the
// point (first) and of the analytic first derivatives (second); h = 1e-5 on
// a unit parameter range gives truncation ~h^2 * |S'''| ~ 1e-10 m.
TEST(NurbsSurface, DerivativesMatchFiniteDifferences) {
  const NurbsSurface s = testing::DoublyCurved();
  const double h = 1e-5;
  for (double u : {0.05, 0.3, 0.5, 0.77}) {
    for (double v : {0.1, 0.45, 0.9}) {
      const SurfaceDerivatives d = s.Evaluate(u, v);
      const SurfaceDerivatives up = s.Evaluate(u + h, v), um = s.Evaluate(u - h, v);
      const SurfaceDerivatives vp = s.Evaluate(u, v + h), vm = s.Evaluate(u, v - h);
      EXPECT_LT(((up.S - um.S) / (2 * h) - d.S_u).norm(), 1e-8);
      EXPECT_LT(((vp.S - vm.S) / (2 * h) - d.S_v).norm(), 1e-8);
      EXPECT_LT(((up.S_u - um.S_u) / (2 * h) - d.S_uu).norm(), 1e-7);
      EXPECT_LT(((vp.S_v - vm.S_v) / (2 * h) - d.S_vv).norm(), 1e-7);
      EXPECT_LT(((vp.S_u - vm.S_u) / (2 * h) - d.S_uv).norm(), 1e-7);
      EXPECT_LT(((up.S_v - um.S_v) / (2 * h) - d.S_uv).norm(), 1e-7);
    }
  }
}

// Normal curvature from the tensor equals the curvature of the normal
// section, measured by fitting the surface's deviation from the tangent
// plane along a direction (second method).
TEST(NurbsSurface, CurvatureTensorMatchesNormalSection) {
  const NurbsSurface s = testing::DoublyCurved();
  const double u0 = 0.4, v0 = 0.6;
  const SurfaceDerivatives d = s.Evaluate(u0, v0);
  const Eigen::Vector3d n = UnitNormal(d);
  const Eigen::Vector3d e1 = d.S_u.normalized(), e2 = n.cross(e1);
  const Eigen::Matrix2d K = CurvatureTensor(d, e1, e2);
  for (double ang : {0.0, 0.5, 1.2, 2.0}) {
    const Eigen::Vector3d dir = std::cos(ang) * e1 + std::sin(ang) * e2;
    // Parameter direction of `dir`.
    Eigen::Matrix<double, 3, 2> J;
    J << d.S_u, d.S_v;
    const Eigen::Vector2d w = (J.transpose() * J).ldlt().solve(J.transpose() * dir);
    // Curve c(t) = S(u0 + t w) has arc length ~t; its normal deviation
    // z(t) = (c - S0).n ~ -k t^2 / 2 with tangential distance x(t) ~ t.
    const double t = 1e-4;
    double k_fd = 0;
    for (double sgn : {-1.0, 1.0}) {
      const Eigen::Vector3d q = s.Point(u0 + sgn * t * w(0), v0 + sgn * t * w(1)) - d.S;
      const double x = q.dot(dir), z = q.dot(n);
      k_fd += -2.0 * z / (x * x) / 2.0;
    }
    const Eigen::Vector2d a(std::cos(ang), std::sin(ang));
    EXPECT_NEAR(k_fd, a.dot(K * a), 1e-5 * std::max(1.0, std::abs(k_fd))) << ang;
  }
}

TEST(NurbsSurface, RejectsMismatchedKnotsAndBadWeights) {
  const std::vector<std::vector<Eigen::Vector3d>> P = {{{0, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {1, 1, 0}}};
  EXPECT_THAT(robomach::testing::CaptureError([&] { NurbsSurface::Create(1, 1, {0, 0, 0.5, 1, 1}, {0, 0, 1, 1}, P); }),
              HasSubstr("knots_u: expected 4 knots (control points 2 + degree 1 + 1), got 5"));
  EXPECT_THAT(robomach::testing::CaptureError([&] { NurbsSurface::Create(1, 1, {0, 0, 1, 1}, {0, 1, 0, 1}, P); }),
              HasSubstr("knots_v: knots must be non-decreasing"));
  EXPECT_THAT(robomach::testing::CaptureError(
                  [&] { NurbsSurface::Create(1, 1, {0, 0, 1, 1}, {0, 0, 1, 1}, P, {{1, 1}, {1, -0.5}}); }),
              HasSubstr("weights: row 2, entry 2: expected a weight > 0, got -0.5"));
}

}  // namespace
}  // namespace robomach::polishing
