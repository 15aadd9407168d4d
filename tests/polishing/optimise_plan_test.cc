// Issue 19 acceptance: polishing::OptimisePlan (what polish-plan --optimise
// nlopt does) on three surfaces unlike the shipped ones (config/polishing:
// a 90 deg arc of a 60 mm cylinder 94 x 120 mm, a 100 x 80 mm dome, the
// blade): a long narrow flat strip 200 x 50 mm turned 30 deg, a saddle
// (hyperbolic paraboloid, principal radii +-250 mm at the centre) 90 x
// 110 mm, and a strongly curved cylinder (radius 32 mm, 120 deg arc, 67 mm
// by 110 mm along the axis), with the shipped process (belt_2N.yaml: 2 N, 50 mm/s, margin
// 5 mm) and --target-removal-um 5. Asserted, on the optimiser's 1 mm grid:
//  - the optimum is feasible: planned at the speed limit it removes at
//    most the target (slower then reaches it exactly);
//  - its cv is at most 0.9 x the optimised zig-zag's, the zig-zag's row
//    spacing, direction and edge overrun searched here by a plain scan
//    (independent of OptimisePlan: 0.3 .. 1.5 contact widths in steps of
//    0.05, rows along s and along t, overrun 0, 0.5, 1 x margin);
//  - its cv is at most 1.1 x the best feasible point of a dense grid search
//    written here as plain nested loops over guide family (3), d (6), r/d
//    (3), pitch/r (4), stagger (3 on lines) and edge overrun (2): 1008
//    plans, on a 2 mm removal grid for time; its 6 best points re-evaluated
//    on the 1 mm grid.
// The same three comparisons are asserted again on the 0.5 mm grid with
// 0.5 mm rows (what polish-plan writes), the optimum, the zig-zag's 6 best
// and the grid search's 6 best re-evaluated there: the 1 mm grid aliases
// with sub-mm loops and row spacings (on dome.yaml an optimum's cv was
// 0.0065 at 1 mm and 0.0188 at 0.5 mm).
// The ratios 0.9 and 1.1 are the acceptance, not tolerances.
// These are the long polishing tests (OptimisePlanLong.*, in their own
// executable polishing_optimise_tests): 46, 142 and 92 s for the three
// surfaces on the shared 2-core machine at load ~4 (2 optimiser threads);
// the grid search is 1008 plans per surface.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "polishing/test_surfaces.h"
#include "robomach/common/units.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/optimise.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::polishing {
namespace {

PolishingProcess ShippedProcess() {
  return io::ReadPolishingProcess(std::string(ROBOMACH_SOURCE_DIR) + "/config/polishing/belt_2N.yaml");
}

// A long narrow flat strip, Lx x Ly in z = 0, turned 30 deg about z (its
// parameter lines are not the world axes).
NurbsSurface Strip(double Lx, double Ly) {
  const double c = std::cos(kPi / 6), s = std::sin(kPi / 6);
  auto P = [&](double x, double y) { return Eigen::Vector3d(c * x - s * y, s * x + c * y, 0.0); };
  return NurbsSurface::Create(1, 1, {0, 0, 1, 1}, {0, 0, 1, 1}, {{P(0, 0), P(0, Ly)}, {P(Lx, 0), P(Lx, Ly)}});
}

// Hyperbolic paraboloid z = x y / c over [-Lx/2, Lx/2] x [-Ly/2, Ly/2]: a
// bilinear patch (exact), principal curvatures +-1/c at the centre.
NurbsSurface Saddle(double Lx, double Ly, double c) {
  const double hx = Lx / 2, hy = Ly / 2, z = hx * hy / c;
  return NurbsSurface::Create(1, 1, {0, 0, 1, 1}, {0, 0, 1, 1},
                              {{Eigen::Vector3d(-hx, -hy, z), Eigen::Vector3d(-hx, hy, -z)},
                               {Eigen::Vector3d(hx, -hy, -z), Eigen::Vector3d(hx, hy, z)}});
}

// An arc of `angle` (< 180 deg) of a cylinder of radius R about y, length
// L, convex towards +z: one rational quadratic segment (The NURBS Book
// §7.5, middle weight cos(angle / 2)).
NurbsSurface CylinderArc(double R, double angle, double L) {
  const double h = angle / 2, w = std::cos(h);
  const Eigen::Vector3d a(-R * std::sin(h), 0, R * std::cos(h)), m(0, 0, R / std::cos(h)), b(R * std::sin(h), 0, R * std::cos(h));
  const Eigen::Vector3d y(0, L, 0);
  return NurbsSurface::Create(2, 1, {0, 0, 0, 1, 1, 1}, {0, 0, 1, 1}, {{a, a + y}, {m, m + y}, {b, b + y}},
                              {{1, 1}, {w, w}, {1, 1}});
}

struct Setup {
  NurbsSurface surface;
  PolishingProcess process;
  SampleGrid g1, g2, g05;  // 1 mm (the optimiser's), 2 mm (grid search), 0.5 mm (polish-plan's final map)
  double w{0};             // contact width at the centre
  std::unique_ptr<RemovalSimulator> s1, s2, s05;
  Setup(NurbsSurface s, const PolishingProcess& p)
      : surface(std::move(s)),
        process(p),
        g1(SampleGrid::Build(surface, 1e-3, p.margin, false)),
        g2(SampleGrid::Build(surface, 2e-3, p.margin, false)),
        g05(SampleGrid::Build(surface, 0.5e-3, p.margin, false)) {
    w = ContactWidthAtCentre(surface, g1, process);
    s1 = std::make_unique<RemovalSimulator>(surface, process, g1.points(), g1.normals(), 0.5 * w);
    s2 = std::make_unique<RemovalSimulator>(surface, process, g2.points(), g2.normals(), 0.5 * w);
    s05 = std::make_unique<RemovalSimulator>(surface, process, g05.points(), g05.normals(), 0.5 * w);
  }
  PlanProblem Problem(bool coarse, double target) const {
    PlanProblem pb;
    pb.surface = &surface;
    pb.grid = coarse ? &g2 : &g1;
    pb.sim = coarse ? s2.get() : s1.get();
    pb.process = &process;
    pb.target = target;
    pb.contact_width = w;
    return pb;
  }
  PlanProblem Final(double target) const {  // 0.5 mm, as polish-plan's written map
    PlanProblem pb = Problem(false, target);
    pb.grid = &g05;
    pb.sim = s05.get();
    return pb;
  }
};

struct Outcome {
  double nlopt_cv, parallel_cv, grid_cv, nlopt_mean, seconds;
  bool feasible;
  double nlopt_cv05, parallel_cv05, grid_cv05;  // the same on the 0.5 mm grid
  bool feasible05;
};

Outcome RunCase(const std::string& name, NurbsSurface surface) {
  const double target = 5e-6;
  const Setup su(std::move(surface), ShippedProcess());
  const PlanProblem fine = su.Problem(false, target), coarse = su.Problem(true, target);

  // The optimiser, as polish-plan --optimise nlopt calls it (defaults: 1 mm
  // grid, row step 1 mm, d >= 0.3 contact widths, d <= 30 mm).
  PathParameters start;
  start.row_step = 1e-3;
  PlanOptimiseOptions o;
  o.offset_min = std::max(0.3 * su.w, 0.5e-3);
  o.offset_max = 0.030;
  o.compare_parallel = false;  // the test's own scan is the reference
  // The shipped time cap (50 s) is wall-clock time: on a loaded CI machine
  // it would cut the local searches short at a different point on every
  // run. Here convergence (ftol_rel) decides; bench/bench_polishing.cc
  // measures the time at the defaults.
  o.max_time_s = 900;
  const auto t0 = std::chrono::steady_clock::now();
  const PlanOptimiseResult r = OptimisePlan(fine, start, o);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Re-evaluated independently of the optimiser's bookkeeping.
  const PlanEvaluation best = EvaluatePlan(fine, r.best.params, 1.0);
  // On the 0.5 mm grid with 0.5 mm rows, as polish-plan writes the result:
  // the 1 mm grid aliases with sub-mm loops and row spacings.
  const PlanProblem fin = su.Final(target);
  auto final_eval = [&](PathParameters p) {
    p.row_step = 0.5e-3;
    return EvaluatePlan(fin, p, 1.0);
  };
  const PlanEvaluation best05 = final_eval(r.best.params);
  std::cerr << name << ": optimiser " << secs << " s, " << r.evaluations << " evaluations\n";

  // The zig-zag: plain scan of the spacing, both directions, rows run
  // 0 .. margin into the margin (as PathParameters::edge_overrun allows),
  // on the 1 mm grid.
  const auto t1 = std::chrono::steady_clock::now();
  double par = 1e300;
  std::vector<PlanEvaluation> zz;
  for (double angle : {0.0, kPi / 2}) {
    for (double over : {0.0, 0.5, 1.0}) {
      for (double k = 0.3; k <= 1.5 + 1e-9; k += 0.05) {
        PathParameters p;
        p.pattern = Pattern::kParallel;
        p.row_step = 1e-3;
        p.offset = k * su.w;
        p.line_angle = angle;
        p.edge_overrun = over * su.process.margin;
        const PlanEvaluation e = EvaluatePlan(fine, p, 0.98);
        if (e.feasible) par = std::min(par, e.cv);
        if (e.feasible) zz.push_back(e);
      }
    }
  }
  const auto t2 = std::chrono::steady_clock::now();
  std::cerr << name << ": zig-zag scan " << std::chrono::duration<double>(t2 - t1).count() << " s\n";

  // Dense grid search over the cycloid family on the 2 mm grid.
  std::vector<PlanEvaluation> pts;
  const std::vector<std::pair<GuideLines, double>> fams = {
      {GuideLines::kBoundaryOffsets, 0.0}, {GuideLines::kParallelLines, 0.0}, {GuideLines::kParallelLines, kPi / 2}};
  for (const auto& [guides, angle] : fams) {
    const bool offsets = guides == GuideLines::kBoundaryOffsets;
    for (double dw : {0.3, 0.4, 0.55, 0.75, 1.0, 1.4}) {       // d in contact widths
      for (double rd : {0.5, 0.75, 1.0}) {                      // r / d
        for (double pr : {0.5, 1.0, 1.6, 2.4}) {                // pitch / r
          for (double st : offsets ? std::vector<double>{0.5} : std::vector<double>{0.0, 0.25, 0.5}) {  // stagger [loops]
            for (double ov : {0.0, 1.0}) {                      // edge overrun / its largest
              PathParameters p;
              p.guides = guides;
              p.line_angle = angle;
              p.offset = dw * su.w;
              p.radius = rd * p.offset;
              p.pitch = pr * p.radius;
              p.stagger = st;
              p.edge_overrun = ov * MaxEdgeOverrun(p, su.process);
              p.row_step = 2e-3;
              const PlanEvaluation e = EvaluatePlan(coarse, p, 0.98);
              if (e.feasible) pts.push_back(e);
            }
          }
        }
      }
    }
  }
  const auto t3 = std::chrono::steady_clock::now();
  std::sort(pts.begin(), pts.end(), [](const PlanEvaluation& a, const PlanEvaluation& b) { return a.cv < b.cv; });
  double grid_best = 1e300;
  PathParameters gb;
  for (size_t i = 0; i < std::min<size_t>(6, pts.size()); ++i) {
    PathParameters p = pts[i].params;
    p.row_step = 1e-3;
    const PlanEvaluation e = EvaluatePlan(fine, p, 0.98);
    if (e.feasible && e.cv < grid_best) grid_best = e.cv, gb = p;
  }
  // The 0.5 mm grid: the zig-zag's and the grid search's 6 best (1 mm) re-evaluated.
  auto by_cv = [](const PlanEvaluation& a, const PlanEvaluation& b) { return a.cv < b.cv; };
  std::sort(zz.begin(), zz.end(), by_cv);
  double par05 = 1e300, grid05 = 1e300;
  for (size_t i = 0; i < std::min<size_t>(6, zz.size()); ++i) {
    const PlanEvaluation e = final_eval(zz[i].params);
    if (e.feasible) par05 = std::min(par05, e.cv);
  }
  for (size_t i = 0; i < std::min<size_t>(6, pts.size()); ++i) {
    const PlanEvaluation e = final_eval(pts[i].params);
    if (e.feasible) grid05 = std::min(grid05, e.cv);
  }
  std::cout << name << ": on the 0.5 mm grid: NLopt cycloid cv " << best05.cv << " (removes " << 1e6 * best05.mean
            << " um at the limit), zig-zag " << par05 << ", grid search " << grid05 << "\n";
  std::cout << name << ": grid search best " << FamilyName({gb.guides, gb.line_angle}) << ", d " << 1e3 * gb.offset
            << " r " << 1e3 * gb.radius << " pitch " << 1e3 * gb.pitch << " mm, stagger " << gb.stagger
            << ", overrun " << 1e3 * gb.edge_overrun << " mm\n";
  std::cout << name << ": NLopt cycloid cv " << best.cv << " (" << FamilyName({best.params.guides, best.params.line_angle})
            << ", d " << 1e3 * best.params.offset << " r " << 1e3 * best.params.radius << " pitch "
            << 1e3 * best.params.pitch << " mm, stagger " << best.params.stagger << ", overrun "
            << 1e3 * best.params.edge_overrun << " mm; removes " << 1e6 * best.mean
            << " um at the limit, " << r.evaluations << " evaluations, " << secs << " s, " << ToString(r.status) << " (" << r.stop_reason << ")"
            << "), zig-zag cv " << par << ", grid search cv " << grid_best << " (" << pts.size()
            << " feasible points); zig-zag scan " << std::chrono::duration<double>(t2 - t1).count()
            << " s, grid search " << std::chrono::duration<double>(t3 - t2).count() << " s\n";
  return {best.cv, par, grid_best, best.mean, secs, best.valid && best.mean <= target,
          best05.cv, par05, grid05, best05.valid && best05.mean <= target};
}

void ExpectAcceptance(const Outcome& c) {
  EXPECT_TRUE(c.feasible) << "removes " << 1e6 * c.nlopt_mean << " um at the speed limit";
  EXPECT_LE(c.nlopt_cv, 0.9 * c.parallel_cv);
  EXPECT_LE(c.nlopt_cv, 1.1 * c.grid_cv);
  // What polish-plan writes: the 0.5 mm map.
  EXPECT_TRUE(c.feasible05);
  EXPECT_LE(c.nlopt_cv05, 0.9 * c.parallel_cv05);
  EXPECT_LE(c.nlopt_cv05, 1.1 * c.grid_cv05);
}

TEST(OptimisePlanLong, NarrowStrip) { ExpectAcceptance(RunCase("strip 200 x 50 mm", Strip(0.200, 0.050))); }
TEST(OptimisePlanLong, Saddle) { ExpectAcceptance(RunCase("saddle 90 x 110 mm", Saddle(0.090, 0.110, 0.250))); }
TEST(OptimisePlanLong, SmallCylinder) {
  ExpectAcceptance(RunCase("cylinder r 32 mm, 120 deg x 110 mm", CylinderArc(0.032, 2 * kPi / 3, 0.110)));
}

}  // namespace
}  // namespace robomach::polishing
