#include "robomach/polishing/region_outline.h"

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/common/units.h"

namespace robomach::polishing {
namespace {

Polygon2 Circle(double R, int n, bool clockwise) {
  Polygon2 p;
  for (int i = 0; i < n; ++i) {
    const double a = (clockwise ? -2.0 : 2.0) * kPi * i / n;
    p.emplace_back(R * std::cos(a), R * std::sin(a));
  }
  return p;
}

// An annulus 10 mm < radius < 40 mm: its offsets at distance x are the
// circles of radius 40 - x and 10 + x, its inradius 15 mm, a line at height
// t crosses it in [-sqrt(40^2 - t^2), -sqrt(10^2 - t^2)] and the mirror
// interval.
TEST(RegionOutline, AnnulusOffsetsAreConcentricCircles) {
  const DevelopedRegion ring = DevelopedRegion::FromPolygons({Circle(0.040, 4000, false), Circle(0.010, 1000, true)});
  EXPECT_FALSE(ring.rectangle());
  ASSERT_EQ(ring.loops().size(), 2u);
  EXPECT_NEAR(ring.Area(), kPi * (0.040 * 0.040 - 0.010 * 0.010), 1e-5 * ring.Area());
  EXPECT_NEAR(ring.Inradius(), 0.015, 2e-6);
  for (double x : {0.002, 0.007, 0.0145}) {
    const std::vector<Polygon2> loops = ring.Offset(x);
    ASSERT_EQ(loops.size(), 2u) << x;
    for (const Polygon2& loop : loops) {
      // One loop is the outer circle (counter-clockwise), the other the grown hole (clockwise).
      double area = 0.0;
      for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++)
        area += loop[j].x() * loop[i].y() - loop[i].x() * loop[j].y();
      const double R = area > 0 ? 0.040 - x : 0.010 + x;
      for (const Eigen::Vector2d& p : loop) {
        // Vertices on the offset circle to the chord sag of the input and
        // Clipper's 0.1 um integer grid; round joins put vertices on the arc.
        EXPECT_NEAR(p.norm(), R, 1e-6) << "offset " << x;
      }
    }
  }
  EXPECT_TRUE(ring.Offset(0.0155).empty());
  const auto iv = ring.Intervals(0.005);
  ASSERT_EQ(iv.size(), 2u);
  EXPECT_NEAR(iv[0].first, -std::sqrt(0.040 * 0.040 - 0.005 * 0.005), 1e-6);
  EXPECT_NEAR(iv[0].second, -std::sqrt(0.010 * 0.010 - 0.005 * 0.005), 1e-6);
  EXPECT_NEAR(iv[1].first, std::sqrt(0.010 * 0.010 - 0.005 * 0.005), 1e-6);
  EXPECT_NEAR(iv[1].second, std::sqrt(0.040 * 0.040 - 0.005 * 0.005), 1e-6);
  ASSERT_EQ(ring.Intervals(0.020).size(), 1u);
  EXPECT_TRUE(ring.Intervals(0.041).empty());
  EXPECT_FALSE(ring.Contains(Eigen::Vector2d(0, 0)));
  EXPECT_TRUE(ring.Contains(Eigen::Vector2d(0.025, 0)));
  EXPECT_FALSE(ring.Contains(Eigen::Vector2d(0.045, 0)));
  EXPECT_NEAR(ring.DistanceToBoundary(Eigen::Vector2d(0.0, 0.030)), 0.010, 1e-6);
}

// A rectangle is recognised (the planner keeps its rectangular loops and
// centre line there); its inward offsets keep sharp corners.
TEST(RegionOutline, RectangleIsRecognisedAndOffsetsKeepCorners) {
  const DevelopedRegion r = DevelopedRegion::FromPolygons(
      {{Eigen::Vector2d(0, 0), Eigen::Vector2d(0.1, 0), Eigen::Vector2d(0.1, 0.06), Eigen::Vector2d(0, 0.06)}});
  EXPECT_TRUE(r.rectangle());
  EXPECT_NEAR(r.Inradius(), 0.03, 2e-6);
  const auto loops = r.Offset(0.01);
  ASSERT_EQ(loops.size(), 1u);
  bool corner = false;
  for (const auto& p : loops[0]) {
    // On the inner rectangle [10, 90] x [10, 50] mm.
    EXPECT_NEAR(std::min({std::abs(p.x() - 0.01), std::abs(p.x() - 0.09), std::abs(p.y() - 0.01),
                          std::abs(p.y() - 0.05)}), 0.0, 1e-7);
    EXPECT_TRUE(p.x() > 0.01 - 1e-7 && p.x() < 0.09 + 1e-7 && p.y() > 0.01 - 1e-7 && p.y() < 0.05 + 1e-7);
    corner |= (p - Eigen::Vector2d(0.01, 0.01)).norm() < 1e-7;
  }
  EXPECT_TRUE(corner);
  // With a notch cut out of it, it is not a rectangle any more.
  const DevelopedRegion notched = DevelopedRegion::FromPolygons(
      {{Eigen::Vector2d(0, 0), Eigen::Vector2d(0.1, 0), Eigen::Vector2d(0.1, 0.06), Eigen::Vector2d(0.05, 0.03),
        Eigen::Vector2d(0, 0.06)}});
  EXPECT_FALSE(notched.rectangle());
}

}  // namespace
}  // namespace robomach::polishing
