#include "robomach/stability/stability_map.h"

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/region_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/kinematics/serial_chain.h"
#include "test_support.h"

namespace robomach::stability {
namespace {

using robomach::testing::SourcePath;

struct Fixture {
  std::shared_ptr<const dynamics::RobotModel> model =
      io::LoadRobotConfig(SourcePath("config/kr210.yaml")).Build();
  io::CutSpec cut = io::ReadCutFile(SourcePath("config/cut_demo.yaml"));
  io::RegionSpec region = io::ReadRegionFile(SourcePath("config/region_demo.yaml"), 6);
  MapOptions Options() const {
    MapOptions o;
    o.seed_q = region.seed_q;
    o.rotation = region.rotation_fixed;
    o.analysis.spindle_speed_rad_s = Eigen::VectorXd::LinSpaced(20, cut.spindle_speed_min_rad_s, cut.spindle_speed_max_rad_s);
    o.threads = 2;
    return o;
  }
};

// Independent check of the IK: forward kinematics of every returned q
// reproduces the target pose. The solver accepts 1e-5 m and 1e-4 rad
// (stability_map.cc); the check uses the same bounds.
TEST(StabilityMap, IkSolutionsReproduceTargetsAndStayOnOneConfiguration) {
  Fixture f;
  f.region.size_u = f.region.size_v = 0.2;
  f.region.grid_step = 0.1;
  const auto targets = f.region.Targets(f.cut.feed_direction_B);
  const auto pts = EvaluateStabilityMap(f.model, targets, f.region.num_v(), f.region.num_u(), f.cut.process, f.Options());
  ASSERT_EQ(pts.size(), targets.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    ASSERT_EQ(pts[i].status, PointStatus::kOk) << i;
    const Eigen::Isometry3d X = kinematics::ForwardKinematics(f.model->chain(), pts[i].q);
    const Eigen::Isometry3d T = targets[i].Pose(f.region.rotation_fixed);
    EXPECT_LT((X.translation() - T.translation()).norm(), 1e-5);
    EXPECT_LT(Eigen::AngleAxisd(X.linear().transpose() * T.linear()).angle(), 1e-4);
    // Neighbours 100 mm apart need joint changes of a few degrees, not a
    // branch switch (which moves joints by tens of degrees).
    if (i > 0 && i % f.region.num_u() != 0) {
      EXPECT_LT((pts[i].q - pts[i - 1].q).cwiseAbs().maxCoeff(), DegToRad(20.0)) << i;
    }
    EXPECT_GT(pts[i].stability.critical_depth, 0.0);
  }
}

// Points out of reach are marked, not dropped; the others are unaffected.
TEST(StabilityMap, UnreachablePointsAreMarkedNotDropped) {
  Fixture f;
  std::vector<ToolPoseTarget> targets = f.region.Targets(f.cut.feed_direction_B);
  targets.resize(3);
  targets[1].p_BT = Eigen::Vector3d(6.0, 0.0, 0.8);  // 6 m: beyond the 2.7 m reach
  const auto pts = EvaluateStabilityMap(f.model, targets, 1, 3, f.cut.process, f.Options());
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_EQ(pts[0].status, PointStatus::kOk);
  EXPECT_EQ(pts[1].status, PointStatus::kUnreachable);
  EXPECT_FALSE(std::isfinite(pts[1].stability.critical_depth));
  EXPECT_EQ(pts[2].status, PointStatus::kOk);
}

// With a free rotation the optimiser starts from a scan that includes the
// fixed rotation's neighbourhood; its result can only be at least as good
// as any rotation it evaluated, in particular the scan's end points. We
// compare against the fixed-rotation depth at both bounds.
TEST(StabilityMap, FreeRotationIsAtLeastAsGoodAsTheBounds) {
  Fixture f;
  std::vector<ToolPoseTarget> targets = f.region.Targets(f.cut.feed_direction_B);
  targets.resize(1);
  MapOptions fixed = f.Options();
  const double lo = f.region.rotation_fixed - DegToRad(60.0), hi = f.region.rotation_fixed + DegToRad(60.0);
  fixed.rotation = lo;
  const double d_lo = EvaluateStabilityMap(f.model, targets, 1, 1, f.cut.process, fixed)[0].stability.critical_depth;
  fixed.rotation = hi;
  const double d_hi = EvaluateStabilityMap(f.model, targets, 1, 1, f.cut.process, fixed)[0].stability.critical_depth;
  MapOptions free = f.Options();
  free.optimise_rotation = true;
  free.rotation = f.region.rotation_fixed;
  free.rotation_min = lo;
  free.rotation_max = hi;
  const MapPoint p = EvaluateStabilityMap(f.model, targets, 1, 1, f.cut.process, free)[0];
  ASSERT_EQ(p.status, PointStatus::kOk);
  EXPECT_GE(p.rotation, lo);
  EXPECT_LE(p.rotation, hi);
  // The same numbers through the same code: only the IK re-solve
  // (1e-5 m) can differ, far below the 1e-4 bisection bracket.
  EXPECT_GE(p.stability.critical_depth, std::max(d_lo, d_hi) * (1.0 - 1e-3));
  EXPECT_FALSE(p.optimiser_status.empty());
}

}  // namespace
}  // namespace robomach::stability

namespace robomach::stability {
namespace {

// Each point's computation does not depend on the schedule, so 1 and 2
// threads must give bit-identical results. (This caught a data race: KDL
// joints cache their last pose in mutable members, so threads sharing one
// KDL chain corrupted each other's IK; every thread now has its own model.)
TEST(StabilityMap, ThreadCountDoesNotChangeResults) {
  Fixture f;
  f.region.size_u = f.region.size_v = 0.4;
  f.region.grid_step = 0.05;
  const auto targets = f.region.Targets(f.cut.feed_direction_B);
  MapOptions one = f.Options(), two = f.Options();
  one.threads = 1;
  two.threads = 2;
  const auto a = EvaluateStabilityMap(f.model, targets, f.region.num_v(), f.region.num_u(), f.cut.process, one);
  for (int rep = 0; rep < 3; ++rep) {
    const auto b = EvaluateStabilityMap(f.model, targets, f.region.num_v(), f.region.num_u(), f.cut.process, two);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].status, b[i].status) << i;
      ASSERT_EQ(a[i].q, b[i].q) << i;
      ASSERT_EQ(a[i].stability.critical_depth, b[i].stability.critical_depth) << i;
    }
  }
}

}  // namespace
}  // namespace robomach::stability
