#include "robomach/polishing/surface_grid.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

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
                    std::vector<double>* table_par, double* max_len) {
  constexpr int kFine = 2000, kLines = 9;
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

}  // namespace

SampleGrid SampleGrid::Build(const NurbsSurface& surface, double max_spacing, double margin, bool flip) {
  SampleGrid g;
  double max_s = 0, max_t = 0;
  ArcLengthTable(surface, true, &g.table_s_, &g.table_u_, &max_s);
  ArcLengthTable(surface, false, &g.table_t_, &g.table_v_, &max_t);
  g.length_s_ = g.table_s_.back();
  g.length_t_ = g.table_t_.back();
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
      g.n_[k] = UnitNormal(d, flip);
      jac[k] = d.S_u.cross(d.S_v).norm();
    }
  }
  auto half_span = [](const std::vector<double>& x, int i) {
    const int n = static_cast<int>(x.size());
    return 0.5 * (x[std::min(i + 1, n - 1)] - x[std::max(i - 1, 0)]);
  };
  for (int j = 0; j < g.nt_; ++j)
    for (int i = 0; i < g.ns_; ++i) g.area_[g.index(i, j)] = jac[g.index(i, j)] * half_span(g.u_, i) * half_span(g.v_, j);
  // Distance to the boundary along the iso-lines through each point.
  std::vector<double> along_s(N, 0.0), along_t(N, 0.0);
  for (int j = 0; j < g.nt_; ++j)
    for (int i = 1; i < g.ns_; ++i)
      along_s[g.index(i, j)] = along_s[g.index(i - 1, j)] + (g.p_[g.index(i, j)] - g.p_[g.index(i - 1, j)]).norm();
  for (int i = 0; i < g.ns_; ++i)
    for (int j = 1; j < g.nt_; ++j)
      along_t[g.index(i, j)] = along_t[g.index(i, j - 1)] + (g.p_[g.index(i, j)] - g.p_[g.index(i, j - 1)]).norm();
  g.in_region_.assign(N, 0);
  g.s_lo_ = g.t_lo_ = 1e300;
  g.s_hi_ = g.t_hi_ = -1e300;
  for (int j = 0; j < g.nt_; ++j) {
    for (int i = 0; i < g.ns_; ++i) {
      const int k = g.index(i, j);
      const double ds = std::min(along_s[k], along_s[g.index(g.ns_ - 1, j)] - along_s[k]);
      const double dt = std::min(along_t[k], along_t[g.index(i, g.nt_ - 1)] - along_t[k]);
      if (std::min(ds, dt) >= margin - 1e-12) {
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
double SampleGrid::UOfS(double s) const { return Interp(table_s_, table_u_, s); }
double SampleGrid::VOfT(double t) const { return Interp(table_t_, table_v_, t); }
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
