#pragma once

// Tool paths on a sampled patch (seed 004 §2.2-3.1; formats.md §6): cycloids
// (seed eq. 11) rolling along guide lines, and the direction-parallel
// (zig-zag) pattern for comparison. Paths are laid out in the developed
// (s, t) plane of the SampleGrid and mapped onto the surface; the tool frame
// is z = surface normal, x = the guide line's tangent (seed eq. 16).
//
// Cycloid parametrisation (the README documents it): guide-line offset d
// (spacing of adjacent guide lines), radius r, pitch = advance of the
// circle's centre per loop. With the seed's rolling rate omega [rad/s] and
// centre speed v: pitch = 2 pi v / omega. The shape depends on (d, r,
// pitch) only; the time scale (omega, and v = pitch omega / 2 pi) is set
// afterwards by the speed limit or the target removal.
//
// Two more shape parameters (issue 19): the stagger, the phase of the loops
// of one guide line against the previous one, in loops (0.5: half a loop,
// seed 004 §3.1 Fig. 11: a loop of one row faces the gap between two loops
// of the next); and, for parallel guide lines and the zig-zag, the lines'
// direction in the developed plane (line_angle, 0: along s).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::polishing {

enum class Pattern { kCycloid, kParallel };
enum class GuideLines { kBoundaryOffsets, kParallelLines };

/// "cycloid", "parallel": the name of the pattern's PathPattern (polish-plan's
/// --pattern, summaries).
std::string ToString(Pattern p);
/// The id of PathPatternRegistry()'s pattern `name` (path_patterns.h).
/// @throws std::invalid_argument "unknown path pattern 'NAME': expected
/// cycloid or parallel".
Pattern ParsePattern(const std::string& name);

/// "offsets", "parallel" (PlanOptions::guides, polish-plan's --guides).
std::string ToString(GuideLines g);
/// @throws std::invalid_argument "guides 'NAME': expected offsets or parallel".
GuideLines ParseGuideLines(const std::string& name);

struct PathParameters {
  Pattern pattern{Pattern::kCycloid};
  GuideLines guides{GuideLines::kBoundaryOffsets};  // cycloid only
  double offset{0.008};    // d: guide-line spacing (row spacing of the parallel pattern) [m]
  double radius{0.006};    // r [m] (cycloid)
  double pitch{0.003};     // centre advance per loop [m] (cycloid)
  double row_step{0.5e-3}; // largest distance between consecutive rows [m]
  /// Cycloid on boundary offsets: distance of the outermost guide loop from
  /// the region boundary [m]; < 0 (default): on the boundary, or r - margin
  /// inside it if the margin is narrower than r (the circle stays on the face).
  double edge_inset{-1.0};
  /// Phase of adjacent cycloid rows, in loops, [0, 1). On parallel guide
  /// lines it is spatial: the rolling angle at the centre position c of
  /// line k (k-th line across) is 2 pi (c . e / pitch + stagger k), e the
  /// lines' direction, whichever way the boustrophedon runs the line. On
  /// boundary offsets loop k starts at the phase 2 pi stagger k.
  double stagger{0.5};
  /// Direction of the parallel guide lines (cycloid) and of the zig-zag's
  /// rows in the developed (s, t) plane [rad], 0: along s, pi/2: along t.
  double line_angle{0.0};
  /// Plain patches (rectangular regions): how far the guide lines (the
  /// zig-zag's rows) run beyond the polished region into the margin [m],
  /// at most margin - r for the cycloid (the circle stays on the patch) and
  /// margin for the zig-zag (PlanPath clips to that). Boundary offsets: the
  /// outermost loop that far outside the region. Rows that stop at the
  /// region's edge leave it half polished (issue 19). Ignored on trimmed faces.
  double edge_overrun{0.0};
};

/// The largest edge_overrun PlanPath uses for `p` [m].
double MaxEdgeOverrun(const PathParameters& p, const PolishingProcess& process);

/// Seed 004 §3.2 feasibility limits in this parametrisation: d <= 2 r
/// (no unpolished strip between rows, Fig. 10), 0.5 d <= r <= d (limit 3),
/// and the centre slower than the rolling point, v < omega r, i.e.
/// pitch < 2 pi r (limit 2: the curve still loops, Fig. 13).
/// @throws std::invalid_argument naming the violated limit.
void CheckValid(const PathParameters& p);

struct PlannedPath {
  std::vector<PathRow> rows;
  /// Guide lines (row centre lines of the parallel pattern) on the surface [m].
  std::vector<std::vector<Eigen::Vector3d>> guide_lines;
  /// The same in the developed (s, t) plane of the SampleGrid [m].
  std::vector<std::vector<Eigen::Vector2d>> guide_lines_st;
  double length{0.0};            // [m]
  double omega_rad_per_s{0.0};   // cycloid rolling rate with the current time stamps
  double centre_speed{0.0};      // [m/s]
  /// Links where the tool is lifted (rows with force 0) because the straight
  /// move on the surface would leave the face (across a hole or a notch of a
  /// trimmed face). With lifts, every row carries its force.
  int lifts{0};
};

/// Plans the path with time stamps at the fastest rate that keeps every
/// segment at or below process.max_speed. On a rectangular region (a plain
/// patch) the guide loops are rectangles and a centre line; on any other
/// region (a trimmed face: curved outline, holes) they are the region's
/// equidistant offsets (region_outline.h), and parallel lines are clipped to
/// it and run cell by cell.
PlannedPath PlanPath(const NurbsSurface& surface, const SampleGrid& grid, const PathParameters& params,
                     const PolishingProcess& process);

/// Multiplies all time stamps by `factor` (> 1 slows down), keeping omega and
/// the centre speed consistent.
void ScaleTime(PlannedPath* path, double factor);

/// Length of the path in contact [m]: segments that start at a lifted row
/// (force 0) are in the air.
double ContactLength(const std::vector<PathRow>& rows);
/// Number of lifts: rows with force 0 that follow a row in contact.
int CountLifts(const std::vector<PathRow>& rows);

/// Largest segment speed of a path [m/s].
double MaxSpeed(const std::vector<PathRow>& rows);

/// Width of the contact across tool x (2 x the half-width along tool y) on
/// the surface at the region's centre [m]: the default row spacing of the
/// parallel pattern (tracks touching).
double ContactWidthAtCentre(const NurbsSurface& surface, const SampleGrid& grid, const PolishingProcess& process);

struct TargetResult {
  bool reached{false};   // false: the target needs a speed above max_speed
  double mean{0.0};      // mean removal over the region after scaling [m]
  std::vector<double> removal;  // at every grid point [m]
  std::string message;
};
/// Sets the time stamps so that the area-weighted mean removal over the
/// region equals `target` [m] (a few fixed-point steps: the removal is
/// inversely proportional to the speed up to v_rel's small dependence on
/// it). If that needs a speed above process.max_speed, the path runs at the
/// limit and the result says so.
TargetResult ScaleToTargetRemoval(const RemovalSimulator& sim, const SampleGrid& grid, double target,
                                  double max_speed, PlannedPath* path);

/// Rows of a path read from a file: fills u, v by projecting x, y, z on the
/// surface (from the row's u, v when given), checks the 0.01 mm tolerance
/// and the tool side.
/// @throws PathRowError naming the row.
void AttachToSurface(const NurbsSurface& surface, const SampleGrid& grid, bool flip_normal,
                     std::vector<PathRow>* rows);

}  // namespace robomach::polishing
