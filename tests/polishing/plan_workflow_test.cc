#include "robomach/polishing/plan_workflow.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "polishing/test_surfaces.h"
#include "robomach/polishing/optimise.h"
#include "robomach/polishing/path_patterns.h"
#include "test_support.h"

namespace robomach::polishing {
namespace {

using ::testing::HasSubstr;

PolishingProcess Belt() {
  PolishingProcess p;  // the library's defaults: a 2 N belt contact
  p.margin = 0.010;
  return p;
}

// polish-plan's plan on a 100 x 60 mm plate, timed for a 2 um mean removal:
// the target is reached, the mean removal over the region is the target
// (area-weighted, as RemovalStats computes it: checked here by summing the
// map), the rows are those EvaluatePlanOnGrid plans at the speed limit (the
// target only stretches the time), nothing is flagged.
TEST(PlanPolishing, ZigZagOnAPlateReachesItsTargetMean) {
  const NurbsSurface plate = testing::Plane(0.100, 0.060);
  const PlanningContext ctx = PreparePlanning(plate, Belt(), 1e-3, "plate.yaml", "belt.yaml");
  ASSERT_GT(ctx.contact_width, 0.0);
  PlanRequest req;
  req.params.pattern = Pattern::kParallel;
  req.params.offset = ctx.contact_width;
  req.params.row_step = 1e-3;
  req.target_removal = 2e-6;
  const PlanOutcome out = PlanPolishing(ctx, req);
  ASSERT_TRUE(out.target_given);
  EXPECT_TRUE(out.target.reached) << out.target.message;
  EXPECT_FALSE(out.verdict.flagged());
  EXPECT_EQ(out.status(), RunStatus::kOk);
  EXPECT_FALSE(out.optimisation.has_value());
  EXPECT_FALSE(out.comparison.has_value());
  double area = 0.0, removed = 0.0;
  for (int k = 0; k < ctx.grid->size(); ++k) {
    if (!ctx.grid->in_region()[k]) continue;
    area += ctx.grid->areas()[k];
    removed += ctx.grid->areas()[k] * out.plan.removal[k];
  }
  // ScaleToTargetRemoval's fixed-point steps stop within 1e-6 (relative) of the target.
  EXPECT_NEAR(removed / area, 2e-6, 2e-6 * 1e-6);
  EXPECT_NEAR(out.plan.stats.mean, 2e-6, 2e-6 * 1e-6);
  const EvaluatedPlan at_limit = EvaluatePlanOnGrid(ctx, req.params);
  ASSERT_EQ(at_limit.path.rows.size(), out.plan.path.rows.size());
  for (size_t i = 0; i < at_limit.path.rows.size(); ++i) {
    ASSERT_EQ(at_limit.path.rows[i].p, out.plan.path.rows[i].p) << "row " << i;
  }
  // Timed for the target: slower than the speed limit, so more removal at the limit is less.
  EXPECT_GT(out.plan.path.rows.back().t, at_limit.path.rows.back().t);
}

// A target below what one pass removes at the speed limit is out of reach
// (going faster is not allowed): the plan is flagged, with the target's own
// message as its one finding. A target just above it only slows the path
// down and is reached.
TEST(PlanPolishing, TargetOutOfReachIsAFindingNotAnError) {
  const NurbsSurface plate = testing::Plane(0.100, 0.060);
  const PlanningContext ctx = PreparePlanning(plate, Belt(), 1e-3, "plate.yaml", "belt.yaml");
  PlanRequest req;
  req.params.pattern = Pattern::kParallel;
  req.params.offset = ctx.contact_width;
  req.params.row_step = 1e-3;
  const double at_limit = EvaluatePlanOnGrid(ctx, req.params).stats.mean;
  ASSERT_GT(at_limit, 0.0);
  req.target_removal = 0.5 * at_limit;
  const PlanOutcome low = PlanPolishing(ctx, req);
  EXPECT_FALSE(low.target.reached);
  EXPECT_EQ(low.status(), RunStatus::kFlagged);
  ASSERT_EQ(low.verdict.findings.size(), 1u);
  EXPECT_EQ(low.verdict.findings[0].message, low.target.message);
  EXPECT_FALSE(low.target.message.empty());
  req.target_removal = 1.01 * at_limit;
  const PlanOutcome ok = PlanPolishing(ctx, req);
  EXPECT_TRUE(ok.target.reached) << ok.target.message;
  EXPECT_EQ(ok.status(), RunStatus::kOk);
}

// A margin that leaves no region names the process file; a cycloid wider
// than a narrow strip names the surface file.
TEST(PlanPolishing, ErrorsNameTheFileThatIsWrong) {
  const NurbsSurface plate = testing::Plane(0.100, 0.060);
  PolishingProcess wide = Belt();
  wide.margin = 0.031;
  EXPECT_THAT(robomach::testing::CaptureError([&] { PreparePlanning(plate, wide, 1e-3, "plate.yaml", "belt.yaml"); }),
              HasSubstr("belt.yaml: process.margin_mm 31 leaves no polished region"));
  const NurbsSurface strip = testing::Plane(0.100, 0.024);
  const PlanningContext ctx = PreparePlanning(strip, Belt(), 1e-3, "strip.yaml", "belt.yaml");
  PlanRequest req;
  req.params.pattern = Pattern::kCycloid;
  req.params.radius = 0.015;  // its centre 5 mm inside a region 4 mm wide
  req.params.offset = 0.016;
  req.params.pitch = 0.004;
  const std::string what = robomach::testing::CaptureError([&] { PlanPolishing(ctx, req); });
  EXPECT_THAT(what, HasSubstr("strip.yaml"));
  EXPECT_THAT(what, HasSubstr("face too narrow for the circle"));
}

// The optimiser's names are one parser and one printer (issue #36), the
// names polish-plan's --optimise takes.
TEST(Optimiser, NamesRoundTripAndAWrongNameListsTheRightOnes) {
  for (Optimiser o : {Optimiser::kNlopt, Optimiser::kPso}) EXPECT_EQ(ParseOptimiser(ToString(o)), o);
  EXPECT_EQ(ToString(Optimiser::kNlopt), "nlopt");
  EXPECT_EQ(ToString(Optimiser::kPso), "pso");
  EXPECT_THAT(robomach::testing::CaptureError([] { ParseOptimiser("NLopt"); }),
              HasSubstr("optimiser 'NLopt': expected nlopt or pso"));
}

}  // namespace
}  // namespace robomach::polishing
