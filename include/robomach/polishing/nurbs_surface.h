#pragma once

// A rational B-spline (NURBS) surface patch of any degree, formats.md §5:
// S(u,v) = sum N_i,p(u) N_j,q(v) w_ij P_ij / sum N_i,p(u) N_j,q(v) w_ij
// (The NURBS Book, Piegl and Tiller, eq. 4.1), with first and second
// derivatives (rational quotient rule, The NURBS Book eq. 4.20), the unit
// normal and the principal curvatures and directions.

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/polishing/face_trim.h"

namespace robomach::polishing {

/// Point and partial derivatives of S at (u, v) [m, m per parameter unit].
struct SurfaceDerivatives {
  Eigen::Vector3d S, S_u, S_v, S_uu, S_uv, S_vv;
};

/// Principal curvatures at a point, signed so that a surface that bulges
/// towards the side of `normal` (convex as seen by the tool) has positive
/// curvature: a cylinder of radius R with its outward normal has k1 = 1/R.
/// k1 >= k2; d1, d2 are the unit principal directions (tangent, orthogonal).
struct SurfaceCurvature {
  Eigen::Vector3d normal;   // unit
  double k1{0.0}, k2{0.0};  // [1/m]
  Eigen::Vector3d d1, d2;   // unit, tangent
};

/// Immutable NURBS patch; lengths in metres.
class NurbsSurface {
 public:
  /// control_points[i][j], i < n_u, j < n_v; weights the same shape (empty:
  /// all 1). Knot vectors non-decreasing, len = n + degree + 1, clamped.
  /// @throws std::invalid_argument naming the violated rule and the values.
  static NurbsSurface Create(int degree_u, int degree_v, std::vector<double> knots_u,
                             std::vector<double> knots_v,
                             std::vector<std::vector<Eigen::Vector3d>> control_points,
                             std::vector<std::vector<double>> weights = {});

  int degree_u() const { return p_; }
  int degree_v() const { return q_; }
  int num_u() const { return n_u_; }
  int num_v() const { return n_v_; }
  const std::vector<double>& knots_u() const { return knots_u_; }
  const std::vector<double>& knots_v() const { return knots_v_; }
  double u_min() const { return knots_u_[p_]; }
  double u_max() const { return knots_u_[n_u_]; }
  double v_min() const { return knots_v_[q_]; }
  double v_max() const { return knots_v_[n_v_]; }
  const Eigen::Vector3d& control_point(int i, int j) const { return points_[i * n_v_ + j]; }
  double weight(int i, int j) const { return weights_[i * n_v_ + j]; }

  /// Point and derivatives up to second order; (u, v) is clamped to the
  /// parameter range.
  SurfaceDerivatives Evaluate(double u, double v) const;
  Eigen::Vector3d Point(double u, double v) const { return Evaluate(u, v).S; }

  /// A CAD face: the patch is the face's underlying surface and `trim` its
  /// trimming wires; the polished region is then the trimmed face minus the
  /// margin (SampleGrid). Null for a plain patch (the whole rectangle).
  const FaceTrim* trim() const { return trim_.get(); }
  NurbsSurface WithTrim(std::shared_ptr<const FaceTrim> trim) const {
    NurbsSurface s = *this;
    s.trim_ = std::move(trim);
    return s;
  }
  /// True if (u, v) is on the surface: inside the parameter rectangle and,
  /// for a trimmed face, on the face.
  bool OnFace(double u, double v) const;

 private:
  NurbsSurface() = default;
  int p_{0}, q_{0}, n_u_{0}, n_v_{0};
  std::vector<double> knots_u_, knots_v_;
  std::vector<Eigen::Vector3d> points_;  // row-major n_u x n_v
  std::vector<double> weights_;
  std::shared_ptr<const FaceTrim> trim_;
};

/// Unit normal (S_u x S_v) / |S_u x S_v|, reversed if `flip`.
/// @throws std::domain_error at a degenerate point (S_u x S_v = 0).
Eigen::Vector3d UnitNormal(const SurfaceDerivatives& d, bool flip = false);

/// Principal curvatures and directions from the first and second fundamental
/// forms (shape operator eigenproblem -II x = k I x).
/// @throws std::domain_error at a degenerate point.
SurfaceCurvature PrincipalCurvatures(const SurfaceDerivatives& d, bool flip = false);

/// Curvature tensor in the tangent basis (e1, e2) (both unit, tangent,
/// orthogonal): kappa_ij = -n . d2S(e_i, e_j), the normal curvature of the
/// surface in direction e_i is kappa_ii. Same sign convention as above.
Eigen::Matrix2d CurvatureTensor(const SurfaceDerivatives& d, const Eigen::Vector3d& e1,
                                const Eigen::Vector3d& e2, bool flip = false);

}  // namespace robomach::polishing
