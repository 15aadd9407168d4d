#include "robomach/polishing/region_outline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include <polyclipping/clipper.hpp>

#include "robomach/polishing/face_trim.h"

namespace robomach::polishing {
namespace {

constexpr double kScale = 1e7;         // Clipper units per metre (0.1 um)
constexpr double kArcTolerance = 1e-5; // sag of the round joins' chords [m]
// On large offsets the sag grows with the distance (1e-4 of it, ~220 chords a
// full turn), so that a join never has more than a few hundred points: with
// 10 um at metres of offset (a 40 m face's Inradius bisection) Clipper made
// thousands of points per vertex and ran out of memory. Unchanged below 0.1 m.
double ArcTolerance(double distance) { return std::max(kArcTolerance, 1e-4 * std::abs(distance)); }

ClipperLib::Paths ToClipper(const std::vector<Polygon2>& loops) {
  ClipperLib::Paths out;
  for (const Polygon2& p : loops) {
    ClipperLib::Path q;
    q.reserve(p.size());
    for (const Eigen::Vector2d& x : p) {
      q.emplace_back(static_cast<ClipperLib::cInt>(std::llround(x.x() * kScale)),
                     static_cast<ClipperLib::cInt>(std::llround(x.y() * kScale)));
    }
    out.push_back(std::move(q));
  }
  return out;
}

std::vector<Polygon2> FromClipper(const ClipperLib::Paths& paths) {
  std::vector<Polygon2> out;
  for (const ClipperLib::Path& q : paths) {
    if (q.size() < 3) continue;
    Polygon2 p;
    p.reserve(q.size());
    for (const ClipperLib::IntPoint& x : q) p.emplace_back(x.X / kScale, x.Y / kScale);
    out.push_back(std::move(p));
  }
  return out;
}

// Normalised even-odd region: outer loops counter-clockwise, holes clockwise.
std::vector<Polygon2> Normalise(const std::vector<Polygon2>& loops) {
  ClipperLib::Paths out;
  ClipperLib::SimplifyPolygons(ToClipper(loops), out, ClipperLib::pftEvenOdd);
  return FromClipper(out);
}

DevelopedRegion BoundingRectangle(const SampleGrid& grid) {
  return DevelopedRegion::FromPolygons({{Eigen::Vector2d(grid.s_lo(), grid.t_lo()), Eigen::Vector2d(grid.s_hi(), grid.t_lo()),
                                         Eigen::Vector2d(grid.s_hi(), grid.t_hi()), Eigen::Vector2d(grid.s_lo(), grid.t_hi())}});
}

// Douglas-Peucker on a closed polygon: the points kept are within `tol` of
// every point dropped (split at the first point and the one farthest from it).
Polygon2 Simplify(const Polygon2& p, double tol) {
  const size_t n = p.size();
  if (n < 8) return p;
  size_t far = 0;
  for (size_t i = 1; i < n; ++i)
    if ((p[i] - p[0]).squaredNorm() > (p[far] - p[0]).squaredNorm()) far = i;
  std::vector<char> keep(n + 1, 0);
  keep[0] = keep[far] = keep[n] = 1;  // index n is p[0] again
  auto at = [&](size_t i) -> const Eigen::Vector2d& { return p[i % n]; };
  std::vector<std::pair<size_t, size_t>> stack = {{0, far}, {far, n}};
  while (!stack.empty()) {
    const auto [a, b] = stack.back();
    stack.pop_back();
    if (b <= a + 1) continue;
    const Eigen::Vector2d ab = at(b) - at(a);
    const double l2 = ab.squaredNorm();
    double worst = -1.0;
    size_t k = a;
    for (size_t i = a + 1; i < b; ++i) {
      const Eigen::Vector2d ap = at(i) - at(a);
      const double f = l2 > 0 ? std::clamp(ap.dot(ab) / l2, 0.0, 1.0) : 0.0;
      const double d = (ap - f * ab).squaredNorm();
      if (d > worst) worst = d, k = i;
    }
    if (worst > tol * tol) {
      keep[k] = 1;
      stack.push_back({a, k});
      stack.push_back({k, b});
    }
  }
  Polygon2 out;
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) out.push_back(p[i]);
  return out.size() >= 3 ? out : p;
}

}  // namespace

double SignedArea(const Polygon2& p) {
  double a = 0.0;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) a += p[j].x() * p[i].y() - p[i].x() * p[j].y();
  return 0.5 * a;
}

DevelopedRegion DevelopedRegion::FromPolygons(const std::vector<Polygon2>& loops) {
  DevelopedRegion r;
  r.loops_ = Normalise(loops);
  if (r.loops_.size() == 1) {
    const Eigen::Vector4d b = r.Bounds();
    const double box = (b(2) - b(0)) * (b(3) - b(1));
    r.rectangle_ = box > 0 && std::abs(r.Area() - box) <= 1e-6 * box;
  }
  return r;
}

DevelopedRegion DevelopedRegion::Build(const NurbsSurface& surface, const SampleGrid& grid, double margin) {
  const FaceTrim* trim = surface.trim();
  if (trim == nullptr || trim->wires_uv.empty()) return BoundingRectangle(grid);
  std::vector<Polygon2> face;
  for (const auto& wire : trim->wires_uv) {
    Polygon2 p;
    p.reserve(wire.size());
    for (const Eigen::Vector2d& uv : wire) p.emplace_back(grid.SOfU(uv.x()), grid.TOfV(uv.y()));
    face.push_back(std::move(p));
  }
  DevelopedRegion whole = FromPolygons(face);
  DevelopedRegion r;
  if (trim->edges_uv.empty()) {
    r = FromPolygons(whole.Offset(margin));
  } else {
    // The face minus a band of half-width `margin` about its material edges:
    // seams of closed surfaces and degenerate edges take no margin.
    std::vector<Polygon2> edges;
    for (const auto& e : trim->edges_uv) {
      Polygon2 p;
      for (const Eigen::Vector2d& uv : e) p.emplace_back(grid.SOfU(uv.x()), grid.TOfV(uv.y()));
      edges.push_back(std::move(p));
    }
    ClipperLib::Paths band;
    if (margin > 0) {
      ClipperLib::ClipperOffset co(2.0, ArcTolerance(margin) * kScale);
      co.AddPaths(ToClipper(edges), ClipperLib::jtRound, ClipperLib::etOpenRound);
      co.Execute(band, margin * kScale);
    }
    ClipperLib::Clipper c;
    c.AddPaths(ToClipper(whole.loops_), ClipperLib::ptSubject, true);
    c.AddPaths(band, ClipperLib::ptClip, true);
    ClipperLib::Paths out;
    c.Execute(ClipperLib::ctDifference, out, ClipperLib::pftEvenOdd, ClipperLib::pftNonZero);
    r = FromPolygons(FromClipper(out));
  }
  // A face trimmed to its patch's boundary: the grid's rectangle, as for a
  // plain patch (the same path as the patch's YAML copy).
  if (r.rectangle_) return BoundingRectangle(grid);
  return r;
}

double DevelopedRegion::Area() const {
  double a = 0.0;
  for (const Polygon2& p : loops_) a += SignedArea(p);
  return a;
}

Eigen::Vector4d DevelopedRegion::Bounds() const {
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::Vector4d b(inf, inf, -inf, -inf);
  for (const Polygon2& p : loops_)
    for (const Eigen::Vector2d& x : p) {
      b(0) = std::min(b(0), x.x());
      b(1) = std::min(b(1), x.y());
      b(2) = std::max(b(2), x.x());
      b(3) = std::max(b(3), x.y());
    }
  return b;
}

std::vector<Polygon2> DevelopedRegion::Offset(double distance) const {
  if (distance <= 0) return loops_;
  ClipperLib::ClipperOffset co(2.0, ArcTolerance(distance) * kScale);
  co.AddPaths(ToClipper(loops_), ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  ClipperLib::Paths out;
  co.Execute(out, -distance * kScale);
  return FromClipper(out);
}

double DevelopedRegion::Inradius() const {
  if (loops_.empty()) return 0.0;
  const Eigen::Vector4d b = Bounds();
  const double size = std::max(b(2) - b(0), b(3) - b(1));
  // The pole of inaccessibility by cell subdivision (Agafonkin's
  // "polylabel", Mapbox 2016): square cells with the distance at their
  // centre, split best bound first, a cell dropped once its bound (centre
  // distance + half diagonal) cannot beat the best by more than `tol`. The
  // loops are first simplified (Douglas-Peucker) to tol / 2. Unlike the
  // bisection on Clipper offsets used before, it stays bounded on large,
  // finely sampled outlines: an inward offset by metres of an outline of
  // thousands of points has millions of self-intersections (the 40 m faces
  // of a CAD file read in the wrong unit ran for minutes, out of memory).
  const double tol = std::max(1e-6, 1e-6 * size);
  DevelopedRegion simple;
  for (const Polygon2& p : loops_) simple.loops_.push_back(Simplify(p, 0.5 * tol));
  auto signed_distance = [&](const Eigen::Vector2d& x) {
    const double d = simple.DistanceToBoundary(x);
    return simple.Contains(x) ? d : -d;
  };
  struct Cell {
    Eigen::Vector2d c;
    double h, d, bound;
  };
  auto make = [&](const Eigen::Vector2d& c, double h) {
    const double d = signed_distance(c);
    return Cell{c, h, d, d + h * std::sqrt(2.0)};
  };
  auto lower = [](const Cell& x, const Cell& y) { return x.bound < y.bound; };
  std::priority_queue<Cell, std::vector<Cell>, decltype(lower)> queue(lower);
  const double w = b(2) - b(0), hgt = b(3) - b(1);
  const double cell = std::max(std::min(w, hgt), 1e-12);
  for (double x = b(0); x < b(2) + 1e-15; x += cell)
    for (double y = b(1); y < b(3) + 1e-15; y += cell) queue.push(make(Eigen::Vector2d(x + cell / 2, y + cell / 2), cell / 2));
  Cell best = make(Eigen::Vector2d((b(0) + b(2)) / 2, (b(1) + b(3)) / 2), 0.0);
  while (!queue.empty()) {
    const Cell c = queue.top();
    queue.pop();
    if (c.d > best.d) best = c;
    if (c.bound - best.d <= tol) continue;
    const double h = c.h / 2;
    for (int i = -1; i <= 1; i += 2)
      for (int j = -1; j <= 1; j += 2) queue.push(make(c.c + Eigen::Vector2d(i * h, j * h), h));
  }
  return std::max(0.0, best.d);
}

std::vector<std::pair<double, double>> DevelopedRegion::Intervals(double t) const {
  std::vector<double> s;
  for (const Polygon2& p : loops_) {
    for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
      const Eigen::Vector2d &a = p[j], &b = p[i];
      if ((a.y() <= t) != (b.y() <= t)) s.push_back(a.x() + (t - a.y()) / (b.y() - a.y()) * (b.x() - a.x()));
    }
  }
  std::sort(s.begin(), s.end());
  std::vector<std::pair<double, double>> out;
  for (size_t k = 0; k + 1 < s.size(); k += 2) {
    if (s[k + 1] > s[k]) out.emplace_back(s[k], s[k + 1]);
  }
  return out;
}

bool DevelopedRegion::Contains(const Eigen::Vector2d& st) const {
  bool in = false;
  for (const Polygon2& p : loops_) {
    for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
      const Eigen::Vector2d &a = p[j], &b = p[i];
      if ((a.y() <= st.y()) != (b.y() <= st.y()) &&
          st.x() < a.x() + (st.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x())) {
        in = !in;
      }
    }
  }
  return in;
}

double DevelopedRegion::DistanceToBoundary(const Eigen::Vector2d& st) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Polygon2& p : loops_) {
    for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
      const Eigen::Vector2d ab = p[i] - p[j];
      const double l2 = ab.squaredNorm();
      const double f = l2 > 0 ? std::clamp((st - p[j]).dot(ab) / l2, 0.0, 1.0) : 0.0;
      best = std::min(best, (st - p[j] - f * ab).norm());
    }
  }
  return best;
}

}  // namespace robomach::polishing
