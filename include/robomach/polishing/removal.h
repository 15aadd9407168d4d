#pragma once

// Preston removal (seed 004 eqs. 1-10; formats.md §7): h = Kp * integral of
// p * v_rel dt, with the Hertz pressure p = p0 sqrt(1 - X^2/a^2 - Y^2/b^2)
// of the contact ellipse and v_rel = |belt_speed * tool_x + traverse
// velocity|. Between two rows the contact moves along the straight segment
// at constant speed with the contact of the segment's first row; the time
// integral over the segment is then done in closed form (the pressure along
// a straight line through an ellipse is the square root of a quadratic).

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/process.h"

namespace robomach::polishing {

/// One row of a tool path (formats.md §6), SI.
struct PathRow {
  double t{0.0};               // [s]
  Eigen::Vector3d p;           // contact point [m]
  Eigen::Vector3d n;           // tool z, unit surface normal towards the tool
  Eigen::Vector3d tx;          // tool x, unit, normal to n
  double u{0.0}, v{0.0};       // surface parameters of p
  double force{-1.0};          // [N]; < 0: the process force; 0: the tool is lifted
                               // (a segment starting or ending at 0 removes nothing)
};

/// The row's contact frame C in the part frame P: origin p, z = n (towards
/// the tool), x = tx, y = n × tx.
Eigen::Isometry3d ContactFrame(const PathRow& row);

/// The contact at one path row, in 3-D: ellipse centre p, semi-axes a (along
/// e_a, the axis nearer tool x) and b (along e_b), peak pressure p0.
struct ToolContact {
  Eigen::Vector3d p, n, e_a, e_b;
  double a{0.0}, b{0.0}, p0{0.0};
};

/// Hertz contact of the wheel (curvature 1/wheel_radius along tool x,
/// 1/crown_radius along tool y) on the surface at `d`.
/// @throws std::domain_error for a non-positive relative curvature or a
///   contact wider than the belt.
ToolContact ContactAt(const SurfaceDerivatives& d, const Eigen::Vector3d& tool_x, const PolishingProcess& process,
                      double force);

/// Integral over tau in [0, 1] of sqrt(max(0, 1 - |alpha - beta tau|^2)):
/// the normalised pressure seen by a point at elliptic coordinates alpha
/// while the ellipse centre moves by beta (elliptic units).
double SegmentPressureIntegral(const Eigen::Vector2d& alpha, const Eigen::Vector2d& beta);

/// Removal at fixed sample points. Immutable after construction; Simulate
/// may be called from several threads.
class RemovalSimulator {
 public:
  /// `points`/`normals`: the sample points [m] and their unit normals;
  /// `cell_size` [m] of the uniform spatial index (about the contact size).
  RemovalSimulator(const NurbsSurface& surface, const PolishingProcess& process,
                   std::vector<Eigen::Vector3d> points, std::vector<Eigen::Vector3d> normals, double cell_size);

  /// Contact of every row (evaluated at the row's u, v).
  /// @throws PathRowError naming the row for a bad contact.
  std::vector<ToolContact> Contacts(const std::vector<PathRow>& path) const;
  /// Removal depth [m] at every sample point.
  /// @throws PathRowError (t not strictly increasing, bad contact).
  std::vector<double> Simulate(const std::vector<PathRow>& path) const;
  std::vector<double> Simulate(const std::vector<PathRow>& path, const std::vector<ToolContact>& contacts) const;

  int num_points() const { return static_cast<int>(points_.size()); }

 private:
  const NurbsSurface* surface_;
  PolishingProcess process_;
  std::vector<Eigen::Vector3d> points_, normals_;
  // Uniform grid index: cell (ix, iy, iz) holds points cell_start_[c] ..
  // cell_start_[c + 1] - 1 of order_.
  Eigen::Vector3d origin_;
  double cell_{1.0};
  int nx_{1}, ny_{1}, nz_{1};
  std::vector<int> cell_start_, order_;
  // x, y, z of the points, then of the normals, in cell order (order_).
  std::vector<double> sorted_;
};

/// Area-weighted removal statistics (formats.md §7), in the input's unit.
struct RemovalStats {
  double mean{0}, std{0}, variance{0}, cv{0}, min{0}, max{0}, peak_to_valley{0}, coverage{0};
  /// Area of the points with a removal below 1 % of the mean: left
  /// unpolished (necks the cycloid cannot enter, gaps between rows) [the
  /// area's unit].
  double unpolished_area{0};
};
/// Over the entries with mask != 0 (all if mask empty).
RemovalStats ComputeRemovalStats(const std::vector<double>& removal, const std::vector<double>& area,
                                 const std::vector<char>& mask = {});

/// What a user should hear when part of the region is left unpolished
/// (stats in m and m^2, `region_area` [m^2]): how much, and the likely
/// reasons for the path's `pattern` ("cycloid", "parallel", or "" when not
/// known: a path file without its pattern line). Empty when nothing is.
std::string DescribeUnpolished(const RemovalStats& stats, double region_area, const std::string& pattern = "");

}  // namespace robomach::polishing
