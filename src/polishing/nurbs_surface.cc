#include "robomach/polishing/nurbs_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "robomach/common/number_format.h"

namespace robomach::polishing {
namespace {

void CheckKnots(const char* name, const std::vector<double>& knots, int n, int degree) {
  const int expected = n + degree + 1;
  if (static_cast<int>(knots.size()) != expected) {
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(expected) +
                                " knots (control points " + std::to_string(n) + " + degree " +
                                std::to_string(degree) + " + 1), got " + std::to_string(knots.size()));
  }
  for (size_t i = 0; i < knots.size(); ++i) {
    if (!std::isfinite(knots[i])) throw std::invalid_argument(std::string(name) + ": knot " + std::to_string(i) + " is not finite");
    if (i > 0 && knots[i] < knots[i - 1]) {
      throw std::invalid_argument(std::string(name) + ": knots must be non-decreasing, knot " + std::to_string(i) +
                                  " = " + FormatNumber(knots[i], 6) + " < " + FormatNumber(knots[i - 1], 6));
    }
  }
  for (int i = 1; i <= degree; ++i) {
    if (knots[i] != knots[0] || knots[expected - 1 - i] != knots[expected - 1]) {
      throw std::invalid_argument(std::string(name) + ": expected a clamped knot vector (first and last knot repeated " +
                                  std::to_string(degree + 1) + " times)");
    }
  }
  if (!(knots[degree] < knots[n])) throw std::invalid_argument(std::string(name) + ": empty parameter range");
}

// Knot span index i with knots[i] <= x < knots[i+1], p <= i <= n-1 (The NURBS
// Book, A2.1); the end of the range belongs to the last non-empty span.
int FindSpan(const std::vector<double>& knots, int n, int p, double x) {
  if (x >= knots[n]) {
    int i = n - 1;
    while (i > p && knots[i] == knots[n]) --i;
    return i;
  }
  if (x <= knots[p]) {
    int i = p;
    while (i < n - 1 && knots[i + 1] <= x) ++i;
    return i;
  }
  const auto it = std::upper_bound(knots.begin() + p, knots.begin() + n + 1, x);
  return static_cast<int>(it - knots.begin()) - 1;
}

// Non-zero basis functions N_{span-p..span, p} and their derivatives up to
// order 2 at x: ders[k][j] (Cox-de Boor recursion with the derivative
// formula of The NURBS Book eq. 2.9).
std::array<std::vector<double>, 3> BasisDerivatives(const std::vector<double>& U, int span, int p, double x) {
  // ndu[j][r]: basis functions (upper triangle incl. diagonal) and knot differences (lower).
  std::vector<std::vector<double>> ndu(p + 1, std::vector<double>(p + 1, 0.0));
  std::vector<double> left(p + 1), right(p + 1);
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = x - U[span + 1 - j];
    right[j] = U[span + j] - x;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  std::array<std::vector<double>, 3> ders;
  for (auto& d : ders) d.assign(p + 1, 0.0);
  for (int j = 0; j <= p; ++j) ders[0][j] = ndu[j][p];
  const int nd = std::min(2, p);
  std::vector<std::vector<double>> a(2, std::vector<double>(p + 1, 0.0));
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= nd; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k][r] = d;
      std::swap(s1, s2);
    }
  }
  double factor = p;
  for (int k = 1; k <= nd; ++k) {
    for (int j = 0; j <= p; ++j) ders[k][j] *= factor;
    factor *= (p - k);
  }
  return ders;
}

}  // namespace

NurbsSurface NurbsSurface::Create(int degree_u, int degree_v, std::vector<double> knots_u,
                                  std::vector<double> knots_v,
                                  std::vector<std::vector<Eigen::Vector3d>> control_points,
                                  std::vector<std::vector<double>> weights) {
  if (degree_u < 1 || degree_v < 1) throw std::invalid_argument("degree_u and degree_v must be >= 1");
  const int n_u = static_cast<int>(control_points.size());
  if (n_u < degree_u + 1) {
    throw std::invalid_argument("control_points: expected at least degree_u + 1 = " + std::to_string(degree_u + 1) +
                                " rows, got " + std::to_string(n_u));
  }
  const int n_v = static_cast<int>(control_points[0].size());
  if (n_v < degree_v + 1) {
    throw std::invalid_argument("control_points: expected at least degree_v + 1 = " + std::to_string(degree_v + 1) +
                                " points per row, got " + std::to_string(n_v));
  }
  NurbsSurface s;
  s.p_ = degree_u;
  s.q_ = degree_v;
  s.n_u_ = n_u;
  s.n_v_ = n_v;
  for (int i = 0; i < n_u; ++i) {
    if (static_cast<int>(control_points[i].size()) != n_v) {
      throw std::invalid_argument("control_points: row " + std::to_string(i + 1) + " has " +
                                  std::to_string(control_points[i].size()) + " points, row 1 has " + std::to_string(n_v));
    }
    for (int j = 0; j < n_v; ++j) {
      if (!control_points[i][j].allFinite()) throw std::invalid_argument("control_points: non-finite coordinate");
      s.points_.push_back(control_points[i][j]);
    }
  }
  if (weights.empty()) {
    s.weights_.assign(n_u * n_v, 1.0);
  } else {
    if (static_cast<int>(weights.size()) != n_u) {
      throw std::invalid_argument("weights: expected " + std::to_string(n_u) + " rows, got " + std::to_string(weights.size()));
    }
    for (int i = 0; i < n_u; ++i) {
      if (static_cast<int>(weights[i].size()) != n_v) {
        throw std::invalid_argument("weights: row " + std::to_string(i + 1) + ": expected " + std::to_string(n_v) +
                                    " numbers, got " + std::to_string(weights[i].size()));
      }
      for (int j = 0; j < n_v; ++j) {
        if (!(weights[i][j] > 0.0) || !std::isfinite(weights[i][j])) {
          throw std::invalid_argument("weights: row " + std::to_string(i + 1) + ", entry " + std::to_string(j + 1) +
                                      ": expected a weight > 0, got " + FormatNumber(weights[i][j], 6));
        }
        s.weights_.push_back(weights[i][j]);
      }
    }
  }
  CheckKnots("knots_u", knots_u, n_u, degree_u);
  CheckKnots("knots_v", knots_v, n_v, degree_v);
  s.knots_u_ = std::move(knots_u);
  s.knots_v_ = std::move(knots_v);
  return s;
}

bool NurbsSurface::OnFace(double u, double v) const {
  const double eu = 1e-12 * (u_max() - u_min()), ev = 1e-12 * (v_max() - v_min());
  if (u < u_min() - eu || u > u_max() + eu || v < v_min() - ev || v > v_max() + ev) return false;
  return trim_ == nullptr || !trim_->contains || trim_->contains(u, v);
}

SurfaceDerivatives NurbsSurface::Evaluate(double u, double v) const {
  u = std::clamp(u, u_min(), u_max());
  v = std::clamp(v, v_min(), v_max());
  const int su = FindSpan(knots_u_, n_u_, p_, u);
  const int sv = FindSpan(knots_v_, n_v_, q_, v);
  const auto Nu = BasisDerivatives(knots_u_, su, p_, u);
  const auto Nv = BasisDerivatives(knots_v_, sv, q_, v);
  // Homogeneous derivatives A^(k,l) (weighted points) and w^(k,l), k + l <= 2.
  Eigen::Vector4d H[3][3];
  for (auto& row : H)
    for (auto& h : row) h.setZero();
  for (int a = 0; a <= p_; ++a) {
    const int i = su - p_ + a;
    for (int b = 0; b <= q_; ++b) {
      const int j = sv - q_ + b;
      const double w = weights_[i * n_v_ + j];
      Eigen::Vector4d Pw;
      Pw << w * points_[i * n_v_ + j], w;
      for (int k = 0; k <= 2; ++k)
        for (int l = 0; k + l <= 2; ++l) H[k][l] += Nu[k][a] * Nv[l][b] * Pw;
    }
  }
  // Rational derivatives (The NURBS Book eq. 4.20).
  auto A = [&](int k, int l) { return Eigen::Vector3d(H[k][l].head<3>()); };
  auto W = [&](int k, int l) { return H[k][l](3); };
  const double w = W(0, 0);
  SurfaceDerivatives d;
  d.S = A(0, 0) / w;
  d.S_u = (A(1, 0) - W(1, 0) * d.S) / w;
  d.S_v = (A(0, 1) - W(0, 1) * d.S) / w;
  d.S_uu = (A(2, 0) - 2.0 * W(1, 0) * d.S_u - W(2, 0) * d.S) / w;
  d.S_vv = (A(0, 2) - 2.0 * W(0, 1) * d.S_v - W(0, 2) * d.S) / w;
  d.S_uv = (A(1, 1) - W(1, 0) * d.S_v - W(0, 1) * d.S_u - W(1, 1) * d.S) / w;
  return d;
}

Eigen::Vector3d UnitNormal(const SurfaceDerivatives& d, bool flip) {
  const Eigen::Vector3d n = d.S_u.cross(d.S_v);
  const double len = n.norm();
  if (!(len > 1e-14 * std::max(1e-300, d.S_u.norm() * d.S_v.norm())) || !std::isfinite(len)) {
    throw std::domain_error("degenerate surface point: S_u x S_v = 0, the normal is undefined");
  }
  return flip ? Eigen::Vector3d(-n / len) : Eigen::Vector3d(n / len);
}

Eigen::Matrix2d CurvatureTensor(const SurfaceDerivatives& d, const Eigen::Vector3d& e1,
                                const Eigen::Vector3d& e2, bool flip) {
  const Eigen::Vector3d n = UnitNormal(d, flip);
  Eigen::Matrix<double, 3, 2> J;
  J << d.S_u, d.S_v;
  // Parameter-space components of the tangent directions: J w = e.
  const Eigen::Matrix2d G = J.transpose() * J;
  Eigen::Matrix<double, 2, 2> Wm;
  Wm.col(0) = G.ldlt().solve(J.transpose() * e1);
  Wm.col(1) = G.ldlt().solve(J.transpose() * e2);
  Eigen::Matrix2d II;
  II << d.S_uu.dot(n), d.S_uv.dot(n), d.S_uv.dot(n), d.S_vv.dot(n);
  const Eigen::Matrix2d k = -(Wm.transpose() * II * Wm);
  return 0.5 * (k + k.transpose());
}

SurfaceCurvature PrincipalCurvatures(const SurfaceDerivatives& d, bool flip) {
  SurfaceCurvature c;
  c.normal = UnitNormal(d, flip);
  const Eigen::Vector3d e1 = d.S_u.normalized();
  const Eigen::Vector3d e2 = c.normal.cross(e1);
  const Eigen::Matrix2d k = CurvatureTensor(d, e1, e2, flip);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(k);  // ascending
  c.k1 = eig.eigenvalues()(1);
  c.k2 = eig.eigenvalues()(0);
  const Eigen::Vector2d x1 = eig.eigenvectors().col(1), x2 = eig.eigenvectors().col(0);
  c.d1 = (x1(0) * e1 + x1(1) * e2).normalized();
  c.d2 = (x2(0) * e1 + x2(1) * e2).normalized();
  return c;
}

}  // namespace robomach::polishing
