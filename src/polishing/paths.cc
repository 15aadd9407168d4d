#include "robomach/polishing/paths.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "robomach/common/units.h"

namespace robomach::polishing {
namespace {

using Vec2 = Eigen::Vector2d;

// A polyline guide in the developed plane, parametrised by arc length.
struct Guide {
  std::vector<Vec2> pts;
  std::vector<double> cum;  // cumulative length at each point
  explicit Guide(std::vector<Vec2> p) : pts(std::move(p)) {
    cum.assign(pts.size(), 0.0);
    for (size_t i = 1; i < pts.size(); ++i) cum[i] = cum[i - 1] + (pts[i] - pts[i - 1]).norm();
  }
  double length() const { return cum.back(); }
  size_t Segment(double s) const {
    size_t k = std::upper_bound(cum.begin(), cum.end(), s) - cum.begin();
    return std::clamp<size_t>(k, 1, pts.size() - 1);
  }
  Vec2 At(double s) const {
    if (pts.size() == 1) return pts[0];
    const size_t k = Segment(s);
    const double len = cum[k] - cum[k - 1];
    const double f = len > 0 ? std::clamp((s - cum[k - 1]) / len, 0.0, 1.0) : 0.0;
    return pts[k - 1] + f * (pts[k] - pts[k - 1]);
  }
  Vec2 Tangent(double s) const {
    if (pts.size() == 1) return Vec2(1, 0);
    size_t k = Segment(s);
    while (k + 1 < pts.size() && cum[k] - cum[k - 1] <= 0) ++k;
    const Vec2 d = pts[k] - pts[k - 1];
    return d.norm() > 0 ? Vec2(d.normalized()) : Vec2(1, 0);
  }
};

class Mapper {
 public:
  Mapper(const NurbsSurface& s, const SampleGrid& g, bool flip) : s_(s), g_(g), flip_(flip) {}
  PathRow Row(const Vec2& st, const Vec2& tangent) const {
    const double sc = std::clamp(st.x(), 0.0, g_.length_s()), tc = std::clamp(st.y(), 0.0, g_.length_t());
    PathRow r;
    r.u = g_.UOfS(sc);
    r.v = g_.VOfT(tc);
    const SurfaceDerivatives d = s_.Evaluate(r.u, r.v);
    r.p = d.S;
    r.n = UnitNormal(d, flip_);
    Eigen::Vector3d x = d.S_u * g_.DuDs(sc) * tangent.x() + d.S_v * g_.DvDt(tc) * tangent.y();
    x -= x.dot(r.n) * r.n;
    r.tx = x.normalized();
    return r;
  }
  Eigen::Vector3d Point(const Vec2& st) const {
    return s_.Point(g_.UOfS(std::clamp(st.x(), 0.0, g_.length_s())), g_.VOfT(std::clamp(st.y(), 0.0, g_.length_t())));
  }

 private:
  const NurbsSurface& s_;
  const SampleGrid& g_;
  bool flip_;
};

// Appends rows along a straight developed move at `speed` (nominal time).
void StraightMove(const Mapper& m, const Vec2& a, const Vec2& b, const Vec2& tangent, double speed, double step,
                  bool include_start, std::vector<PathRow>* rows, std::vector<double>* t) {
  const double len = (b - a).norm();
  if (len < 1e-12 && !include_start && !rows->empty()) return;
  const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
  for (int i = include_start ? 0 : 1; i <= n; ++i) {
    const double f = double(i) / n;
    rows->push_back(m.Row(a + f * (b - a), tangent));
    const double t0 = t->empty() ? 0.0 : t->back();
    t->push_back(t->empty() ? 0.0 : t0 + (len / n) / speed);
  }
}

std::vector<Vec2> Rectangle(double s0, double t0, double s1, double t1) {
  return {Vec2(s0, t0), Vec2(s1, t0), Vec2(s1, t1), Vec2(s0, t1), Vec2(s0, t0)};
}

}  // namespace

void CheckValid(const PathParameters& p) {
  auto fail = [](const std::string& m) { throw std::invalid_argument(m); };
  auto mm = [](double x) {
    std::ostringstream s;
    s << x * 1e3;
    return s.str();
  };
  if (!(p.offset > 0) || !std::isfinite(p.offset)) fail("offset_mm: expected > 0, got " + mm(p.offset));
  if (!(p.row_step > 0)) fail("row step must be > 0");
  if (p.pattern == Pattern::kParallel) return;
  if (!(p.radius > 0)) fail("radius_mm: expected > 0, got " + mm(p.radius));
  if (!(p.pitch > 0)) fail("pitch_mm: expected > 0, got " + mm(p.pitch));
  if (p.offset > 2 * p.radius * (1 + 1e-12)) {
    fail("offset_mm " + mm(p.offset) + " > 2 x radius_mm " + mm(p.radius) +
         ": adjacent cycloid rows would leave an unpolished strip (seed 004 §3.1, d <= 2r)");
  }
  if (p.pitch >= 2 * kPi * p.radius) {
    fail("pitch_mm " + mm(p.pitch) + " >= 2 pi radius_mm: the centre outruns the rolling point and the cycloid "
         "no longer loops (seed 004 §3.2, v < omega r)");
  }
}

PlannedPath PlanPath(const NurbsSurface& surface, const SampleGrid& grid, const PathParameters& params,
                     const PolishingProcess& process) {
  CheckValid(params);
  const Mapper m(surface, grid, process.flip_normal);
  const double s_lo = grid.s_lo(), s_hi = grid.s_hi(), t_lo = grid.t_lo(), t_hi = grid.t_hi();
  if (!(s_hi >= s_lo) || !(t_hi >= t_lo)) throw std::invalid_argument("the polished region is empty (margin too large for the patch)");
  const double W = s_hi - s_lo, H = t_hi - t_lo;
  const double d = params.offset, r = params.radius, pitch = params.pitch;
  const double vmax = process.max_speed;

  // Guide lines, in order, with the direction sense of the cycloid.
  std::vector<Guide> guides;
  std::vector<int> sense;
  const bool cyc = params.pattern == Pattern::kCycloid;
  std::vector<bool> closed;
  if (cyc && params.guides == GuideLines::kBoundaryOffsets) {
    // n closed loops at insets e + k de and a centre line (the innermost
    // loop collapsed) at half the short side, de = (half_min - e) / n <= d:
    // every pair of adjacent guide lines, the centre line included, is the
    // same distance apart (a leftover strip narrower or wider than d would
    // be over- or under-polished along the whole centre).
    // The outermost loop runs on the region boundary (e = 0) so that the
    // rolling circle overruns the edge as a belt grinder does; if the
    // margin is narrower than r, it moves in by r - margin so that the
    // circle stays on the face. With the loop half a spacing inside (the
    // layout before), no row outside the edge feeds the outer strip and
    // the boundary band was the largest source of non-uniformity (README).
    const double half_min = std::min(W, H) / 2;
    const double e = std::min(half_min, params.edge_inset >= 0 ? params.edge_inset
                                                                : std::max(0.0, r - process.margin));
    const int n = std::max(1, static_cast<int>(std::ceil((half_min - e) / d - 1e-9)));
    const double de = (half_min - e) / n;
    for (int k = 0; k < n; ++k) {
      const double inset = e + k * de;
      // Start each loop in the middle of its lower side, not at a corner:
      // the loops close seamlessly (below), and the transition to the next
      // loop is a short move across, away from the corners.
      const double s0 = s_lo + inset, t0 = t_lo + inset, s1 = s_hi - inset, t1 = t_hi - inset;
      const double sm = (s0 + s1) / 2;
      guides.emplace_back(std::vector<Vec2>{Vec2(sm, t0), Vec2(s1, t0), Vec2(s1, t1), Vec2(s0, t1), Vec2(s0, t0),
                                            Vec2(sm, t0)});
      sense.push_back(1);
      closed.push_back(true);
    }
    const double sc = (s_lo + s_hi) / 2, tc = (t_lo + t_hi) / 2;
    if (W >= H) guides.emplace_back(std::vector<Vec2>{Vec2(s_lo + half_min, tc), Vec2(s_hi - half_min, tc)});
    else guides.emplace_back(std::vector<Vec2>{Vec2(sc, t_lo + half_min), Vec2(sc, t_hi - half_min)});
    sense.push_back(1);
    closed.push_back(false);
  } else {
    // Parallel lines along s, centred in the region, boustrophedon.
    const int n = std::max(1, static_cast<int>(std::ceil(H / d - 1e-9)));
    const double first = t_lo + (H - (n - 1) * d) / 2;
    for (int k = 0; k < n; ++k) {
      const double tk = first + k * d;
      if (k % 2 == 0) guides.emplace_back(std::vector<Vec2>{Vec2(s_lo, tk), Vec2(s_hi, tk)});
      else guides.emplace_back(std::vector<Vec2>{Vec2(s_hi, tk), Vec2(s_lo, tk)});
      // Mirror the rolling sense on reversed rows so that the dense side of
      // every row (where the rolling point runs backwards) faces +t and meets
      // the sparse side of the next row (seed §3.1, Fig. 11).
      sense.push_back(k % 2 == 0 ? 1 : -1);
      closed.push_back(false);
    }
  }
  // Tool x along the guide line (seed eq. 16) with one sign for all the
  // parallel lines: the belt keeps running the same way and the wrist does
  // not turn half a revolution at every row end.
  const bool parallel_lines = !(cyc && params.guides == GuideLines::kBoundaryOffsets);
  auto tool_dir = [&](const Vec2& tangent) {
    return (parallel_lines && tangent.x() < 0) ? Vec2(-tangent) : tangent;
  };

  PlannedPath out;
  std::vector<double> t;
  Vec2 last_st(0, 0);
  const double omega0 = cyc ? vmax / (r + pitch / (2 * kPi)) : 0.0;  // nominal rolling rate
  for (size_t g = 0; g < guides.size(); ++g) {
    const Guide& guide = guides[g];
    std::vector<Eigen::Vector3d> line;
    for (const Vec2& p : guide.pts) line.push_back(m.Point(p));
    out.guide_lines.push_back(line);
    if (!cyc) {
      const Vec2 dir = tool_dir(guide.Tangent(0.0));
      if (!out.rows.empty()) StraightMove(m, last_st, guide.pts.front(), dir, vmax, params.row_step, false, &out.rows, &t);
      StraightMove(m, guide.pts.front(), guide.pts.back(), dir, vmax, params.row_step, out.rows.empty(), &out.rows, &t);
      last_st = guide.pts.back();
      continue;
    }
    // Cycloid (seed eq. 11): x = xc + r cos(omega t + theta), y = yc + r sin(...),
    // the centre advancing `pitch` per loop; rows staggered by half a loop.
    const double theta = kPi * static_cast<double>(g);
    const double L = guide.length();
    // On a closed guide a whole number of loops (the pitch adjusted by at
    // most half a loop over the guide's length) closes the cycloid on
    // itself: no dense head and tail where it starts and ends.
    const double loops = closed[g] ? std::max(1.0, std::round(L / pitch)) : std::max(1.0, L / pitch);
    const double pitch_g = L > 0 ? L / loops : pitch;
    const double phi_end = 2 * kPi * loops;
    const double dphi = std::min(0.5, params.row_step / (r + pitch / (2 * kPi)));
    const int n = std::max(1, static_cast<int>(std::ceil(phi_end / dphi)));
    auto point = [&](double phi) {
      const double sigma = pitch_g * phi / (2 * kPi);
      const double ang = sense[g] * phi + theta;
      return Vec2(guide.At(sigma) + r * Vec2(std::cos(ang), std::sin(ang)));
    };
    for (int i = 0; i <= n; ++i) {
      const double phi = phi_end * i / n;
      const Vec2 st = point(phi);
      const Vec2 tan = tool_dir(guide.Tangent(pitch_g * phi / (2 * kPi)));
      if (i == 0) {
        if (out.rows.empty()) {
          out.rows.push_back(m.Row(st, tan));
          t.push_back(0.0);
        } else {
          // Transition from the end of the previous row, on the surface.
          StraightMove(m, last_st, st, tan, vmax, params.row_step, false, &out.rows, &t);
        }
      } else {
        out.rows.push_back(m.Row(st, tan));
        t.push_back(t.back() + (phi_end / n) / omega0);
      }
      last_st = st;
    }
  }
  // Enforce the speed limit on the mapped 3-D path (the developed plane
  // distorts lengths on doubly curved patches).
  for (size_t i = 0; i < out.rows.size(); ++i) out.rows[i].t = t[i];
  out.omega_rad_per_s = omega0;
  out.centre_speed = cyc ? pitch * omega0 / (2 * kPi) : 0.0;
  const double vm = MaxSpeed(out.rows);
  if (vm > vmax) ScaleTime(&out, vm / vmax);
  out.length = 0.0;
  for (size_t i = 1; i < out.rows.size(); ++i) out.length += (out.rows[i].p - out.rows[i - 1].p).norm();
  return out;
}

void ScaleTime(PlannedPath* path, double factor) {
  for (auto& r : path->rows) r.t *= factor;
  path->omega_rad_per_s /= factor;
  path->centre_speed /= factor;
}

double MaxSpeed(const std::vector<PathRow>& rows) {
  double v = 0.0;
  for (size_t i = 1; i < rows.size(); ++i) v = std::max(v, (rows[i].p - rows[i - 1].p).norm() / (rows[i].t - rows[i - 1].t));
  return v;
}

double ContactWidthAtCentre(const NurbsSurface& surface, const SampleGrid& grid, const PolishingProcess& process) {
  const Mapper m(surface, grid, process.flip_normal);
  const PathRow r = m.Row(Vec2((grid.s_lo() + grid.s_hi()) / 2, (grid.t_lo() + grid.t_hi()) / 2), Vec2(1, 0));
  const ToolContact c = ContactAt(surface.Evaluate(r.u, r.v), r.tx, process, process.force);
  const Eigen::Vector3d ty = c.n.cross(r.tx);
  return 2.0 * std::hypot(c.a * c.e_a.dot(ty), c.b * c.e_b.dot(ty));
}

TargetResult ScaleToTargetRemoval(const RemovalSimulator& sim, const SampleGrid& grid, double target,
                                  double max_speed, PlannedPath* path) {
  TargetResult res;
  const std::vector<ToolContact> contacts = sim.Contacts(path->rows);
  for (int it = 0; it < 6; ++it) {
    res.removal = sim.Simulate(path->rows, contacts);
    res.mean = ComputeRemovalStats(res.removal, grid.areas(), grid.in_region()).mean;
    if (!(res.mean > 0)) {
      res.message = "the path removes nothing in the polished region";
      return res;
    }
    const double f = target / res.mean;
    if (std::abs(f - 1.0) < 1e-6) break;
    ScaleTime(path, f);
  }
  res.reached = true;
  const double vm = MaxSpeed(path->rows);
  if (vm > max_speed * (1 + 1e-9)) {
    ScaleTime(path, vm / max_speed);
    res.removal = sim.Simulate(path->rows, contacts);
    res.mean = ComputeRemovalStats(res.removal, grid.areas(), grid.in_region()).mean;
    std::ostringstream msg;
    msg << "the target removal needs a traverse speed of " << vm * 1e3 << " mm/s, above max_speed_mm_per_s "
        << max_speed * 1e3 << "; the path runs at the limit and removes " << res.mean * 1e6 << " um on average";
    res.message = msg.str();
    res.reached = false;
  }
  return res;
}

void AttachToSurface(const NurbsSurface& surface, const SampleGrid& grid, bool flip_normal, std::vector<PathRow>* rows) {
  double u = std::nan(""), v = std::nan("");
  auto nearest_node = [&](const Eigen::Vector3d& x, double* uu, double* vv) {
    double best = 1e300;
    for (int j = 0; j < grid.nt(); ++j)
      for (int i = 0; i < grid.ns(); ++i) {
        const double dd = (grid.points()[grid.index(i, j)] - x).squaredNorm();
        if (dd < best) best = dd, *uu = grid.u(i), *vv = grid.v(j);
      }
  };
  constexpr double kTol = 1e-5;  // formats.md §6: 0.01 mm
  for (size_t r = 0; r < rows->size(); ++r) {
    PathRow& row = (*rows)[r];
    double uu = std::isfinite(row.u) ? row.u : u, vv = std::isfinite(row.v) ? row.v : v;
    if (!std::isfinite(uu) || !std::isfinite(vv)) nearest_node(row.p, &uu, &vv);
    double dist = ProjectToSurface(surface, row.p, &uu, &vv);
    if (dist > kTol) {
      nearest_node(row.p, &uu, &vv);
      dist = ProjectToSurface(surface, row.p, &uu, &vv);
    }
    if (dist > kTol) {
      std::ostringstream m;
      m << "the point (" << row.p.x() * 1e3 << ", " << row.p.y() * 1e3 << ", " << row.p.z() * 1e3 << ") mm is "
        << dist * 1e3 << " mm off the surface (tolerance 0.01 mm)";
      throw PathRowError(static_cast<int>(r), m.str());
    }
    if (!surface.OnFace(uu, vv)) {
      std::ostringstream m;
      m << "the point (" << row.p.x() * 1e3 << ", " << row.p.y() * 1e3 << ", " << row.p.z() * 1e3
        << ") mm is off the trimmed face (outside its boundary or in a hole"
        << (surface.trim()->source.empty() ? "" : " of " + surface.trim()->source) << ")";
      throw PathRowError(static_cast<int>(r), m.str());
    }
    const SurfaceDerivatives d = surface.Evaluate(uu, vv);
    const Eigen::Vector3d n = UnitNormal(d, flip_normal);
    if (row.n.dot(n) <= 0.0) {
      throw PathRowError(static_cast<int>(r), "the tool axis (nx,ny,nz) points into the surface (the surface normal "
                                              "is the other way); set process.flip_normal if the tool side is right");
    }
    row.u = uu;
    row.v = vv;
    u = uu;
    v = vv;
  }
}

}  // namespace robomach::polishing
