#pragma once

// The polished region as polygons in the developed (s, t) plane of a
// SampleGrid, and its equidistant inward offsets: the guide lines of
// contour-parallel paths on trimmed faces (outlines that are not
// rectangles, holes). Offsetting is done by Clipper (libpolyclipping, round
// joins), in integer units of 0.1 um.
//
// The developed plane is length-preserving on planes and cylinders, so there
// the offsets are exactly equidistant on the surface; on doubly curved
// patches they carry the developed plane's mild distortion (surface_grid.h).

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::polishing {

/// A closed polygon in the developed plane [m]; the last point is not repeated.
using Polygon2 = std::vector<Eigen::Vector2d>;

/// Signed area of a closed polygon [m^2]: > 0 counter-clockwise (s right, t up).
double SignedArea(const Polygon2& p);

class DevelopedRegion {
 public:
  /// The polished region of `surface`: for a plain patch (or a face whose
  /// trimming wires are its patch's boundary) the grid's bounding rectangle
  /// of the region; for a trimmed face its wires (FaceTrim::wires_uv) mapped
  /// to (s, t) and offset inwards by `margin` [m].
  static DevelopedRegion Build(const NurbsSurface& surface, const SampleGrid& grid, double margin);
  /// From polygons in the developed plane (even-odd: a polygon inside another is a hole).
  static DevelopedRegion FromPolygons(const std::vector<Polygon2>& loops);

  /// True if the region is one axis-aligned rectangle (to 1e-6 of its area).
  bool rectangle() const { return rectangle_; }
  /// Outer boundaries counter-clockwise, holes clockwise (s right, t up).
  const std::vector<Polygon2>& loops() const { return loops_; }
  double Area() const;
  /// Bounding box [s_lo, t_lo, s_hi, t_hi].
  Eigen::Vector4d Bounds() const;

  /// The closed loops at `distance` [m] inside the boundary (holes grow,
  /// outer boundaries shrink, round joins), in the same orientation
  /// convention; empty once the region has vanished.
  std::vector<Polygon2> Offset(double distance) const;
  /// The largest distance from the boundary of a point of the region
  /// (radius of the largest inscribed circle) [m], to 1e-6 m or 1e-6 of the
  /// region's size, whichever is larger.
  double Inradius() const;
  /// The intervals [s0, s1] (sorted) where the line t = const crosses the region.
  std::vector<std::pair<double, double>> Intervals(double t) const;
  /// Even-odd inside test.
  bool Contains(const Eigen::Vector2d& st) const;
  /// Distance from `st` to the nearest boundary edge [m].
  double DistanceToBoundary(const Eigen::Vector2d& st) const;

 private:
  std::vector<Polygon2> loops_;
  bool rectangle_{false};
};

}  // namespace robomach::polishing
