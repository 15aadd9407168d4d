#include "robomach/polishing/paths.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "robomach/common/enum_names.h"
#include "robomach/common/units.h"
#include "robomach/polishing/face_check.h"
#include "robomach/polishing/path_patterns.h"
#include "robomach/polishing/region_outline.h"

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

}  // namespace

namespace {

std::string Mm(double x) {
  std::ostringstream s;
  s << x * 1e3;
  return s.str();
}

}  // namespace

double MaxEdgeOverrun(const PathParameters& p, const PolishingProcess& process) {
  return PathPatternOf(p.pattern).MaxEdgeOverrun(p, process);
}

void CheckValid(const PathParameters& p) {
  auto fail = [](const std::string& m) { throw std::invalid_argument(m); };
  if (!(p.offset > 0) || !std::isfinite(p.offset)) fail("offset_mm: expected > 0, got " + Mm(p.offset));
  if (!(p.row_step > 0)) fail("row step must be > 0");
  if (!std::isfinite(p.line_angle)) fail("line angle: expected a finite number of radians");
  PathPatternOf(p.pattern).CheckValid(p);
}

namespace {

struct GuideSpec {
  Guide guide;
  int sense;    // +1: the rolling point turns counter-clockwise in (s, t)
  bool closed;  // a closed loop (whole number of cycloid loops)
};

// The guide lines of a rectangular region (a plain patch): n closed loops at
// insets e + k de and a centre line (the innermost loop collapsed) at half
// the short side, or parallel lines along s.
std::vector<GuideSpec> RectangleGuides(const SampleGrid& grid, const PathParameters& params,
                                       const PolishingProcess& process) {
  const double s_lo = grid.s_lo(), s_hi = grid.s_hi(), t_lo = grid.t_lo(), t_hi = grid.t_hi();
  const double W = s_hi - s_lo, H = t_hi - t_lo;
  const double d = params.offset, r = params.radius;
  std::vector<GuideSpec> guides;
  if (params.pattern == Pattern::kCycloid && params.guides == GuideLines::kBoundaryOffsets) {
    // de = (half_min - e) / n <= d: every pair of adjacent guide lines, the
    // centre line included, is the same distance apart (a leftover strip
    // narrower or wider than d would be over- or under-polished along the
    // whole centre).
    // The outermost loop runs on the region boundary (e = 0) so that the
    // rolling circle overruns the edge as a belt grinder does; if the
    // margin is narrower than r, it moves in by r - margin so that the
    // circle stays on the face. With the loop half a spacing inside (the
    // layout before), no row outside the edge feeds the outer strip and
    // the boundary band was the largest source of non-uniformity (README).
    const double half_min = std::min(W, H) / 2;
    const double e = std::min(half_min, params.edge_inset >= 0 ? params.edge_inset
                                        : r >= process.margin ? r - process.margin
                                                              : -std::min(std::max(0.0, params.edge_overrun),
                                                                          MaxEdgeOverrun(params, process)));
    const int n = std::max(1, static_cast<int>(std::ceil((half_min - e) / d - 1e-9)));
    const double de = (half_min - e) / n;
    for (int k = 0; k < n; ++k) {
      const double inset = e + k * de;
      // Start each loop in the middle of its lower side, not at a corner:
      // the loops close seamlessly (below), and the transition to the next
      // loop is a short move across, away from the corners.
      const double s0 = s_lo + inset, t0 = t_lo + inset, s1 = s_hi - inset, t1 = t_hi - inset;
      const double sm = (s0 + s1) / 2;
      guides.push_back({Guide({Vec2(sm, t0), Vec2(s1, t0), Vec2(s1, t1), Vec2(s0, t1), Vec2(s0, t0), Vec2(sm, t0)}),
                        1, true});
    }
    const double sc = (s_lo + s_hi) / 2, tc = (t_lo + t_hi) / 2;
    if (W >= H) guides.push_back({Guide({Vec2(s_lo + half_min, tc), Vec2(s_hi - half_min, tc)}), 1, false});
    else guides.push_back({Guide({Vec2(sc, t_lo + half_min), Vec2(sc, t_hi - half_min)}), 1, false});
    return guides;
  }
  // Parallel lines along s, centred in the region, boustrophedon.
  const int n = std::max(1, static_cast<int>(std::ceil(H / d - 1e-9)));
  const double first = t_lo + (H - (n - 1) * d) / 2;
  for (int k = 0; k < n; ++k) {
    const double tk = first + k * d;
    // Mirror the rolling sense on reversed rows so that the dense side of
    // every row (where the rolling point runs backwards) faces +t and meets
    // the sparse side of the next row (seed §3.1, Fig. 11).
    if (k % 2 == 0) guides.push_back({Guide({Vec2(s_lo, tk), Vec2(s_hi, tk)}), 1, false});
    else guides.push_back({Guide({Vec2(s_hi, tk), Vec2(s_lo, tk)}), -1, false});
  }
  return guides;
}

// Inserts points so that no edge of the closed polygon is longer than `step`.
Polygon2 Densify(const Polygon2& p, double step) {
  Polygon2 out;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2 &a = p[i], &b = p[(i + 1) % p.size()];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 0; k < n; ++k) out.push_back(a + (double(k) / n) * (b - a));
  }
  return out;
}

// How far inside the region the cycloid's guide lines must stay so that the
// circle stays on the face: r - margin, plus kClearance for the chords of the
// face's outline (sag < 1 um) and of the offsets' round joins (sag 10 um),
// which cut slightly into holes. --edge-inset-mm overrides it.
double CycloidInset(const PathParameters& params, const PolishingProcess& process) {
  constexpr double kClearance = 50e-6;
  return params.edge_inset >= 0 ? params.edge_inset : std::max(0.0, params.radius - process.margin) + kClearance;
}

[[noreturn]] void RegionTooNarrow(double inradius, double inset, const PathParameters& params) {
  std::ostringstream m;
  m << "radius_mm " << params.radius * 1e3 << ": the cycloid does not fit the polished region; its guide lines "
    << "must stay " << inset * 1e3 << " mm inside it (r - margin_mm) so that the circle stays on the face, and "
    << "the region's widest spot is " << 2e3 * inradius << " mm across; use a smaller radius";
  throw std::invalid_argument(m.str());
}

// Guide loops of a region that is not a rectangle (a trimmed face, holes):
// the equidistant inward offsets of its boundary at e + k de, k = 0 .. n-1,
// the last at half a spacing from the inscribed circle's centre, so that the
// two innermost loops of a strip between two boundaries are one spacing
// apart (the rectangle's centre line has no general counterpart). The loops
// are visited nearest first, each starting at its point nearest to where the
// previous one ended.
std::vector<GuideSpec> OffsetGuides(const DevelopedRegion& region, const PathParameters& params,
                                    const PolishingProcess& process) {
  const double d = params.offset;
  const double R = region.Inradius();
  const double e = CycloidInset(params, process);
  if (!(R > e)) RegionTooNarrow(R, e, params);
  const int n = std::max(1, static_cast<int>(std::ceil((R - e) / d + 0.5 - 1e-9)));
  const double de = (R - e) / (n - 0.5);
  std::vector<Polygon2> loops;
  for (int k = 0; k < n; ++k) {
    for (const Polygon2& p : region.Offset(e + k * de)) loops.push_back(Densify(p, std::max(d / 4, 1e-4)));
  }
  std::vector<GuideSpec> guides;
  std::vector<bool> done(loops.size(), false);
  // Start on the largest loop of the outermost level, at its lowest point.
  size_t cur = 0;
  Vec2 pos(0, 0);
  {
    double best = -1;
    for (size_t i = 0; i < loops.size(); ++i) {
      const double a = std::abs(SignedArea(loops[i]));
      if (a > best) best = a, cur = i;
    }
    pos = loops[cur][0];
    for (const Vec2& x : loops[cur]) {
      if (x.y() < pos.y() || (x.y() == pos.y() && x.x() < pos.x())) pos = x;
    }
  }
  for (size_t visited = 0; visited < loops.size(); ++visited) {
    if (visited > 0) {
      double best = 1e300;
      for (size_t i = 0; i < loops.size(); ++i) {
        if (done[i]) continue;
        for (const Vec2& x : loops[i]) {
          const double dd = (x - pos).squaredNorm();
          if (dd < best) best = dd, cur = i;
        }
      }
    }
    const Polygon2& p = loops[cur];
    size_t k0 = 0;
    for (size_t k = 1; k < p.size(); ++k) {
      if ((p[k] - pos).squaredNorm() < (p[k0] - pos).squaredNorm()) k0 = k;
    }
    std::vector<Vec2> pts;
    for (size_t k = 0; k <= p.size(); ++k) pts.push_back(p[(k0 + k) % p.size()]);
    pos = pts.back();
    done[cur] = true;
    guides.push_back({Guide(std::move(pts)), 1, true});
  }
  return guides;
}

// Parallel lines along s clipped to a region that is not a rectangle. The
// pieces are grouped into cells (consecutive lines whose pieces overlap one
// to one, a boustrophedon decomposition around holes and notches); each
// cell is run back and forth, the cells nearest first.
std::vector<GuideSpec> LineGuides(const DevelopedRegion& region, const PathParameters& params) {
  const Eigen::Vector4d b = region.Bounds();
  const double d = params.offset, H = b(3) - b(1);
  const int n = std::max(1, static_cast<int>(std::ceil(H / d - 1e-9)));
  const double first = b(1) + (H - (n - 1) * d) / 2;
  struct Piece {
    double t, s0, s1;
  };
  std::vector<std::vector<Piece>> cells;
  std::vector<std::pair<double, double>> prev;
  std::vector<int> prev_cell;
  for (int k = 0; k < n; ++k) {
    const double tk = first + k * d;
    const auto iv = region.Intervals(tk);
    std::vector<int> cell_of(iv.size(), -1);
    auto overlaps = [](const std::pair<double, double>& x, const std::pair<double, double>& y) {
      return x.first < y.second && y.first < x.second;
    };
    for (size_t i = 0; i < iv.size(); ++i) {
      int count = 0, j_hit = -1;
      for (size_t j = 0; j < prev.size(); ++j)
        if (overlaps(iv[i], prev[j])) ++count, j_hit = static_cast<int>(j);
      if (count == 1) {
        int back = 0;
        for (const auto& x : iv) back += overlaps(x, prev[j_hit]);
        if (back == 1) cell_of[i] = prev_cell[j_hit];
      }
      if (cell_of[i] < 0) {
        cell_of[i] = static_cast<int>(cells.size());
        cells.emplace_back();
      }
      cells[cell_of[i]].push_back({tk, iv[i].first, iv[i].second});
    }
    prev = iv;
    prev_cell = cell_of;
  }
  std::vector<GuideSpec> guides;
  std::vector<bool> done(cells.size(), false);
  Vec2 pos(b(0), b(1));
  for (size_t visited = 0; visited < cells.size(); ++visited) {
    // The nearest cell end: bottom or top line, left or right end.
    double best = 1e300;
    size_t c_best = 0;
    bool from_top = false, from_right = false;
    for (size_t c = 0; c < cells.size(); ++c) {
      if (done[c]) continue;
      for (int top = 0; top < 2; ++top) {
        const Piece& pc = top ? cells[c].back() : cells[c].front();
        for (int right = 0; right < 2; ++right) {
          const double dd = (Vec2(right ? pc.s1 : pc.s0, pc.t) - pos).squaredNorm();
          if (dd < best - 1e-18) best = dd, c_best = c, from_top = top, from_right = right;
        }
      }
    }
    done[c_best] = true;
    std::vector<Piece> pieces = cells[c_best];
    if (from_top) std::reverse(pieces.begin(), pieces.end());
    bool right_to_left = from_right;
    for (const Piece& pc : pieces) {
      const Vec2 a(right_to_left ? pc.s1 : pc.s0, pc.t), z(right_to_left ? pc.s0 : pc.s1, pc.t);
      guides.push_back({Guide({a, z}), right_to_left ? -1 : 1, false});
      pos = z;
      right_to_left = !right_to_left;
    }
  }
  return guides;
}

constexpr double kLiftTime = 1e-3;  // [s] to lift the tool off or set it down

// Links the end of the path to `to`: a straight move on the surface if it is
// at most `max_length` long and every row of it is on the face, else the
// tool is lifted (rows with force 0: it leaves the surface at the last row,
// travels to `to` and sets down there). A long move in contact would polish
// a stripe across the region. Returns true for a lift.
bool Link(const Mapper& m, const NurbsSurface& surface, const Vec2& from, const Vec2& to, const Vec2& tangent,
          double speed, double step, double max_length, std::vector<PathRow>* rows, std::vector<double>* t) {
  if ((to - from).norm() < 1e-12) return false;  // already there
  std::vector<PathRow> move;
  std::vector<double> tm{t->back()};
  StraightMove(m, from, to, tangent, speed, step, false, &move, &tm);
  const bool in_contact = (to - from).norm() <= max_length &&
                          std::all_of(move.begin(), move.end(), [&](const PathRow& r) { return surface.OnFace(r.u, r.v); });
  if (in_contact) {
    rows->insert(rows->end(), move.begin(), move.end());
    t->insert(t->end(), tm.begin() + 1, tm.end());
    return false;
  }
  // Lifted, the tool follows the surface (rows every `step`, as a move in
  // contact would), so that the air move does not cut through a convex part
  // as one long chord would, and the robot sees small steps.
  PathRow up = rows->back();
  up.force = 0.0;
  rows->push_back(up);
  t->push_back(t->back() + kLiftTime);
  for (size_t k = 0; k < move.size(); ++k) {
    move[k].force = 0.0;
    rows->push_back(move[k]);
    t->push_back(tm[k + 1] + kLiftTime);
  }
  PathRow down = move.back();
  down.force = -1.0;
  rows->push_back(down);
  t->push_back(t->back() + kLiftTime);
  return true;
}

}  // namespace

namespace internal {

// PlanPath's state along one guide line: what a pattern's Follow reads and
// appends to (path_patterns.h).
struct GuideWalk {
  const Mapper& m;
  const std::vector<GuideSpec>& guides;
  size_t g;                      // the guide line being walked
  const Guide& guide;            // guides[g].guide
  const PathParameters& params;
  bool parallel_lines;           // the guides are parallel lines (not boundary offsets)
  Vec2 e_dir, nrm;               // along and across the parallel lines
  const std::function<Vec2(const Vec2&)>& tool_dir;    // tool x for a guide tangent
  const std::function<void(const Vec2&, const Vec2&)>& link;  // from last_st to a point, lifting if needed
  double vmax;                   // process.max_speed [m/s]
  double omega0;                 // the pattern's NominalRate [rad/s]
  PlannedPath& out;
  std::vector<double>& t;        // time stamps of out.rows
  Vec2& last_st;                 // where the previous guide ended, (s, t)
};

}  // namespace internal

namespace {

// The cycloid (seed 004 eq. 11): the tool circles with radius r around a
// centre that advances `pitch` per loop along the guide line.
class CycloidPattern final : public PathPattern {
 public:
  Pattern id() const override { return Pattern::kCycloid; }
  std::string name() const override { return ToString(id()); }
  std::string description() const override {
    return "cycloid: the tool circles (radius_mm) around a centre that advances pitch_mm per loop along guide lines "
           "offset_mm apart (seed 004)";
  }
  double circle_radius(const PathParameters& p) const override { return p.radius; }
  void CheckValid(const PathParameters& p) const override {
    auto fail = [](const std::string& m) { throw std::invalid_argument(m); };
    if (!(p.stagger >= 0.0 && p.stagger <= 1.0)) fail("stagger: expected in [0, 1] loops, got " + std::to_string(p.stagger));
    if (!(p.radius > 0)) fail("radius_mm: expected > 0, got " + Mm(p.radius));
    if (!(p.pitch > 0)) fail("pitch_mm: expected > 0, got " + Mm(p.pitch));
    if (p.offset > 2 * p.radius * (1 + 1e-12)) {
      fail("offset_mm " + Mm(p.offset) + " > 2 x radius_mm " + Mm(p.radius) +
           ": adjacent cycloid rows would leave an unpolished strip (seed 004 §3.1, d <= 2r)");
    }
    if (p.pitch >= 2 * kPi * p.radius) {
      fail("pitch_mm " + Mm(p.pitch) + " >= 2 pi radius_mm: the centre outruns the rolling point and the cycloid "
           "no longer loops (seed 004 §3.2, v < omega r)");
    }
  }
  double MaxEdgeOverrun(const PathParameters& p, const PolishingProcess& process) const override {
    return std::max(0.0, process.margin - p.radius);
  }
  double NominalRate(const PathParameters& p, double max_speed) const override {
    return max_speed / (p.radius + p.pitch / (2 * kPi));
  }
  double CentreSpeed(const PathParameters& p, double rate) const override { return p.pitch * rate / (2 * kPi); }
  void Follow(internal::GuideWalk& w) const override {
    const double r = w.params.radius, pitch = w.params.pitch;
    // Cycloid (seed eq. 11): x = xc + r cos(omega t + theta), y = yc + r sin(...),
    // the centre advancing `pitch` per loop; adjacent rows staggered by
    // params.stagger loops. On parallel lines the phase is tied to the
    // position along e_dir (paths.h), so that the stagger between
    // neighbours does not depend on the lines' lengths or run direction.
    double theta = 2 * kPi * w.params.stagger * static_cast<double>(w.g);
    if (w.parallel_lines) {
      const Vec2& a = w.guide.pts.front();
      const double k = std::round((a - w.guides[0].guide.pts.front()).dot(w.nrm) / w.params.offset);
      theta = 2 * kPi * (a.dot(w.e_dir) / pitch + w.params.stagger * k);
    }
    const double L = w.guide.length();
    // On a closed guide a whole number of loops (the pitch adjusted by at
    // most half a loop over the guide's length) closes the cycloid on
    // itself: no dense head and tail where it starts and ends.
    const double loops = w.guides[w.g].closed ? std::max(1.0, std::round(L / pitch)) : std::max(1.0, L / pitch);
    const double pitch_g = L > 0 ? L / loops : pitch;
    const double phi_end = 2 * kPi * loops;
    const double dphi = std::min(0.5, w.params.row_step / (r + pitch / (2 * kPi)));
    const int n = std::max(1, static_cast<int>(std::ceil(phi_end / dphi)));
    const int sense = w.guides[w.g].sense;
    auto point = [&](double phi) {
      const double sigma = pitch_g * phi / (2 * kPi);
      const double ang = sense * phi + theta;
      return Vec2(w.guide.At(sigma) + r * Vec2(std::cos(ang), std::sin(ang)));
    };
    for (int i = 0; i <= n; ++i) {
      const double phi = phi_end * i / n;
      const Vec2 st = point(phi);
      const Vec2 tan = w.tool_dir(w.guide.Tangent(pitch_g * phi / (2 * kPi)));
      if (i == 0) {
        if (w.out.rows.empty()) {
          w.out.rows.push_back(w.m.Row(st, tan));
          w.t.push_back(0.0);
        } else {
          // Transition from the end of the previous row, on the surface.
          w.link(st, tan);
        }
      } else {
        w.out.rows.push_back(w.m.Row(st, tan));
        w.t.push_back(w.t.back() + (phi_end / n) / w.omega0);
      }
      w.last_st = st;
    }
  }
};

// The direction-parallel (zig-zag) pattern: the tool follows each guide
// line (row) straight, linked to the next.
class ParallelPattern final : public PathPattern {
 public:
  Pattern id() const override { return Pattern::kParallel; }
  std::string name() const override { return ToString(id()); }
  std::string description() const override {
    return "parallel: the direction-parallel zig-zag, rows offset_mm apart (default: the contact width)";
  }
  double circle_radius(const PathParameters&) const override { return 0.0; }
  void CheckValid(const PathParameters&) const override {}
  double MaxEdgeOverrun(const PathParameters&, const PolishingProcess& process) const override { return process.margin; }
  double NominalRate(const PathParameters&, double) const override { return 0.0; }
  double CentreSpeed(const PathParameters&, double) const override { return 0.0; }
  void Follow(internal::GuideWalk& w) const override {
    const Vec2 dir = w.tool_dir(w.guide.Tangent(0.0));
    if (!w.out.rows.empty()) w.link(w.guide.pts.front(), dir);
    StraightMove(w.m, w.guide.pts.front(), w.guide.pts.back(), dir, w.vmax, w.params.row_step, w.out.rows.empty(), &w.out.rows, &w.t);
    w.last_st = w.guide.pts.back();
  }
};

}  // namespace

std::string ToString(Pattern p) {
  switch (p) {
    case Pattern::kCycloid: return "cycloid";
    case Pattern::kParallel: return "parallel";
  }
  return "?";
}

// Through the registry (the documented idiom for path patterns, library.md):
// its names are the one list, and its refusal is the enum parsers'.
Pattern ParsePattern(const std::string& name) { return PathPatternRegistry().Find(name)->id(); }

std::string ToString(GuideLines g) {
  switch (g) {
    case GuideLines::kBoundaryOffsets: return "offsets";
    case GuideLines::kParallelLines: return "parallel";
  }
  return "?";
}

GuideLines ParseGuideLines(const std::string& name) {
  static constexpr GuideLines kAll[] = {GuideLines::kBoundaryOffsets, GuideLines::kParallelLines};
  return ParseByName("guides", name, kAll);
}

const NamedRegistry<const PathPattern*>& PathPatternRegistry() {
  static const CycloidPattern cycloid;
  static const ParallelPattern parallel;
  static const NamedRegistry<const PathPattern*> registry = [] {
    NamedRegistry<const PathPattern*> r("unknown path pattern");
    r.Add(cycloid.name(), &cycloid).Add(parallel.name(), &parallel);
    return r;
  }();
  return registry;
}

const std::vector<const PathPattern*>& PathPatterns() {
  static const std::vector<const PathPattern*> all = PathPatternRegistry().Values();
  return all;
}

std::string PathPatternList() { return PathPatternRegistry().NameList(); }

const PathPattern& FindPathPattern(const std::string& name) { return *PathPatternRegistry().Find(name); }

const PathPattern& PathPatternOf(Pattern id) {
  for (const PathPattern* p : PathPatterns()) {
    if (p->id() == id) return *p;
  }
  throw std::invalid_argument("PathPatternOf: no pattern has this id");
}

PlannedPath PlanPath(const NurbsSurface& surface, const SampleGrid& grid, const PathParameters& params,
                     const PolishingProcess& process) {
  CheckValid(params);
  const PathPattern& pattern = PathPatternOf(params.pattern);
  const Mapper m(surface, grid, process.flip_normal);
  if (!(grid.s_hi() >= grid.s_lo()) || !(grid.t_hi() >= grid.t_lo())) {
    throw std::invalid_argument("the polished region is empty (margin too large for the patch)");
  }
  const double r = pattern.circle_radius(params);
  const double vmax = process.max_speed;
  // A pattern whose tool circles around its guide lines needs room for the
  // circle at the region's edge; its guides can be the boundary's offsets.
  const bool cyc = r > 0.0;
  const bool parallel_lines = !(cyc && params.guides == GuideLines::kBoundaryOffsets);

  // Guide lines, in order, with the direction sense of the cycloid.
  const DevelopedRegion region = DevelopedRegion::Build(surface, grid, process.margin);
  if (cyc) CheckCircleFits(surface, grid, region, params, process);  // never rows clamped onto the edges
  std::vector<GuideSpec> guides;
  // Direction of parallel lines: e (along the lines), nrm (across them).
  const double ca = std::cos(params.line_angle), sa = std::sin(params.line_angle);
  const Vec2 e_dir(ca, sa), nrm(-sa, ca);
  const bool rotated = parallel_lines && std::abs(params.line_angle) > 1e-12;
  const double overrun = region.rectangle() ? std::clamp(params.edge_overrun, 0.0, MaxEdgeOverrun(params, process)) : 0.0;
  if (region.rectangle() && !(parallel_lines && (rotated || overrun > 0))) guides = RectangleGuides(grid, params, process);
  else if (region.loops().empty()) throw std::invalid_argument("the polished region is empty (margin too large for the face)");
  else if (parallel_lines) {
    // Lines along e_dir: laid out along s in the region turned by -angle,
    // then turned back (a rotation keeps the rolling sense).
    auto turn = [](const Vec2& p, double c, double s) { return Vec2(c * p.x() - s * p.y(), s * p.x() + c * p.y()); };
    std::vector<Polygon2> loops = region.loops();
    for (auto& loop : loops)
      for (auto& x : loop) x = turn(x, ca, -sa);
    DevelopedRegion turned = rotated ? DevelopedRegion::FromPolygons(loops) : region;
    if (overrun > 0 && turned.rectangle()) {
      // The lines (rows) run `overrun` into the margin all round.
      const Eigen::Vector4d b = turned.Bounds();
      const double x0 = b(0) - overrun, y0 = b(1) - overrun, x1 = b(2) + overrun, y1 = b(3) + overrun;
      turned = DevelopedRegion::FromPolygons({{Vec2(x0, y0), Vec2(x1, y0), Vec2(x1, y1), Vec2(x0, y1)}});
    }
    if (cyc && !region.rectangle()) {
      // Cycloids along the lines: the lines stop the inset short of the
      // boundary, holes included, so that the circle stays on the face.
      const double e = CycloidInset(params, process);
      const DevelopedRegion inner = DevelopedRegion::FromPolygons(turned.Offset(e));
      if (inner.loops().empty()) RegionTooNarrow(region.Inradius(), e, params);
      guides = LineGuides(inner, params);
    } else {
      guides = LineGuides(turned, params);
    }
    if (rotated) {
      for (auto& g : guides) {
        std::vector<Vec2> pts = g.guide.pts;
        for (auto& x : pts) x = turn(x, ca, sa);
        g.guide = Guide(std::move(pts));
      }
    }
  } else guides = OffsetGuides(region, params, process);
  if (guides.empty()) throw std::invalid_argument("the polished region is narrower than the row spacing: no guide line fits");

  // Tool x along the guide line (seed eq. 16) with one sign for all the
  // parallel lines: the belt keeps running the same way and the wrist does
  // not turn half a revolution at every row end.
  const std::function<Vec2(const Vec2&)> tool_dir = [&](const Vec2& tangent) {
    return (parallel_lines && tangent.dot(e_dir) < 0) ? Vec2(-tangent) : tangent;
  };

  PlannedPath out;
  std::vector<double> t;
  Vec2 last_st(0, 0);
  // The rectangle's links are short by construction (the next loop, the
  // next line, the centre line); the general layouts lift on long ones.
  const double max_link = region.rectangle() ? std::numeric_limits<double>::infinity()
                                             : 2.0 * (params.offset + r);
  const std::function<void(const Vec2&, const Vec2&)> link = [&](const Vec2& to, const Vec2& tangent) {
    out.lifts += Link(m, surface, last_st, to, tangent, vmax, params.row_step, max_link, &out.rows, &t);
  };
  const double omega0 = pattern.NominalRate(params, vmax);
  for (size_t g = 0; g < guides.size(); ++g) {
    const Guide& guide = guides[g].guide;
    std::vector<Eigen::Vector3d> line;
    for (const Vec2& p : guide.pts) line.push_back(m.Point(p));
    out.guide_lines.push_back(line);
    out.guide_lines_st.push_back(guide.pts);
    internal::GuideWalk w{m, guides, g, guide, params, parallel_lines, e_dir, nrm, tool_dir, link,
                          vmax, omega0, out, t, last_st};
    pattern.Follow(w);
  }
  // With lifts every row says its force (the file's force_N column).
  if (out.lifts > 0) {
    for (auto& row : out.rows)
      if (row.force < 0) row.force = process.force;
  }
  // Enforce the speed limit on the mapped 3-D path (the developed plane
  // distorts lengths on doubly curved patches).
  for (size_t i = 0; i < out.rows.size(); ++i) out.rows[i].t = t[i];
  out.omega_rad_per_s = omega0;
  out.centre_speed = pattern.CentreSpeed(params, omega0);
  const double vm = MaxSpeed(out.rows);
  if (vm > vmax) ScaleTime(&out, vm / vmax);
  out.length = ContactLength(out.rows);
  return out;
}

double ContactLength(const std::vector<PathRow>& rows) {
  double len = 0.0;
  for (size_t i = 1; i < rows.size(); ++i) {
    if (rows[i - 1].force != 0.0) len += (rows[i].p - rows[i - 1].p).norm();
  }
  return len;
}

int CountLifts(const std::vector<PathRow>& rows) {
  int n = 0;
  for (size_t i = 1; i < rows.size(); ++i) n += rows[i].force == 0.0 && rows[i - 1].force != 0.0;
  return n;
}

void ScaleTime(PlannedPath* path, double factor) {
  // Lifting off and setting down (a force step between two rows at the same
  // point) keep their short duration: scaled, the step before a lift would
  // be a dwell at full force that leaves a mark.
  auto& rows = path->rows;
  if (path->lifts == 0 || rows.empty()) {
    for (auto& r : rows) r.t *= factor;
  } else {
    double prev = rows[0].t;
    rows[0].t *= factor;
    for (size_t i = 1; i < rows.size(); ++i) {
      const double dt = rows[i].t - prev;
      prev = rows[i].t;
      const bool force_step = (rows[i].force == 0.0) != (rows[i - 1].force == 0.0) && rows[i].p == rows[i - 1].p;
      rows[i].t = rows[i - 1].t + (force_step ? dt : dt * factor);
    }
  }
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
    if (row.force != 0.0 && !surface.OnFace(uu, vv)) {  // a lifted row may pass over a hole
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
