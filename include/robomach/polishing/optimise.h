#pragma once

// Optimisation of the cycloid's parameters (seed 004 §3.2): minimise the
// coefficient of variation of the removal over the polished region (the
// seed's variance F(h), eq. 19, at equal mean) over (d, r, pitch) inside the
// seed's feasibility limits. Two methods, so that users can compare them:
//  - NLopt: DIRECT-L (GN_DIRECT_L), a deterministic global search of the
//    box that needs no gradient (the objective is a simulation, piecewise
//    smooth and slightly noisy through the sampling), then Subplex
//    (LN_SBPLX) from its best point, a derivative-free local method that
//    copes with that noise better than a quadratic model (BOBYQA);
//  - the seed's PSO with adaptive inertia weight (eq. 18), at most 100
//    iterations, stopping after 30 without an improvement beyond 0.001,
//    fixed random seed.
// Variables: d in [offset_min, offset_max], r/d in [0.5, 1] (seed limit 3,
// implies d <= 2r), pitch/r in [0.5, pi] (seed limit 2: v < omega r means
// pitch < 2 pi r; pi keeps clear loops; the lower bound keeps the path, and
// the polishing time, within ~4 pi region-area / d).

#include <functional>
#include <string>
#include <vector>

#include "robomach/common/solver_status.h"
#include "robomach/polishing/paths.h"

namespace robomach::polishing {

enum class Optimiser { kNlopt, kPso };
/// Every Optimiser, in the order its names are listed ("nlopt or pso"): the
/// one list ParseOptimiser and PlanOptions::Validate name.
inline constexpr Optimiser kOptimisers[] = {Optimiser::kNlopt, Optimiser::kPso};

/// "nlopt", "pso" (the names polish-plan's --optimise and Python take).
std::string ToString(Optimiser o);
/// The inverse of ToString. @throws std::invalid_argument naming the
/// accepted names.
Optimiser ParseOptimiser(const std::string& name);

struct OptimiseOptions {
  Optimiser method{Optimiser::kNlopt};
  double offset_min{0.004}, offset_max{0.030};  // [m]
  int global_evaluations{40};   // NLopt DIRECT-L budget
  int local_evaluations{30};    // NLopt Subplex budget
  int pso_particles{10};
  int pso_max_iterations{100};
  int pso_stall_iterations{30};
  double pso_tolerance{0.001};
  unsigned seed{20240404};
  /// Called after each evaluation (NLopt) or iteration (PSO) with the count
  /// so far and the best value; may be empty.
  std::function<void(int, double)> progress;

  /// The bounds (issue #36), for either method:
  /// - offset_min > 0 [m]: a guide-line spacing.
  /// - offset_max > offset_min and finite: the search maps [offset_min, offset_max] onto
  ///   [0, 1] ("offset_max: expected a value > offset_min MIN, got VALUE").
  /// - global_evaluations, local_evaluations >= 1: NLopt takes a budget <= 0
  ///   as none.
  /// - pso_particles >= 1: the start is particle 0.
  /// - pso_max_iterations >= 0; pso_stall_iterations >= 1.
  /// - pso_tolerance >= 0: an improvement is compared with it.
  /// @throws OptionError(field, "FIELD: expected ..., got VALUE") naming the bound.
  void Validate() const;
};

struct OptimiseResult {
  PathParameters best;
  double best_value{0.0};
  std::vector<double> history;  // best value after each iteration (PSO) or evaluation (NLopt)
  int evaluations{0};
  /// kConverged: NLopt met its tolerance (or stopped at roundoff, the
  /// objective's noise level), the PSO stalled within pso_tolerance;
  /// kNotConverged: an evaluation or iteration budget ran out (the best so
  /// far is returned); kFailed: NLopt failed.
  SolverStatus status{SolverStatus::kConverged};
  /// The optimiser's own word: "converged", "roundoff_limited",
  /// "max_evaluations" (NLopt), "max_iterations" (PSO), "forced_stop",
  /// "failed: <NLopt's message>".
  std::string stop_reason;
  std::string method;           // human-readable description
};

/// `objective(params)` returns the value to minimise (cv); `start` gives
/// the pattern, guides and row step, and the NLopt local start if the
/// global stage finds nothing better.
OptimiseResult OptimiseCycloid(const std::function<double(const PathParameters&)>& objective,
                               const PathParameters& start, const OptimiseOptions& options);

// ---------------------------------------------------------------------------
// OptimisePlan (issue 19): the whole optimisation polish-plan --optimise
// does, with the speed limit and the target as a constraint.
//
// A plan is evaluated on the optimiser's (coarse) grid, planned at the speed
// limit: it removes `mean` there, the least any speed within the limit
// gives. It is feasible if mean <= feasibility_margin x target (no target:
// always): slowing down then reaches the target exactly; and if it covers
// the region (coverage >= kMinCoverage, polish-plan's warning threshold: a
// plan that barely touches the region reaches any small target).
//
// Cycloid: the variables are, in the unit box, d on a log scale over
// [offset_min, offset_max], r/d in [0.5, 1], pitch/r in [0.5, pi]
// (OptimiseCycloid's box), the stagger in [0, 1] loops and the edge overrun
// in [0, 1] x MaxEdgeOverrun; the guide family is a discrete choice, each
// tried: boundary offsets, parallel lines along s, parallel lines along t
// (those given in `families`). Method (NLopt):
//  1. a coarse grid per family (d x r/d x pitch/r = 3 x 2 x 3 at the
//     half-loop stagger and full overrun), plus the start plan;
//  2. multi-start: from the best grid point of each family within 1.5 x of
//     the best, then the next best points (`starts` in all), COBYLA
//     (LN_COBYLA) with the constraint mean / (margin target) - 1 <= 0 and
//     the cv as the objective, each run stopping on a relative change of
//     the cv below ftol_rel (or x below 0.005 of the box, or
//     max_local_evaluations);
//  3. restarts from the best point, a fresh run and one a quarter loop of
//     stagger away, while the best improves by more than ftol_rel (at most
//     5 rounds);
//  all under max_time_s; the best feasible evaluation seen anywhere is
//  returned; only if none was seen, the least infeasible one (feasible =
//  false).
// The zig-zag (and the cycloid's comparison): the row spacing scanned on
// [0.3, 1.5] contact widths (13 points) x edge overrun (0, 0.5, 1 margin) x
// rows along s and t, then a golden-section refinement of the spacing per
// direction; the best feasible kept.
// PSO: OptimiseCycloid's seed PSO on the first family, the same
// feasibility bookkeeping.
// Evaluations run on `threads` threads (the simulator is immutable).
// ---------------------------------------------------------------------------

class RemovalSimulator;
struct PolishingProcess;

constexpr double kMinCoverage = 0.99;

/// What is optimised: plans on `grid` simulated by `sim` (built on the same grid).
struct PlanProblem {
  const NurbsSurface* surface{nullptr};
  const SampleGrid* grid{nullptr};
  const RemovalSimulator* sim{nullptr};
  const PolishingProcess* process{nullptr};
  double target{0.0};         // mean removal [m]; 0: no target, every plan feasible
  double contact_width{0.0};  // ContactWidthAtCentre [m]: the zig-zag's spacing unit
};

struct PlanEvaluation {
  PathParameters params;
  bool valid{false};     // planned: inside the seed limits, fits the region
  bool feasible{false};  // valid and reaches the target within the speed limit
  double cv{0.0};        // cv of the removal at the speed limit
  double mean{0.0};      // mean removal at the speed limit [m]
  double coverage{0.0};  // RemovalStats::coverage
  std::string error;     // why not valid
};

/// Plans `p` at the speed limit on the problem's grid and simulates it.
/// Bad contact (PathRowError) propagates; std::invalid_argument (seed
/// limits, region too narrow) gives valid = false.
PlanEvaluation EvaluatePlan(const PlanProblem& problem, const PathParameters& p, double feasibility_margin = 0.98);

/// A guide family of the cycloid.
struct GuideFamily {
  GuideLines guides{GuideLines::kBoundaryOffsets};
  double line_angle{0.0};  // parallel lines [rad]
};
std::string FamilyName(const GuideFamily& f);

struct PlanOptimiseOptions {
  Optimiser method{Optimiser::kNlopt};
  Pattern pattern{Pattern::kCycloid};
  /// Cycloid guide families tried (empty: offsets, lines along s, along t).
  std::vector<GuideFamily> families;
  double offset_min{0.004}, offset_max{0.030};  // cycloid d bounds [m]
  double feasibility_margin{0.98};  // grid difference optimiser -> final grid
  int starts{3};                    // local searches
  double ftol_rel{5e-3};            // local stop: relative change of the cv
  int max_local_evaluations{120};   // per local search (a safety net)
  double max_time_s{50.0};          // all of it
  int threads{2};
  bool compare_parallel{true};      // cycloid: optimise the zig-zag too
  unsigned seed{20240404};          // PSO
  /// After each evaluation (from any thread, serialised): the count, the
  /// best feasible cv so far (NaN before the first), elapsed seconds.
  std::function<void(int, double, double)> progress;

  /// The bounds (issue #36); starts and threads below 1 are taken as 1:
  /// - offset_min > 0 [m] and offset_max > offset_min, finite: the search is on
  ///   log(d / offset_min) / log(offset_max / offset_min).
  /// - feasibility_margin in (0, 1]: the target is divided by it; above 1
  ///   the optimiser would hold its plans to more than the target.
  /// - ftol_rel in [0, 1]: a relative change of the cv (0: none, the budgets stop).
  /// - max_local_evaluations >= 1: NLopt takes a budget <= 0 as none.
  /// - max_time_s >= 0 [s]: a NaN would never run out.
  /// @throws OptionError(field, "FIELD: expected ..., got VALUE") naming the bound.
  void Validate() const;
};

struct PlanOptimiseResult {
  PlanEvaluation best;           // of options.pattern
  PlanEvaluation best_parallel;  // the optimised zig-zag (pattern parallel: = best)
  std::vector<PlanEvaluation> family_best;  // cycloid: the best per family tried
  /// Per evaluation, in order: its cv if feasible (NaN if not), and the
  /// best feasible cv so far (NaN before the first feasible one).
  std::vector<double> cv_history, best_history;
  /// Per evaluation: 1 if it was a zig-zag (the cycloid's comparison).
  std::vector<char> history_parallel;
  int evaluations{0};
  int local_searches{0}, local_converged{0};
  /// kConverged when every local search met ftol_rel (the zig-zag: within
  /// the time budget; the PSO: OptimiseResult's), kNotConverged when the
  /// time budget or a local search's evaluation budget ran out (the best so
  /// far is returned), kFailed as OptimiseResult's.
  SolverStatus status{SolverStatus::kConverged};
  /// Why it stopped, in the optimiser's words: "converged", "max_time",
  /// "max_evaluations" (and the PSO's, OptimiseResult::stop_reason).
  std::string stop_reason;
  std::string method;
  double seconds{0.0};
};

/// @throws PathRowError for a contact that fails on the surface.
PlanOptimiseResult OptimisePlan(const PlanProblem& problem, const PathParameters& start,
                                const PlanOptimiseOptions& options);

}  // namespace robomach::polishing
