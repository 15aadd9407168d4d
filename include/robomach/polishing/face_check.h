#pragma once

// Can a face be polished with a process and a path's circle? (issue 19,
// real CAD parts): the region left after the process margin must exist and,
// for the cycloid, admit its rolling circle, so that no row is clamped onto
// the patch's edges; and the face must be small enough to sample. Used by
// the planner (PlanPath), by the optimiser's feasibility (through PlanPath)
// and by `polish-plan --list-faces`.

#include <stdexcept>
#include <string>

#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/region_outline.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::polishing {

/// "face too narrow for the circle": the cycloid's circle, with its centre on
/// the innermost guide line, would leave the face (rows clamped onto the
/// patch's edges). A std::invalid_argument, so that the optimiser counts the
/// parameters infeasible.
class FaceTooNarrowError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Throws FaceTooNarrowError (naming the face, its width and the circle's
/// radius) if the cycloid of `params` does not fit `region` of `surface`:
/// the circle stays on the face only if its centre stays r - margin inside
/// the region (the default edge inset), so the region's inscribed circle
/// must have a radius of at least r - margin (plus 50 um of clearance for
/// the chords of a trimmed outline, as the planner's guide loops use).
/// Does nothing for the parallel pattern.
void CheckCircleFits(const NurbsSurface& surface, const SampleGrid& grid, const DevelopedRegion& region,
                     const PathParameters& params, const PolishingProcess& process);

struct PolishableOptions {
  double sample_spacing{0.5e-3};   // the planner's sampling [m]
  /// Refuse larger faces: the issue 19 budget is 60 s and 2 GB per face;
  /// OCCT's hammer face 32 read as mm (1.24e6 points, ~4.9e5 rows) took
  /// 190 s and 0.4 GB on the shared 2-core machine.
  double max_grid_points{1e6};
  double max_path_rows{3e5};
  /// The region is measured on a grid of at most this many points (the
  /// margin and width are then known to one coarse spacing).
  double check_grid_points{2e4};

  /// The bounds (issue #36):
  /// - sample_spacing > 0 and finite [m]: a grid's spacing.
  /// - max_grid_points, max_path_rows and check_grid_points >= 1: a count
  ///   of points or rows (check_grid_points divides the region).
  /// @throws OptionError(field, "FIELD: expected ..., got VALUE") naming the bound.
  void Validate() const;
};

struct Polishability {
  bool polishable{false};
  std::string reason;              // why not ("" when polishable)
  double grid_points{0};           // at sample_spacing
  double region_width{0};          // diameter of the region's inscribed circle [m]
  double contact_width{0};         // [m], 0 if not reached
};

/// Rows of a path over `area` [m^2] (order of magnitude): the area swept row
/// by row at params.offset, the cycloid running ~2 pi r per pitch of advance,
/// a row every params.row_step.
double EstimatePathRows(double area, const PathParameters& params);

/// Whether `surface` can be polished with `process` and the circle of
/// `params` (cycloid) or the parallel rows: not too large to sample at
/// options.sample_spacing, a region left after the margin, the contact
/// defined at its centre (convex enough) and, for the cycloid, the circle
/// fitting the region (CheckCircleFits), and the estimated path not longer
/// than options.max_path_rows. Never throws for a bad face: the
/// reason says what is wrong, naming the face and its size.
Polishability CheckPolishable(const NurbsSurface& surface, const PolishingProcess& process,
                              const PathParameters& params, const PolishableOptions& options = {});

/// How big planning on a surface will be, before the work (polish-plan
/// refuses a face beyond the limits and warns about a large one).
struct PlanSize {
  std::string what;      // "<surface name> (L_u x L_v mm, mean arc lengths along u and v; A mm^2)"
  std::string estimate;  // "<points> grid points at --sample-mm S (~G GB) and a path of ~R rows"
  double grid_points{0.0};
  double path_rows{0.0};
  bool too_large{false};  // beyond options.max_grid_points or max_path_rows
  /// With too_large: "<what> is too large to plan within the limits (...):
  /// <estimate>", for the caller to add how to fix it in its own terms.
  std::string too_large_message;
  bool large{false};      // over 2e5 grid points or 1e5 rows: a minute or more
};
PlanSize EstimatePlanSize(const NurbsSurface& surface, double sample_spacing, const PathParameters& params,
                          const PolishableOptions& limits = {});

}  // namespace robomach::polishing
