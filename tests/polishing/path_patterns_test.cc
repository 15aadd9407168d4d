#include "robomach/polishing/path_patterns.h"

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "test_support.h"

namespace robomach::polishing {
namespace {

using ::testing::HasSubstr;

// One registry: every pattern found by its name and by its id, the names
// distinct, and an unknown name refused with the known ones listed.
TEST(PathPatterns, FoundByNameAndByIdInOnePlace) {
  std::set<std::string> names;
  for (const PathPattern* p : PathPatterns()) {
    EXPECT_EQ(&FindPathPattern(p->name()), p);
    EXPECT_EQ(&PathPatternOf(p->id()), p);
    EXPECT_FALSE(p->description().empty());
    names.insert(p->name());
  }
  EXPECT_EQ(names, (std::set<std::string>{"cycloid", "parallel"}));
  EXPECT_EQ(PathPatternList(), "cycloid or parallel");
  EXPECT_THAT(testing::CaptureError([] { FindPathPattern("spiral"); }),
              HasSubstr("unknown path pattern 'spiral': expected cycloid or parallel"));
}

// The cycloid's limits (seed 004 §3.2) are the cycloid's: d > 2r and
// pitch >= 2 pi r fail it, and the same parameters pass for the zig-zag,
// whose tool runs on the guide line itself.
TEST(PathPatterns, CycloidLimitsApplyToTheCycloidOnly) {
  PathParameters p;
  p.offset = 0.013;
  p.radius = 0.006;  // d > 2 r
  p.pattern = Pattern::kCycloid;
  EXPECT_THAT(testing::CaptureError([&] { CheckValid(p); }), HasSubstr("d <= 2r"));
  p.pattern = Pattern::kParallel;
  EXPECT_NO_THROW(CheckValid(p));
  p.pattern = Pattern::kCycloid;
  p.offset = 0.008;
  p.pitch = 2 * kPi * p.radius;  // the centre as fast as the rolling point
  EXPECT_THAT(testing::CaptureError([&] { CheckValid(p); }), HasSubstr("v < omega r"));
  p.pitch = 0.003;
  EXPECT_NO_THROW(CheckValid(p));
  // The shared limits hold for every pattern.
  for (const PathPattern* pat : PathPatterns()) {
    PathParameters q = p;
    q.pattern = pat->id();
    q.offset = -1.0;
    EXPECT_THAT(testing::CaptureError([&] { CheckValid(q); }), HasSubstr("offset_mm: expected > 0")) << pat->name();
  }
}

// The cycloid's nominal rate puts the fastest point of the curve at the
// speed limit: the point on the circle moves at omega r plus the centre's
// pitch omega / 2 pi when both are aligned, so (r + pitch/2pi) omega = vmax;
// the centre speed is pitch omega / 2 pi. The zig-zag does not roll.
TEST(PathPatterns, CycloidRateKeepsTheFastestPointAtTheLimit) {
  PathParameters p;
  p.radius = 0.006;
  p.pitch = 0.003;
  const double vmax = 0.05;
  const PathPattern& c = FindPathPattern("cycloid");
  const double w = c.NominalRate(p, vmax);
  EXPECT_NEAR(w * p.radius + c.CentreSpeed(p, w), vmax, 1e-15);
  // One loop takes 2 pi / omega, and the centre advances one pitch in it.
  EXPECT_NEAR(c.CentreSpeed(p, w) * (2 * kPi / w), p.pitch, 1e-15);
  EXPECT_EQ(c.circle_radius(p), p.radius);
  const PathPattern& z = FindPathPattern("parallel");
  EXPECT_EQ(z.NominalRate(p, vmax), 0.0);
  EXPECT_EQ(z.circle_radius(p), 0.0);
  // The circle must stay on the patch: the cycloid's rows run at most
  // margin - r into the margin, the zig-zag's the whole margin.
  PolishingProcess process;
  process.margin = 0.010;
  EXPECT_NEAR(c.MaxEdgeOverrun(p, process), 0.004, 1e-15);
  EXPECT_EQ(z.MaxEdgeOverrun(p, process), 0.010);
  p.pattern = Pattern::kCycloid;
  EXPECT_EQ(MaxEdgeOverrun(p, process), c.MaxEdgeOverrun(p, process));
}

// Issue #36: every Pattern and GuideLines value goes through its name and
// back; the registry's names are the enum's (a pattern's name() is
// ToString of its id()); a name that is not one is refused naming them all.
TEST(PathPatterns, EnumNamesRoundTripAndAgreeWithTheRegistry) {
  for (Pattern p : {Pattern::kCycloid, Pattern::kParallel}) {
    EXPECT_EQ(ParsePattern(ToString(p)), p) << ToString(p);
    EXPECT_EQ(PathPatternOf(p).name(), ToString(p));
    EXPECT_TRUE(PathPatternRegistry().Contains(ToString(p)));
  }
  EXPECT_EQ(PathPatternRegistry().Names(), (std::vector<std::string>{"cycloid", "parallel"}));
  EXPECT_THAT(testing::CaptureError([] { ParsePattern("zigzag"); }),
              HasSubstr("unknown path pattern 'zigzag': expected cycloid or parallel"));
  for (GuideLines g : {GuideLines::kBoundaryOffsets, GuideLines::kParallelLines}) {
    EXPECT_EQ(ParseGuideLines(ToString(g)), g) << ToString(g);
  }
  EXPECT_EQ(ToString(GuideLines::kBoundaryOffsets), "offsets");
  EXPECT_THAT(testing::CaptureError([] { ParseGuideLines("lines"); }),
              HasSubstr("guides 'lines': expected offsets or parallel"));
}

}  // namespace
}  // namespace robomach::polishing
