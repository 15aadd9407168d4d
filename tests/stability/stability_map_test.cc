#include "robomach/stability/stability_map.h"

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/region_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/kinematics/serial_chain.h"
#include "robomach/stability/mode_coupling.h"
#include "robomach/stability/tool_tip_model.h"
#include "robomach/stability/zoa_lobes.h"
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

namespace robomach::stability {
namespace {

// The map against a serial reference (issue #23 item 3): every analysed
// point of a 2-thread map equals AnalysePosture at the map's own posture,
// evaluated point after point on one thread with the plain calls (its own
// model and PostureEvaluator, the speeds all at once). The same functions
// of the same numbers in the same order: equal to rounding, and 1e-12
// relative leaves room only for that.
TEST(StabilityMap, PointsEqualASerialReferenceAnalysis) {
  Fixture f;
  f.region.size_u = 0.3;
  f.region.size_v = 0.2;
  f.region.grid_step = 0.05;
  const auto targets = f.region.Targets(f.cut.feed_direction_B);
  MapOptions o = f.Options();
  o.analysis.spindle_speed_rad_s =
      Eigen::VectorXd::LinSpaced(200, f.cut.spindle_speed_min_rad_s, f.cut.spindle_speed_max_rad_s);
  const auto map = EvaluateStabilityMap(f.model, targets, f.region.num_v(), f.region.num_u(), f.cut.process, o);
  dynamics::PostureEvaluator ev(dynamics::RobotModel::Build(f.model->description(), f.model->parameters()));
  int analysed = 0;
  for (size_t i = 0; i < map.size(); ++i) {
    const MapPoint& p = map[i];
    if (p.status != PointStatus::kOk && p.status != PointStatus::kNearSingular) continue;
    ++analysed;
    const dynamics::PostureDynamics d = ev.Evaluate(p.q, dynamics::PostureOptions{false, true});
    const PostureStability ref = AnalysePosture(
        d, CuttingFrameAtPosture(targets[i].Pose(p.rotation), targets[i].feed_B), f.cut.process, o.analysis);
    const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::abs(b); };
    EXPECT_TRUE(near(p.stability.critical_depth, ref.critical_depth))
        << i << ": " << p.stability.critical_depth << " vs " << ref.critical_depth;
    EXPECT_TRUE(near(p.stability.mode_coupling.critical_depth, ref.mode_coupling.critical_depth)) << i;
    EXPECT_TRUE(near(p.stability.regenerative.critical_depth, ref.regenerative.critical_depth)) << i;
    EXPECT_TRUE(near(p.stability.regenerative.spindle_speed_rad_s, ref.regenerative.spindle_speed_rad_s)) << i;
    EXPECT_TRUE(near(p.stability.closed_form.critical_depth, ref.closed_form.critical_depth)) << i;
    EXPECT_EQ(p.stability.limiting, ref.limiting) << i;
    EXPECT_TRUE(near(p.jacobian_condition, d.jacobian_condition)) << i;
  }
  EXPECT_GE(analysed, 20);  // 7 x 5 points, nearly all reachable from the demo seed
}

// ZoaLobes::At skips the lines of lobe k that cannot reach the speed range;
// a plain interpolation over every segment of every curve (from curves(),
// written here without the skipping) must give the same envelope. KR210
// demo posture, 1200 lines, 200 speeds over 6000-24000 rpm (the map's
// case) and a narrow range (where most lines are skipped).
TEST(StabilityMap, LobeEnvelopeEqualsAPlainScanOfEveryCurve) {
  Fixture f;
  dynamics::PostureEvaluator ev(f.model);
  const dynamics::PostureDynamics d = ev.Evaluate(f.region.seed_q, dynamics::PostureOptions{false, true});
  const Eigen::Matrix3d R = CuttingFrameAtPosture(d.X_BT, f.cut.feed_direction_B);
  const TipModalModel modes = ModalModelFromPosture(d);
  for (const auto& [lo_rpm, hi_rpm] : {std::pair{6000.0, 24000.0}, std::pair{11000.0, 11500.0}}) {
    const Eigen::VectorXd speeds = Eigen::VectorXd::LinSpaced(200, RpmToRadPerSec(lo_rpm), RpmToRadPerSec(hi_rpm));
    const Eigen::VectorXd freq = LobeFrequencyGrid(modes, f.cut.process.teeth, speeds.maxCoeff(), 1200);
    ZoaOptions zo;
    zo.min_spindle_speed_rad_s = speeds.minCoeff();
    const ZoaLobes lobes =
        ComputeZoaLobes(freq, InPlaneModalReceptance(modes.Rotated(R), freq), f.cut.process, zo);
    const std::vector<LobePoint> got = lobes.At(speeds);
    int covered = 0;
    for (Eigen::Index j = 0; j < speeds.size(); ++j) {
      const double s = speeds(j);
      double best = NAN;
      for (const LobeCurve& c : lobes.curves()) {
        for (size_t i = 0; i + 1 < c.spindle_speed_rad_s.size(); ++i) {
          const double sa = c.spindle_speed_rad_s[i], sb = c.spindle_speed_rad_s[i + 1];
          if (!std::isfinite(sa) || !std::isfinite(sb) || s < std::min(sa, sb) || s > std::max(sa, sb)) continue;
          const double t = sb != sa ? (s - sa) / (sb - sa) : 0.0;
          const double depth = c.critical_depth[i] + t * (c.critical_depth[i + 1] - c.critical_depth[i]);
          if (!(depth >= best)) best = depth;
        }
      }
      ASSERT_EQ(got[j].status == LobeStatus::kOk, std::isfinite(best)) << lo_rpm << " rpm range, speed " << j;
      if (!std::isfinite(best)) continue;
      ++covered;
      // The same interpolation formula: equal to rounding.
      EXPECT_NEAR(got[j].critical_depth, best, 1e-12 * best) << lo_rpm << " rpm range, speed " << j;
    }
    EXPECT_EQ(covered, 200) << lo_rpm;
  }
}

// The modal mode-coupling search of six modes runs on fixed-size 12 x 12
// matrices; the joint-space search (dynamic size) of the same structure
// written as M = I, C = diag(2ζω), K = diag(ω²), B = P must give the same
// depth. The bracket tolerance is set to 1e-10 so that both searches end
// within 1e-10 relative of the same crossing; they differ only by rounding.
TEST(StabilityMap, SixModeModalSearchEqualsTheGeneralSearch) {
  Fixture f;
  dynamics::PostureEvaluator ev(f.model);
  const dynamics::PostureDynamics d = ev.Evaluate(f.region.seed_q, dynamics::PostureOptions{false, true});
  const TipModalModel m = ModalModelFromPosture(d);
  ASSERT_EQ(m.num_modes(), 6);
  const Eigen::Matrix3d R = CuttingFrameAtPosture(d.X_BT, f.cut.feed_direction_B);
  const Eigen::Matrix3d Kc_B = R * CuttingStiffnessPerDepth(f.cut.process) * R.transpose();
  ModeCouplingOptions opt;
  opt.depth_tolerance = 1e-10;
  const ModeCouplingResult modal = CriticalDepthModeCouplingModal(m, Kc_B, opt);
  const Eigen::VectorXd w = m.omega_rad_s;
  const ModeCouplingResult general = CriticalDepthModeCoupling(
      Eigen::MatrixXd::Identity(6, 6), (2.0 * m.zeta.cwiseProduct(w)).asDiagonal().toDenseMatrix(),
      w.array().square().matrix().asDiagonal().toDenseMatrix(), m.p, Kc_B, opt);
  ASSERT_EQ(modal.status, ModeCouplingStatus::kFound);
  ASSERT_EQ(general.status, ModeCouplingStatus::kFound);
  EXPECT_NEAR(modal.critical_depth, general.critical_depth, 2e-10 * general.critical_depth);
  // The frequency of the eigenvalue at the upper end of each bracket (both
  // within 1e-10 of the crossing, where Im λ varies smoothly): 1e-6 is loose.
  EXPECT_NEAR(modal.chatter_freq_hz, general.chatter_freq_hz, 1e-6 * general.chatter_freq_hz);
}

// The map's statistics on hand-made points (the answers worked out by hand).
MapPoint PointWith(double depth, ModeCouplingStatus mc, double mc_depth, double closed_form_depth) {
  MapPoint p;
  p.stability.critical_depth = depth;
  p.stability.mode_coupling.status = mc;
  p.stability.mode_coupling.critical_depth = mc_depth;
  p.stability.closed_form.critical_depth = closed_form_depth;
  return p;
}

TEST(StabilityMapStatistics, CriticalDepthExtremesSkipPointsWithoutADepth) {
  const std::vector<MapPoint> pts = {PointWith(NAN, ModeCouplingStatus::kStableUpToMax, NAN, INFINITY),
                                     PointWith(3e-3, ModeCouplingStatus::kFound, 3e-3, 6e-3),
                                     PointWith(1e-3, ModeCouplingStatus::kFound, 1e-3, 1e-3),
                                     PointWith(INFINITY, ModeCouplingStatus::kStableUpToMax, NAN, INFINITY),
                                     PointWith(5e-3, ModeCouplingStatus::kFound, 5e-3, 0.0),
                                     PointWith(1e-3, ModeCouplingStatus::kFound, 1e-3, 2e-3)};
  const CriticalDepthExtremes e = FindCriticalDepthExtremes(pts);
  EXPECT_EQ(e.with_depth, 4);
  EXPECT_EQ(e.min_index, 2);  // the first of the two 1 mm points
  EXPECT_EQ(e.max_index, 4);

  // Ratios closed form / eigenvalue criterion: 2 (point 1), 1 (point 2),
  // 2 (point 5); point 4's closed form is 0 and points 0 and 3 found no
  // mode coupling. Sorted 1, 2, 2: median 2.
  const ClosedFormAgreement a = CompareClosedForm(pts);
  EXPECT_EQ(a.points, 3);
  EXPECT_DOUBLE_EQ(a.median, 2.0);
  EXPECT_DOUBLE_EQ(a.min, 1.0);
  EXPECT_DOUBLE_EQ(a.max, 2.0);
}

TEST(StabilityMapStatistics, NoPointGivesEmptyStatistics) {
  const std::vector<MapPoint> pts = {PointWith(NAN, ModeCouplingStatus::kStableUpToMax, NAN, INFINITY)};
  const CriticalDepthExtremes e = FindCriticalDepthExtremes(pts);
  EXPECT_EQ(e.with_depth, 0);
  EXPECT_EQ(e.min_index, -1);
  EXPECT_EQ(e.max_index, -1);
  const ClosedFormAgreement a = CompareClosedForm(pts);
  EXPECT_EQ(a.points, 0);
  EXPECT_TRUE(std::isnan(a.median));
}

}  // namespace
}  // namespace robomach::stability
