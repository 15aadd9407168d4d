// Faces too narrow, too large or not finite (issue 19 scope 5, issue 22):
// errors that name the face, never rows clamped onto a patch's edges, never
// an unbounded grid.
#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "robomach/polishing/face_check.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/region_outline.h"
#include "robomach/polishing/surface_grid.h"
#include "test_surfaces.h"

namespace robomach::polishing {
namespace {

// A 1.7 mm x 60 mm strip (the turbine strip of issue 19): a 6 mm cycloid
// with a 0.2 mm margin cannot stay on it. Before the check the planner laid
// its guide on the strip's centre line and clamped most rows onto u = 0 and
// u = 1; now it is an error naming the face, its width and the radius.
TEST(FaceCheck, CycloidOnAStripNarrowerThanItsCircleIsAnError) {
  const NurbsSurface strip = testing::Plane(1.7e-3, 60e-3);
  PolishingProcess process;
  process.margin = 0.2e-3;
  const SampleGrid grid = SampleGrid::Build(strip, 0.25e-3, process.margin, false);
  PathParameters params;  // cycloid, r 6 mm, d 8 mm
  params.offset = 1e-3;   // d <= 2r and within the strip
  params.radius = 6e-3;
  try {
    PlanPath(strip, grid, params, process);
    FAIL() << "expected FaceTooNarrowError";
  } catch (const FaceTooNarrowError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("face too narrow for the circle"), std::string::npos) << m;
    EXPECT_NE(m.find("the patch"), std::string::npos) << m;
    EXPECT_NE(m.find("radius_mm 6"), std::string::npos) << m;
    // The region's width: the strip less two margins, 1.3 mm, as the grid
    // resolves it (its in-region points, at most 0.25 mm apart: 1.3 mm less
    // up to one spacing at each side).
    const size_t at = m.find(") is ");
    ASSERT_NE(at, std::string::npos) << m;
    const double w_mm = std::stod(m.substr(at + 5));
    EXPECT_LE(w_mm, 1.3 + 1e-9);
    EXPECT_GE(w_mm, 1.3 - 2 * 0.25);
  }
  // The optimiser sees the same error as infeasible parameters.
  EXPECT_THROW(PlanPath(strip, grid, params, process), std::invalid_argument);
}

// The largest circle the message proposes fits, and then no row leaves the
// strip: every row's x is strictly inside (0, 1.7 mm), none clamped onto an edge.
TEST(FaceCheck, CycloidThatFitsTheStripStaysOnIt) {
  const NurbsSurface strip = testing::Plane(1.7e-3, 60e-3);
  PolishingProcess process;
  process.margin = 0.2e-3;
  const SampleGrid grid = SampleGrid::Build(strip, 0.25e-3, process.margin, false);
  PathParameters params;
  params.radius = 0.8e-3;  // <= margin + width / 2 = 0.2 + 0.625 mm
  params.offset = 0.8e-3;
  params.pitch = 0.5e-3;
  const PlannedPath path = PlanPath(strip, grid, params, process);
  ASSERT_GT(path.rows.size(), 100u);
  int on_edge = 0;
  for (const PathRow& r : path.rows) on_edge += r.p.x() <= 1e-12 || r.p.x() >= 1.7e-3 - 1e-12;
  EXPECT_EQ(on_edge, 0);
  // The parallel pattern needs no circle: it plans with any radius.
  params.pattern = Pattern::kParallel;
  params.radius = 6e-3;
  EXPECT_GT(PlanPath(strip, grid, params, process).rows.size(), 10u);
}

// A trimmed face (a plate with a hole) narrower than the circle: the same
// error through the general (offset) layout.
TEST(FaceCheck, TrimmedFaceTooNarrowNamesTheFace) {
  const NurbsSurface plate = testing::PlateWithHole(20e-3, 12e-3, 10e-3, 6e-3, 3e-3);
  PolishingProcess process;
  process.margin = 0.5e-3;
  const SampleGrid grid = SampleGrid::Build(plate, 0.5e-3, process.margin, false);
  PathParameters params;
  params.radius = 6e-3;  // the strips beside the hole are 2.5 mm wide after the margin
  params.offset = 6e-3;
  try {
    PlanPath(plate, grid, params, process);
    FAIL() << "expected FaceTooNarrowError";
  } catch (const FaceTooNarrowError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("test plate with a hole"), std::string::npos) << m;
    EXPECT_NE(m.find("radius_mm 6"), std::string::npos) << m;
  }
}

TEST(FaceCheck, PolishableSaysWhyNot) {
  PolishingProcess process;  // margin 5 mm
  PathParameters params;
  // Too small for the margin: the reason gives the face's size (3 x 40 mm).
  const Polishability small = CheckPolishable(testing::Plane(3e-3, 40e-3), process, params);
  EXPECT_FALSE(small.polishable);
  EXPECT_NE(small.reason.find("(3 x 40 mm)"), std::string::npos) << small.reason;
  EXPECT_NE(small.reason.find("leaves no polished region"), std::string::npos) << small.reason;
  // Too large to sample at 0.5 mm: 40 m x 13 m is 2e9 points.
  const Polishability big = CheckPolishable(testing::Plane(40.0, 13.0), process, params);
  EXPECT_FALSE(big.polishable);
  EXPECT_NE(big.reason.find("too large"), std::string::npos) << big.reason;
  EXPECT_NE(big.reason.find("4e+04 x 1.3e+04 mm"), std::string::npos) << big.reason;
  EXPECT_NEAR(big.grid_points, (40.0 / 0.5e-3 + 1) * (13.0 / 0.5e-3 + 1), 1.0);
  // A 100 x 60 mm plate takes the 6 mm cycloid: its region (90 x 50 mm) is 50 mm wide.
  const Polishability ok = CheckPolishable(testing::Plane(0.1, 0.06), process, params);
  EXPECT_TRUE(ok.polishable) << ok.reason;
  EXPECT_NEAR(ok.region_width, 0.05, 2 * std::sqrt(0.1 * 0.06 / PolishableOptions{}.check_grid_points));
}

// Issue 22: a patch whose size is not finite (a coordinate of 1e200 whose
// square overflows) or huge makes a clear error, not a cast of NaN or of
// 1e300 to int and an overflowing ns * nt (UBSan at surface_grid.cc).
TEST(FaceCheck, GridSizeIsValidatedBeforeTheCast) {
  const NurbsSurface inf_patch = NurbsSurface::Create(
      1, 1, {0, 0, 1, 1}, {0, 0, 1, 1},
      {{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 1e200, 0)}, {Eigen::Vector3d(1e200, 0, 0), Eigen::Vector3d(1e200, 1e200, 0)}});
  try {
    SampleGrid::Build(inf_patch, 0.5e-3, 0.005, false);
    FAIL() << "expected std::domain_error";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }
  const NurbsSurface huge = testing::Plane(1e6, 1e6);  // 1000 km: 4e18 points at 0.5 mm
  try {
    SampleGrid::Build(huge, 0.5e-3, 0.005, false);
    FAIL() << "expected std::domain_error";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("too large to sample"), std::string::npos) << e.what();
  }
  EXPECT_EQ(EstimateGridPoints(MeasureSurface(inf_patch), 0.5e-3), std::numeric_limits<double>::infinity());
  // The estimate is the count Build makes.
  const SampleGrid g = SampleGrid::Build(testing::Plane(0.02, 0.013), 0.5e-3, 0.0, false);
  EXPECT_EQ(EstimateGridPoints(MeasureSurface(testing::Plane(0.02, 0.013)), 0.5e-3), g.size());
}

// Inradius on a large outline with many points (a 10 m circle as 20 000
// chords, the size of a CAD face read in the wrong unit) stays bounded and
// right: the inscribed circle of the regular polygon, R cos(pi / n), to the
// documented 1e-6 of the size.
TEST(FaceCheck, InradiusOfALargeFineOutline) {
  const int n = 20000;
  const double R = 10.0;
  Polygon2 circle;
  for (int k = 0; k < n; ++k) circle.emplace_back(R * std::cos(2 * M_PI * k / n), R * std::sin(2 * M_PI * k / n));
  const DevelopedRegion region = DevelopedRegion::FromPolygons({circle});
  EXPECT_NEAR(region.Inradius(), R * std::cos(M_PI / n), 2 * 1e-6 * 2 * R);
}

}  // namespace
}  // namespace robomach::polishing
