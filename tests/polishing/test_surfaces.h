#pragma once

// Surfaces shared by the polishing tests, built from their textbook control
// nets (The NURBS Book §7.5 circle, §8.5 surface of revolution).

#include <cmath>
#include <memory>
#include <vector>

#include "robomach/polishing/face_trim.h"
#include "robomach/polishing/nurbs_surface.h"

namespace robomach::polishing::testing {

/// Full cylinder of radius R and height H about z: 9-point rational
/// quadratic circle in u, linear in v. Outward normal.
inline NurbsSurface Cylinder(double R, double H) {
  const double w = std::sqrt(0.5);
  const double cx[9] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
  const double cy[9] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
  std::vector<std::vector<Eigen::Vector3d>> P(9);
  std::vector<std::vector<double>> W(9);
  for (int i = 0; i < 9; ++i) {
    P[i] = {Eigen::Vector3d(R * cx[i], R * cy[i], 0.0), Eigen::Vector3d(R * cx[i], R * cy[i], H)};
    const double wi = (i % 2) ? w : 1.0;
    W[i] = {wi, wi};
  }
  return NurbsSurface::Create(2, 1, {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1}, {0, 0, 1, 1}, P, W);
}

/// An eighth of a sphere of radius R (x, y, z >= 0), biquadratic rational.
inline NurbsSurface SphereOctant(double R) {
  const double w = std::sqrt(0.5);
  // Meridian (in the xz plane) from the equator to the pole.
  const double mx[3] = {R, R, 0}, mz[3] = {0, R, R}, mw[3] = {1, w, 1};
  std::vector<std::vector<Eigen::Vector3d>> P(3);
  std::vector<std::vector<double>> W(3);
  for (int j = 0; j < 3; ++j) {      // around z: rows in u
    for (int i = 0; i < 3; ++i) {    // along the meridian: v
      const double x = mx[i];
      const Eigen::Vector3d p = j == 0 ? Eigen::Vector3d(x, 0, mz[i])
                              : j == 1 ? Eigen::Vector3d(x, x, mz[i])
                                       : Eigen::Vector3d(0, x, mz[i]);
      P[j].push_back(p);
      W[j].push_back(mw[i] * ((j == 1) ? w : 1.0));
    }
  }
  return NurbsSurface::Create(2, 2, {0, 0, 0, 1, 1, 1}, {0, 0, 0, 1, 1, 1}, P, W);
}

/// A flat rectangle [0, Lx] x [0, Ly] in z = 0 (bilinear).
inline NurbsSurface Plane(double Lx, double Ly) {
  return NurbsSurface::Create(1, 1, {0, 0, 1, 1}, {0, 0, 1, 1},
                              {{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, Ly, 0)},
                               {Eigen::Vector3d(Lx, 0, 0), Eigen::Vector3d(Lx, Ly, 0)}});
}

/// The formats.md §5 example (degree 3 x 2), in metres, with non-unit weights.
inline NurbsSurface DoublyCurved(bool unit_weights = false) {
  std::vector<std::vector<Eigen::Vector3d>> P = {
      {{0, 0, 0}, {0, 60, 4}, {0, 120, 0}},
      {{40, 0, 2}, {40, 60, 6}, {40, 120, 2}},
      {{80, 0, 2}, {80, 60, 6}, {80, 120, 2}},
      {{120, 0, 0}, {120, 60, 4}, {120, 120, 0}}};
  for (auto& row : P)
    for (auto& p : row) p *= 1e-3;
  std::vector<std::vector<double>> W;
  if (!unit_weights) W = {{1, 1.3, 1}, {0.8, 1.5, 1.1}, {1.2, 0.7, 1}, {1, 1.1, 0.9}};
  return NurbsSurface::Create(3, 2, {0, 0, 0, 0, 1, 1, 1, 1}, {0, 0, 0, 1, 1, 1}, P, W);
}

/// A 90 degree arc of a cylinder of radius R (axis along y, length L),
/// convex towards +z: config/polishing/cylinder_r60.yaml for R = 60 mm,
/// L = 120 mm.
inline NurbsSurface CylinderArc(double R, double L) {
  const double c = R * std::sqrt(0.5), w = std::sqrt(0.5);
  return NurbsSurface::Create(2, 1, {0, 0, 0, 1, 1, 1}, {0, 0, 1, 1},
                              {{Eigen::Vector3d(-c, 0, c), Eigen::Vector3d(-c, L, c)},
                               {Eigen::Vector3d(0, 0, 2 * c), Eigen::Vector3d(0, L, 2 * c)},
                               {Eigen::Vector3d(c, 0, c), Eigen::Vector3d(c, L, c)}},
                              {{1, 1}, {w, w}, {1, 1}});
}

/// A biquadratic dome Lx x Ly bulging 2 h towards +z (edges' middles at h):
/// config/polishing/dome.yaml for 100 x 80 mm, h = 10 mm.
inline NurbsSurface Dome(double Lx, double Ly, double h) {
  std::vector<std::vector<Eigen::Vector3d>> P(3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      P[i].push_back(Eigen::Vector3d(0.5 * Lx * i, 0.5 * Ly * j, h * ((i == 1) + (j == 1))));
  return NurbsSurface::Create(2, 2, {0, 0, 0, 1, 1, 1}, {0, 0, 0, 1, 1, 1}, P);
}

/// A trimmed face made here, not by the CAD reader: the plate
/// [0, Lx] x [0, Ly] in z = 0 with a circular hole of radius `hole_r` at
/// (cx, cy), as a FaceTrim with an analytic inside test, the boundary as
/// 3-D polylines (0.25 mm chords) and the wires in (u, v) = (x / Lx, y / Ly).
inline NurbsSurface PlateWithHole(double Lx, double Ly, double cx, double cy, double hole_r) {
  auto trim = std::make_shared<FaceTrim>();
  trim->contains = [=](double u, double v) { return std::hypot(u * Lx - cx, v * Ly - cy) >= hole_r; };
  const std::vector<Eigen::Vector3d> corners = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(Lx, 0, 0),
                                                Eigen::Vector3d(Lx, Ly, 0), Eigen::Vector3d(0, Ly, 0)};
  std::vector<Eigen::Vector2d> outer, hole;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d &a = corners[k], &b = corners[(k + 1) % 4];
    const int n = static_cast<int>(std::ceil((b - a).norm() / 0.25e-3));
    std::vector<Eigen::Vector3d> line;
    for (int i = 0; i <= n; ++i) line.push_back(a + (b - a) * (double(i) / n));
    trim->boundary.push_back(line);
    for (int i = 0; i < n; ++i) outer.emplace_back(line[i].x() / Lx, line[i].y() / Ly);
  }
  const int n = static_cast<int>(std::ceil(2 * M_PI * hole_r / 0.25e-3));
  std::vector<Eigen::Vector3d> circle;
  for (int i = 0; i <= n; ++i) {
    const double a = -2 * M_PI * i / n;  // clockwise: a hole
    circle.emplace_back(cx + hole_r * std::cos(a), cy + hole_r * std::sin(a), 0.0);
    if (i < n) hole.emplace_back(circle.back().x() / Lx, circle.back().y() / Ly);
  }
  trim->boundary.push_back(circle);
  trim->wires_uv = {outer, hole};
  trim->boundary_chord = 0.25e-3;
  trim->area = Lx * Ly - M_PI * hole_r * hole_r;
  trim->num_wires = 2;
  trim->source = "test plate with a hole";
  return Plane(Lx, Ly).WithTrim(trim);
}

}  // namespace robomach::polishing::testing
