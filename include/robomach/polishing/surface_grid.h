#pragma once

// Sampling of a NURBS patch uniformly in arc length, the polished region
// (points at least `margin` from the patch boundary, measured on the surface
// along the iso-parameter lines through the point), and the developed (s, t)
// plane in which paths are laid out: s and t are the mean arc lengths along
// u and v, so that (s, t) -> (u(s), v(t)) -> S is a length-preserving map on
// planes and cylinders and a mild distortion on doubly curved patches.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/polishing/nurbs_surface.h"

namespace robomach::polishing {

/// Size of a patch: mean and largest arc length of its iso-parameter lines
/// along u and v [m] (the sampling grid's spacing follows the largest).
struct SurfaceSize {
  double length_u{0}, length_v{0};  // mean over 9 iso-lines
  double max_u{0}, max_v{0};        // longest iso-line
};
/// `fine` chords per iso-line (SampleGrid::Build uses 2000).
SurfaceSize MeasureSurface(const NurbsSurface& surface, int fine = 400);

/// Grid points SampleGrid::Build makes at `max_spacing` (a double: it may be
/// far beyond int; +inf for a non-finite size).
double EstimateGridPoints(const SurfaceSize& size, double max_spacing);

/// The largest grid SampleGrid::Build makes (~90 bytes a point: 0.9 GB).
constexpr double kMaxGridPoints = 1e7;

/// "file.step, face 3" for a CAD face, "the patch" otherwise (for messages).
std::string SurfaceName(const NurbsSurface& surface);

class SampleGrid {
 public:
  /// Samples `surface` with at most `max_spacing` [m] between neighbouring
  /// points along either parameter direction.
  /// @throws std::domain_error at a degenerate point (no normal), for a patch
  /// whose size is not finite (NaN or infinite control points), or when the
  /// grid would exceed `max_points` (the message gives the face, its size and
  /// the count).
  static SampleGrid Build(const NurbsSurface& surface, double max_spacing, double margin, bool flip_normal,
                          double max_points = kMaxGridPoints);

  int ns() const { return ns_; }
  int nt() const { return nt_; }
  int size() const { return ns_ * nt_; }
  int index(int i, int j) const { return j * ns_ + i; }  // i along s (u), j along t (v)
  double length_s() const { return length_s_; }  // mean arc length along u [m]
  double length_t() const { return length_t_; }
  double s(int i) const { return s_[i]; }
  double t(int j) const { return t_[j]; }
  double u(int i) const { return u_[i]; }
  double v(int j) const { return v_[j]; }

  const std::vector<Eigen::Vector3d>& points() const { return p_; }
  const std::vector<Eigen::Vector3d>& normals() const { return n_; }
  const std::vector<double>& areas() const { return area_; }    // area weight [m^2]
  const std::vector<char>& in_region() const { return in_region_; }
  int num_in_region() const;
  /// Area of the polished region: the area weights of its points [m^2].
  double region_area() const;
  /// Bounding box of the polished region in the (s, t) plane [m].
  double s_lo() const { return s_lo_; }
  double s_hi() const { return s_hi_; }
  double t_lo() const { return t_lo_; }
  double t_hi() const { return t_hi_; }

  /// Parameters of a developed point (clamped to the patch).
  double UOfS(double s) const;
  double VOfT(double t) const;
  /// Developed coordinates of parameters (the inverse maps).
  double SOfU(double u) const;
  double TOfV(double v) const;
  /// d u / d s and d v / d t at a developed point.
  double DuDs(double s) const;
  double DvDt(double t) const;

 private:
  int ns_{0}, nt_{0};
  double length_s_{0}, length_t_{0};
  double s_lo_{0}, s_hi_{0}, t_lo_{0}, t_hi_{0};
  std::vector<double> s_, t_, u_, v_;
  std::vector<double> table_s_, table_u_, table_t_, table_v_;  // arc length <-> parameter
  std::vector<Eigen::Vector3d> p_, n_;
  std::vector<double> area_;
  std::vector<char> in_region_;
};

/// Closest point of `surface` to `x` by Newton's method from (u, v);
/// returns the distance [m] and updates u, v. Clamped to the patch.
double ProjectToSurface(const NurbsSurface& surface, const Eigen::Vector3d& x, double* u, double* v);

}  // namespace robomach::polishing
