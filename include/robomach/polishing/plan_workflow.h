#pragma once
// polish-plan's workflow as library calls (issue #21): the sampled region
// and the contact on a surface (PreparePlanning), then a path planned,
// optionally optimised for uniform removal, simulated and timed for a
// target removal (PlanPolishing); the optimised cycloid is compared with the
// optimised zig-zag. The tool reads the files, resolves its options into
// PathParameters (an invalid one is a command-line error) and writes what
// comes back.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "robomach/common/run_status.h"
#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/optimise.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::polishing {

/// The sampled region of a surface and what the contact makes of it.
struct PlanningContext {
  const NurbsSurface* surface{nullptr};  // not owned; outlives the context
  PolishingProcess process;
  double sample_spacing{0.5e-3};  // [m]
  std::shared_ptr<const SampleGrid> grid;
  double contact_width{0.0};  // across the path at the region's centre [m]
  std::shared_ptr<const RemovalSimulator> simulator;
  /// Where the surface and the process came from, for errors.
  std::string surface_source, process_source;
};

/// Samples the region (arc-length spacing `sample_spacing` [m], the
/// process's margin), computes the contact width at its centre and builds
/// the removal simulator.
/// @throws InputError naming the surface file for a surface that cannot be
///   sampled or a contact that fails at the centre, and the process file
///   for a margin that leaves no region.
PlanningContext PreparePlanning(const NurbsSurface& surface, const PolishingProcess& process, double sample_spacing,
                                const std::string& surface_source, const std::string& process_source);

/// How to plan: the path's parameters, and optionally the optimisation and
/// the target removal.
struct PlanRequest {
  PathParameters params;  // as given (CheckValid passed)
  /// Mean removal over the region to time the path for [m]; 0: at the
  /// speed limit.
  double target_removal{0.0};
  /// Optimise (OptimisePlan) with this method, on a coarser grid.
  std::optional<Optimiser> optimise;
  bool guides_given{false};  // the optimiser keeps params.guides (else it chooses the family)
  double opt_sample_spacing{1e-3};             // [m]
  double opt_offset_min_contact_widths{0.3};   // smallest spacing tried, in contact widths
  double opt_offset_max{0.030};                // largest spacing tried [m]
  double max_time_s{50.0};
  int threads{2};
  unsigned seed{20240404};
  /// OptimisePlan's progress: evaluations, best feasible cv, elapsed [s].
  std::function<void(int, double, double)> progress;
};

/// polish-plan's options as a user gives them: the names and units of its
/// command line and of Python's plan_polishing, with their defaults.
struct PlanOptions {
  std::string pattern{"cycloid"};  // a PathPatterns() name
  std::string guides{"offsets"};   // cycloid guide lines: offsets (of the boundary) or parallel
  /// Guide-line / row spacing; none: 8 mm for the cycloid, one contact
  /// width for the zig-zag.
  std::optional<double> offset_mm;
  double radius_mm{6.0}, pitch_mm{3.0}, row_step_mm{0.5};
  double edge_inset_mm{-1.0};  // < 0: on the boundary, or r - margin inside
  double stagger_loops{0.5}, edge_overrun_mm{0.0}, line_angle_deg{0.0};
  double target_removal_um{0.0};  // 0: at the speed limit
  std::string optimise{"none"};   // none, nlopt or pso
  bool guides_given{false};       // the optimiser keeps `guides`
  double opt_sample_mm{1.0}, opt_offset_max_mm{30.0}, opt_offset_min_contact_widths{0.3}, max_time_s{50.0};
  int threads{2};
  unsigned seed{20240404};
  double sample_mm{0.5};  // the region's sampling, PreparePlanning's spacing

  /// The checks (issue #36), in this order:
  /// - guides: ParseGuideLines's names (OptionError "guides", "guides
  ///   'NAME': expected offsets or parallel").
  /// - optimise: none or a ParseOptimiser name (OptionError "optimise",
  ///   "optimise: expected none, nlopt or pso, got NAME").
  /// - pattern: a PathPatterns() name (OptionError "pattern", "unknown path
  ///   pattern 'NAME': expected cycloid or parallel").
  /// - optimise pso only with the cycloid (OptionError "optimise").
  /// - the numeric options within PlanOptionRanges: the ranges keep a typo
  ///   from hours of work or an allocation failure (a 1e-6 mm sampling).
  /// @throws OptionError(field, message); a range's "FIELD: expected a value
  ///   in [LO, HI], got VALUE".
  void Validate() const;
};

/// One numeric option with the range it must lie in: the limits keep a typo
/// from hours of work or an allocation failure (a 1e-6 mm sampling), and
/// are those of polish-plan's command line (`name` is the option's name
/// with '_' for '-').
struct PlanOptionRange {
  std::string name;
  double value, lo, hi;
};
std::vector<PlanOptionRange> PlanOptionRanges(const PlanOptions& options);

/// @throws std::invalid_argument "name: expected a value in [lo, hi], got v"
///   for the first option outside its range.
void CheckRanges(const PlanOptions& options);

/// Plausible removal of one planned pass [um] (docs/plausibility.md): fine
/// polishing removes 0.1 - 10 um, robotic belt grinding of blades and
/// castings 10 - 500 um per pass (Ren, Kuhlenkoetter and Mueller, Int. J.
/// Adv. Manuf. Technol. 27 (2006); Huang et al., J. Mater. Process. Technol.
/// 127 (2002)); 0 is "at the speed limit".
inline constexpr double kMinPlausibleTargetRemovalUm = 0.01;
inline constexpr double kMaxPlausibleTargetRemovalUm = 1000.0;

/// Sense checks of the options a user types (issue #35): one message per
/// value outside its plausible range, "implausible (unit mistake?): ..."
/// naming the likely unit mistake (line_angle_deg in radians, then
/// target_removal_um), for polish-plan to warn and flag (exit
/// 3) and for Python to issue as UnitWarnings. Empty when all are plausible.
std::vector<std::string> ImplausiblePlanOptions(const PlanOptions& options);

/// The request `options` make on `context` (the zig-zag's default spacing
/// is its contact width); `progress` is not set.
/// @throws std::invalid_argument for an unknown pattern, guides or
///   optimiser, the PSO asked for the zig-zag, and path parameters outside
///   their limits (CheckValid): all of them mistakes in the options.
PlanRequest ToPlanRequest(const PlanOptions& options, const PlanningContext& context);

/// A planned, simulated path.
struct EvaluatedPlan {
  PlannedPath path;
  std::vector<double> removal;  // at every grid point [m]
  RemovalStats stats;
};

/// Flagged (its `verdict`; exit 3 in the tool) with one finding for each
/// thing the user should act on: no feasible plan, a target out of reach, a
/// better zig-zag, rows off the face.
struct PlanOutcome {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  PathParameters params;  // what was planned (the optimum with optimise)
  EvaluatedPlan plan;
  /// With optimise: the optimiser's result, the bounds it searched, and
  /// for the optimised pattern's evaluations only, each one's cv (NaN:
  /// infeasible) and the best feasible so far.
  std::optional<PlanOptimiseResult> optimisation;
  double opt_offset_min{0.0}, opt_offset_max{0.0};
  std::vector<double> history_cv, history_best;
  /// The optimiser found no plan that reaches the target and covers the
  /// region (the least infeasible is planned): why, for the user.
  std::string infeasible_message;
  /// With a target: whether the speed limit allows it, and why not.
  bool target_given{false};
  TargetResult target;
  /// The optimised cycloid against the optimised zig-zag, both on the final
  /// grid and timed for the target.
  struct Comparison {
    PathParameters parallel;
    RemovalStats parallel_stats;
    bool parallel_reaches_target{true};
    bool zigzag_better{false};
  };
  std::optional<Comparison> comparison;
  /// Rows in contact off a trimmed face (a planner bug, or the developed
  /// plane's distortion on a strongly doubly curved face); 0 on a patch.
  int rows_off_face{0};
};

/// Plans `request.params` (or the optimum) on the context's region.
/// @throws InputError naming the surface file for a contact that fails at a
///   row (with its position) or a cycloid too wide for the face;
///   std::runtime_error when the optimiser finds no plan that fits.
PlanOutcome PlanPolishing(const PlanningContext& context, const PlanRequest& request);

/// Plans and simulates `params` on the context's grid.
/// @throws InputError naming the surface file and the row for a contact
///   that fails.
EvaluatedPlan EvaluatePlanOnGrid(const PlanningContext& context, const PathParameters& params);

/// Path rows in contact (force != 0) whose (u, v) lie off a trimmed face.
int RowsOffFace(const NurbsSurface& surface, const std::vector<PathRow>& rows);

}  // namespace robomach::polishing
