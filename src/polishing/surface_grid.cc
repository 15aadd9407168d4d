#include "robomach/polishing/surface_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>

#include <Eigen/Dense>

#include "robomach/polishing/face_trim.h"

namespace robomach::polishing {
namespace {

// Linear interpolation y(x) in a strictly increasing table xs.
double Interp(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  if (x <= xs.front()) return ys.front();
  if (x >= xs.back()) return ys.back();
  const auto it = std::upper_bound(xs.begin(), xs.end(), x);
  const size_t k = it - xs.begin();
  const double f = (x - xs[k - 1]) / (xs[k] - xs[k - 1]);
  return ys[k - 1] + f * (ys[k] - ys[k - 1]);
}

double Slope(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  size_t k = std::upper_bound(xs.begin(), xs.end(), x) - xs.begin();
  k = std::clamp<size_t>(k, 1, xs.size() - 1);
  return (ys[k] - ys[k - 1]) / (xs[k] - xs[k - 1]);
}

// Mean arc length along one parameter (over several iso-lines of the other)
// as a table of (arc length, parameter).
void ArcLengthTable(const NurbsSurface& S, bool along_u, std::vector<double>* table_len,
                    std::vector<double>* table_par, double* max_len, int kFine = 2000) {
  constexpr int kLines = 9;
  const double a0 = along_u ? S.u_min() : S.v_min(), a1 = along_u ? S.u_max() : S.v_max();
  const double b0 = along_u ? S.v_min() : S.u_min(), b1 = along_u ? S.v_max() : S.u_max();
  table_par->resize(kFine + 1);
  table_len->assign(kFine + 1, 0.0);
  *max_len = 0.0;
  for (int k = 0; k <= kFine; ++k) (*table_par)[k] = a0 + (a1 - a0) * k / kFine;
  for (int l = 0; l < kLines; ++l) {
    const double b = b0 + (b1 - b0) * l / (kLines - 1);
    Eigen::Vector3d prev = along_u ? S.Point(a0, b) : S.Point(b, a0);
    double len = 0.0;
    for (int k = 1; k <= kFine; ++k) {
      const double a = (*table_par)[k];
      const Eigen::Vector3d p = along_u ? S.Point(a, b) : S.Point(b, a);
      len += (p - prev).norm();
      prev = p;
      (*table_len)[k] += len / kLines;
    }
    *max_len = std::max(*max_len, len);
  }
  // Keep the table strictly increasing (a degenerate stretch adds nothing).
  for (int k = 1; k <= kFine; ++k) {
    (*table_len)[k] = std::max((*table_len)[k], (*table_len)[k - 1] + 1e-15);
  }
}

// Distance from points to a set of 3-D polylines, with the segments bucketed
// in a uniform grid of cubes of side `cell` so that a query "closer than
// cell?" looks at 27 cells only.
class SegmentIndex {
 public:
  SegmentIndex(const std::vector<std::vector<Eigen::Vector3d>>& lines, double cell) : cell_(cell) {
    for (const auto& l : lines)
      for (size_t i = 1; i < l.size(); ++i) {
        const int id = static_cast<int>(a_.size());
        a_.push_back(l[i - 1]);
        b_.push_back(l[i]);
        const Eigen::Vector3i lo = Cell(l[i - 1].cwiseMin(l[i])), hi = Cell(l[i - 1].cwiseMax(l[i]));
        for (int x = lo.x(); x <= hi.x(); ++x)
          for (int y = lo.y(); y <= hi.y(); ++y)
            for (int z = lo.z(); z <= hi.z(); ++z) cells_[Key(x, y, z)].push_back(id);
      }
  }
  /// min(distance to the nearest segment, cell).
  double DistanceCapped(const Eigen::Vector3d& p) const {
    double best = cell_;
    const Eigen::Vector3i c = Cell(p);
    for (int x = c.x() - 1; x <= c.x() + 1; ++x)
      for (int y = c.y() - 1; y <= c.y() + 1; ++y)
        for (int z = c.z() - 1; z <= c.z() + 1; ++z) {
          const auto it = cells_.find(Key(x, y, z));
          if (it == cells_.end()) continue;
          for (int id : it->second) {
            const Eigen::Vector3d ab = b_[id] - a_[id];
            const double len2 = ab.squaredNorm();
            const double f = len2 > 0 ? std::clamp((p - a_[id]).dot(ab) / len2, 0.0, 1.0) : 0.0;
            best = std::min(best, (a_[id] + f * ab - p).norm());
          }
        }
    return best;
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / cell_)), static_cast<int>(std::floor(p.y() / cell_)),
                           static_cast<int>(std::floor(p.z() / cell_)));
  }
  static long long Key(int x, int y, int z) {
    return (static_cast<long long>(x & 0x1fffff) << 42) | (static_cast<long long>(y & 0x1fffff) << 21) |
           static_cast<long long>(z & 0x1fffff);
  }
  double cell_;
  std::vector<Eigen::Vector3d> a_, b_;
  std::unordered_map<long long, std::vector<int>> cells_;
};

std::string Mm(double x_m) {
  std::ostringstream o;
  o.precision(4);
  o << 1e3 * x_m;
  return o.str();
}

}  // namespace

SurfaceSize MeasureSurface(const NurbsSurface& surface, int fine) {
  SurfaceSize z;
  std::vector<double> len, par;
  ArcLengthTable(surface, true, &len, &par, &z.max_u, std::max(2, fine));
  z.length_u = len.back();
  ArcLengthTable(surface, false, &len, &par, &z.max_v, std::max(2, fine));
  z.length_v = len.back();
  return z;
}

double EstimateGridPoints(const SurfaceSize& size, double max_spacing) {
  if (!std::isfinite(size.max_u) || !std::isfinite(size.max_v) || !(max_spacing > 0)) {
    return std::numeric_limits<double>::infinity();
  }
  return (std::ceil(size.max_u / max_spacing) + 1) * (std::ceil(size.max_v / max_spacing) + 1);
}

std::string SurfaceName(const NurbsSurface& surface) {
  return surface.trim() && !surface.trim()->source.empty() ? surface.trim()->source : "the patch";
}

SampleGrid SampleGrid::Build(const NurbsSurface& surface, double max_spacing, double margin, bool flip,
                             double max_points) {
  SampleGrid g;
  double max_s = 0, max_t = 0;
  ArcLengthTable(surface, true, &g.table_s_, &g.table_u_, &max_s);
  ArcLengthTable(surface, false, &g.table_t_, &g.table_v_, &max_t);
  g.length_s_ = g.table_s_.back();
  g.length_t_ = g.table_t_.back();
  // The grid's size, validated before any cast to int (issue 22: a mutated
  // patch gave NaN or 1e300 here, and ns * nt overflowed).
  if (!std::isfinite(max_s) || !std::isfinite(max_t) || !std::isfinite(g.length_s_) || !std::isfinite(g.length_t_)) {
    throw std::domain_error(SurfaceName(surface) + ": the patch's size is not finite (a NaN or infinite control "
                            "point or weight?)");
  }
  if (!(max_spacing > 0) || !std::isfinite(max_spacing)) {
    throw std::domain_error("sampling spacing must be a finite number > 0, got " + Mm(max_spacing) + " mm");
  }
  const double points = EstimateGridPoints({g.length_s_, g.length_t_, max_s, max_t}, max_spacing);
  if (!(points <= max_points)) {
    std::ostringstream m;
    m.precision(3);
    m << SurfaceName(surface) << " is too large to sample: " << Mm(g.length_s_) << " x " << Mm(g.length_t_)
      << " mm (mean arc lengths along u and v) at " << Mm(max_spacing) << " mm spacing needs " << points
      << " grid points (~" << points * 90e-9 << " GB), above the limit of " << max_points
      << " (check the file's unit, or use a coarser sampling)";
    throw std::domain_error(m.str());
  }
  // The longest iso-line decides the count, so no spacing exceeds max_spacing
  // (up to the parametrisation's non-uniformity, checked below).
  g.ns_ = static_cast<int>(std::ceil(max_s / max_spacing)) + 1;
  g.nt_ = static_cast<int>(std::ceil(max_t / max_spacing)) + 1;
  for (int i = 0; i < g.ns_; ++i) {
    g.s_.push_back(g.length_s_ * i / (g.ns_ - 1));
    g.u_.push_back(Interp(g.table_s_, g.table_u_, g.s_.back()));
  }
  for (int j = 0; j < g.nt_; ++j) {
    g.t_.push_back(g.length_t_ * j / (g.nt_ - 1));
    g.v_.push_back(Interp(g.table_t_, g.table_v_, g.t_.back()));
  }
  const int N = g.ns_ * g.nt_;
  g.p_.resize(N);
  g.n_.resize(N);
  g.area_.resize(N);
  std::vector<double> jac(N);
  for (int j = 0; j < g.nt_; ++j) {
    for (int i = 0; i < g.ns_; ++i) {
      const SurfaceDerivatives d = surface.Evaluate(g.u_[i], g.v_[j]);
      const int k = g.index(i, j);
      g.p_[k] = d.S;
      try {
        g.n_[k] = UnitNormal(d, flip);
      } catch (const std::domain_error& e) {
        // A pole of the patch (a degenerate edge: cone apex, sphere pole,
        // a collapsed B-spline boundary): name the face, its size and where.
        std::ostringstream m;
        m << SurfaceName(surface) << " (" << Mm(g.length_s_) << " x " << Mm(g.length_t_) << " mm): " << e.what()
          << " at u " << g.u_[i] << ", v " << g.v_[j] << " (a pole of the patch, e.g. a collapsed edge; faces "
          << "with poles cannot be sampled)";
        throw std::domain_error(m.str());
      }
      jac[k] = d.S_u.cross(d.S_v).norm();
    }
  }
  auto half_span = [](const std::vector<double>& x, int i) {
    const int n = static_cast<int>(x.size());
    return 0.5 * (x[std::min(i + 1, n - 1)] - x[std::max(i - 1, 0)]);
  };
  for (int j = 0; j < g.nt_; ++j)
    for (int i = 0; i < g.ns_; ++i) g.area_[g.index(i, j)] = jac[g.index(i, j)] * half_span(g.u_, i) * half_span(g.v_, j);
  // The polished region. A plain patch: distance to the patch boundary along
  // the iso-lines through each point. A trimmed CAD face: on the face, and at
  // least `margin` (straight 3-D distance) from every trimming edge, holes
  // included; the straight distance is the geodesic one to within
  // margin^3 kappa^2 / 24 (0.04 % for 5 mm on a 50 mm radius).
  std::vector<char> keep(N, 1);
  if (const FaceTrim* trim = surface.trim()) {
    const SegmentIndex index(trim->boundary, std::max(margin, 1e-6));
    for (int j = 0; j < g.nt_; ++j)
      for (int i = 0; i < g.ns_; ++i) {
        const int k = g.index(i, j);
        keep[k] = surface.OnFace(g.u_[i], g.v_[j]) && (margin <= 0 || index.DistanceCapped(g.p_[k]) >= margin - 1e-12);
      }
  } else {
    std::vector<double> along_s(N, 0.0), along_t(N, 0.0);
    for (int j = 0; j < g.nt_; ++j)
      for (int i = 1; i < g.ns_; ++i)
        along_s[g.index(i, j)] = along_s[g.index(i - 1, j)] + (g.p_[g.index(i, j)] - g.p_[g.index(i - 1, j)]).norm();
    for (int i = 0; i < g.ns_; ++i)
      for (int j = 1; j < g.nt_; ++j)
        along_t[g.index(i, j)] = along_t[g.index(i, j - 1)] + (g.p_[g.index(i, j)] - g.p_[g.index(i, j - 1)]).norm();
    for (int j = 0; j < g.nt_; ++j)
      for (int i = 0; i < g.ns_; ++i) {
        const int k = g.index(i, j);
        const double ds = std::min(along_s[k], along_s[g.index(g.ns_ - 1, j)] - along_s[k]);
        const double dt = std::min(along_t[k], along_t[g.index(i, g.nt_ - 1)] - along_t[k]);
        keep[k] = std::min(ds, dt) >= margin - 1e-12;
      }
  }
  g.in_region_.assign(N, 0);
  g.s_lo_ = g.t_lo_ = 1e300;
  g.s_hi_ = g.t_hi_ = -1e300;
  for (int j = 0; j < g.nt_; ++j) {
    for (int i = 0; i < g.ns_; ++i) {
      const int k = g.index(i, j);
      if (keep[k]) {
        g.in_region_[k] = 1;
        g.s_lo_ = std::min(g.s_lo_, g.s_[i]);
        g.s_hi_ = std::max(g.s_hi_, g.s_[i]);
        g.t_lo_ = std::min(g.t_lo_, g.t_[j]);
        g.t_hi_ = std::max(g.t_hi_, g.t_[j]);
      }
    }
  }
  return g;
}

int SampleGrid::num_in_region() const {
  return static_cast<int>(std::count(in_region_.begin(), in_region_.end(), 1));
}
double SampleGrid::region_area() const {
  double area = 0.0;
  for (size_t k = 0; k < area_.size(); ++k) area += in_region_[k] ? area_[k] : 0.0;
  return area;
}
double SampleGrid::UOfS(double s) const { return Interp(table_s_, table_u_, s); }
double SampleGrid::VOfT(double t) const { return Interp(table_t_, table_v_, t); }
double SampleGrid::SOfU(double u) const { return Interp(table_u_, table_s_, u); }
double SampleGrid::TOfV(double v) const { return Interp(table_v_, table_t_, v); }
double SampleGrid::DuDs(double s) const { return Slope(table_s_, table_u_, s); }
double SampleGrid::DvDt(double t) const { return Slope(table_t_, table_v_, t); }

double ProjectToSurface(const NurbsSurface& surface, const Eigen::Vector3d& x, double* u, double* v) {
  double uu = std::clamp(*u, surface.u_min(), surface.u_max());
  double vv = std::clamp(*v, surface.v_min(), surface.v_max());
  for (int it = 0; it < 30; ++it) {
    const SurfaceDerivatives d = surface.Evaluate(uu, vv);
    const Eigen::Vector3d r = d.S - x;
    // Gauss-Newton with the second-order terms (Newton on grad |r|^2 / 2).
    Eigen::Matrix2d H;
    H << d.S_u.dot(d.S_u) + r.dot(d.S_uu), d.S_u.dot(d.S_v) + r.dot(d.S_uv),
        d.S_u.dot(d.S_v) + r.dot(d.S_uv), d.S_v.dot(d.S_v) + r.dot(d.S_vv);
    const Eigen::Vector2d grad(r.dot(d.S_u), r.dot(d.S_v));
    Eigen::Vector2d step;
    if (H.determinant() > 0 && H(0, 0) > 0) {
      step = -H.ldlt().solve(grad);
    } else {
      Eigen::Matrix2d G;
      G << d.S_u.dot(d.S_u), d.S_u.dot(d.S_v), d.S_u.dot(d.S_v), d.S_v.dot(d.S_v);
      step = -G.ldlt().solve(grad);
    }
    const double nu = std::clamp(uu + step(0), surface.u_min(), surface.u_max());
    const double nv = std::clamp(vv + step(1), surface.v_min(), surface.v_max());
    const bool done = std::abs(nu - uu) < 1e-13 * (surface.u_max() - surface.u_min()) &&
                      std::abs(nv - vv) < 1e-13 * (surface.v_max() - surface.v_min());
    uu = nu;
    vv = nv;
    if (done) break;
  }
  *u = uu;
  *v = vv;
  return (surface.Point(uu, vv) - x).norm();
}

}  // namespace robomach::polishing
