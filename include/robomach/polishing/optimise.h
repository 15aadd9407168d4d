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

#include "robomach/polishing/paths.h"

namespace robomach::polishing {

enum class Optimiser { kNlopt, kPso };

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
};

struct OptimiseResult {
  PathParameters best;
  double best_value{0.0};
  std::vector<double> history;  // best value after each iteration (PSO) or evaluation (NLopt)
  int evaluations{0};
  std::string status;           // "converged", "max_iterations", "max_evaluations", ...
  std::string method;           // human-readable description
};

/// `objective(params)` returns the value to minimise (cv); `start` gives
/// the pattern, guides and row step, and the NLopt local start if the
/// global stage finds nothing better.
OptimiseResult OptimiseCycloid(const std::function<double(const PathParameters&)>& objective,
                               const PathParameters& start, const OptimiseOptions& options);

}  // namespace robomach::polishing
