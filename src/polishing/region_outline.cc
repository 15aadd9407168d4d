#include "robomach/polishing/region_outline.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <polyclipping/clipper.hpp>

#include "robomach/polishing/face_trim.h"

namespace robomach::polishing {
namespace {

constexpr double kScale = 1e7;         // Clipper units per metre (0.1 um)
constexpr double kArcTolerance = 1e-5; // sag of the round joins' chords [m]

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
      ClipperLib::ClipperOffset co(2.0, kArcTolerance * kScale);
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
  ClipperLib::ClipperOffset co(2.0, kArcTolerance * kScale);
  co.AddPaths(ToClipper(loops_), ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  ClipperLib::Paths out;
  co.Execute(out, -distance * kScale);
  return FromClipper(out);
}

double DevelopedRegion::Inradius() const {
  if (loops_.empty()) return 0.0;
  const Eigen::Vector4d b = Bounds();
  double lo = 0.0, hi = 0.5 * std::min(b(2) - b(0), b(3) - b(1)) + 1e-6;
  while (hi - lo > 1e-6) {
    const double mid = 0.5 * (lo + hi);
    (Offset(mid).empty() ? hi : lo) = mid;
  }
  return lo;
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
