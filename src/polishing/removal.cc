#include "robomach/polishing/removal.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "robomach/polishing/hertz_contact.h"
#include "robomach/polishing/paths.h"

namespace robomach::polishing {

namespace {

// The ellipse's axes in the tool frame (tx, ty) and the belt-width check,
// for ContactAt and RemovalSimulator::Contacts alike.
// @throws std::domain_error when the contact is wider than the belt.
void SetEllipse(const ContactEllipse& e, const Eigen::Vector3d& tx, const Eigen::Vector3d& ty, double belt_width,
                ToolContact* c) {
  c->a = e.a;
  c->b = e.b;
  c->p0 = e.p0;
  c->e_a = e.dir_a(0) * tx + e.dir_a(1) * ty;
  c->e_b = e.dir_b(0) * tx + e.dir_b(1) * ty;
  // Half-width across the belt (along tool y).
  const double half_width = std::hypot(e.a * e.dir_a(1), e.b * e.dir_b(1));
  if (2.0 * half_width > belt_width) {
    std::ostringstream m;
    m << "contact width " << 2e3 * half_width << " mm across the belt exceeds belt_width_mm " << 1e3 * belt_width;
    throw std::domain_error(m.str());
  }
}

}  // namespace

ToolContact ContactAt(const SurfaceDerivatives& d, const Eigen::Vector3d& tool_x, const PolishingProcess& process,
                      double force) {
  ToolContact c;
  c.p = d.S;
  c.n = UnitNormal(d, process.flip_normal);
  const Eigen::Vector3d tx = (tool_x - tool_x.dot(c.n) * c.n).normalized();
  const Eigen::Vector3d ty = c.n.cross(tx);
  // Relative curvature in the tool's (x, y) frame: wheel + surface (convex +).
  Eigen::Matrix2d K = CurvatureTensor(d, tx, ty, process.flip_normal);
  K(0, 0) += 1.0 / process.wheel_radius;
  K(1, 1) += 1.0 / process.crown_radius;
  SetEllipse(HertzContact(K, force, EffectiveModulus(process)), tx, ty, process.belt_width, &c);
  return c;
}

double SegmentPressureIntegral(const Eigen::Vector2d& alpha, const Eigen::Vector2d& beta) {
  const double bb = beta.squaredNorm();
  if (bb < 1e-24) return std::sqrt(std::max(0.0, 1.0 - alpha.squaredNorm()));
  const double lb = std::sqrt(bb);
  const double tau_star = alpha.dot(beta) / bb;
  // Squared half-chord of the unit circle on the line: R^2 = 1 - |alpha_perp|^2.
  const double R2 = 1.0 - alpha.squaredNorm() + tau_star * tau_star * bb;
  if (R2 <= 0.0) return 0.0;
  const double R = std::sqrt(R2);
  const double s0 = std::max(-R, -lb * tau_star), s1 = std::min(R, lb * (1.0 - tau_star));
  if (s1 <= s0) return 0.0;
  // Integral of sqrt(R^2 - s^2) over [s0, s1] with x = s / R, c = sqrt(1 - x^2):
  // R^2 / 2 [x c + asin x] between the limits. The difference of the two
  // arcsines is one atan2 of the difference angle's sine and cosine, which
  // is also well conditioned when s1 - s0 is small against R (the usual
  // case: a segment much shorter than the contact).
  const double x0 = std::clamp(s0 / R, -1.0, 1.0), x1 = std::clamp(s1 / R, -1.0, 1.0);
  const double c0 = std::sqrt(std::max(0.0, 1.0 - x0 * x0)), c1 = std::sqrt(std::max(0.0, 1.0 - x1 * x1));
  const double dtheta = std::atan2(x1 * c0 - x0 * c1, c0 * c1 + x0 * x1);
  return 0.5 * R2 * (x1 * c1 - x0 * c0 + dtheta) / lb;
}

RemovalSimulator::RemovalSimulator(const NurbsSurface& surface, const PolishingProcess& process,
                                   std::vector<Eigen::Vector3d> points, std::vector<Eigen::Vector3d> normals,
                                   double cell_size)
    : surface_(&surface), process_(process), points_(std::move(points)), normals_(std::move(normals)),
      cell_(cell_size) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(0.0), hi = lo;
  if (!points_.empty()) {
    lo = hi = points_[0];
    for (const auto& p : points_) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  origin_ = lo;
  nx_ = static_cast<int>((hi.x() - lo.x()) / cell_) + 1;
  ny_ = static_cast<int>((hi.y() - lo.y()) / cell_) + 1;
  nz_ = static_cast<int>((hi.z() - lo.z()) / cell_) + 1;
  const long cells = static_cast<long>(nx_) * ny_ * nz_;
  std::vector<int> cell_of(points_.size());
  cell_start_.assign(cells + 1, 0);
  for (size_t k = 0; k < points_.size(); ++k) {
    const Eigen::Vector3d q = (points_[k] - origin_) / cell_;
    const int ix = std::min(nx_ - 1, static_cast<int>(q.x()));
    const int iy = std::min(ny_ - 1, static_cast<int>(q.y()));
    const int iz = std::min(nz_ - 1, static_cast<int>(q.z()));
    cell_of[k] = (iz * ny_ + iy) * nx_ + ix;
    ++cell_start_[cell_of[k] + 1];
  }
  for (long c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  order_.resize(points_.size());
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t k = 0; k < points_.size(); ++k) order_[fill[cell_of[k]]++] = static_cast<int>(k);
  // Points and normals in cell order, one array per coordinate: the inner
  // loop of Simulate reads them contiguously.
  sorted_.resize(6 * points_.size());
  const size_t n = points_.size();
  for (size_t k = 0; k < n; ++k) {
    const int i = order_[k];
    for (int c = 0; c < 3; ++c) {
      sorted_[c * n + k] = points_[i](c);
      sorted_[(3 + c) * n + k] = normals_[i](c);
    }
  }
}

std::vector<ToolContact> RemovalSimulator::Contacts(const std::vector<PathRow>& path) const {
  std::vector<ToolContact> contacts(path.size());
  // Consecutive rows with the same relative curvature and force (planes,
  // cylinders along a generator, ...) share their ellipse: the elliptic
  // integrals are the cost of a contact.
  Eigen::Matrix2d last_K = Eigen::Matrix2d::Constant(std::nan(""));
  double last_force = -1.0;
  ContactEllipse last;
  const double e_star = EffectiveModulus(process_);
  for (size_t r = 0; r < path.size(); ++r) {
    try {
      const SurfaceDerivatives d = surface_->Evaluate(path[r].u, path[r].v);
      const double force = path[r].force >= 0 ? path[r].force : process_.force;
      ToolContact& c = contacts[r];
      c.p = d.S;
      c.n = UnitNormal(d, process_.flip_normal);
      const Eigen::Vector3d tx = (path[r].tx - path[r].tx.dot(c.n) * c.n).normalized();
      const Eigen::Vector3d ty = c.n.cross(tx);
      if (force == 0.0) {  // the tool is lifted: no contact (a = b = p0 = 0)
        c.e_a = tx;
        c.e_b = ty;
        continue;
      }
      Eigen::Matrix2d K = CurvatureTensor(d, tx, ty, process_.flip_normal);
      K(0, 0) += 1.0 / process_.wheel_radius;
      K(1, 1) += 1.0 / process_.crown_radius;
      if (!(K == last_K && force == last_force)) {
        last = HertzContact(K, force, e_star);
        last_K = K;
        last_force = force;
      }
      SetEllipse(last, tx, ty, process_.belt_width, &c);
    } catch (const std::domain_error& e) {
      throw PathRowError(static_cast<int>(r), e.what());
    }
  }
  return contacts;
}

std::vector<double> RemovalSimulator::Simulate(const std::vector<PathRow>& path) const {
  return Simulate(path, Contacts(path));
}

std::vector<double> RemovalSimulator::Simulate(const std::vector<PathRow>& path,
                                               const std::vector<ToolContact>& contacts) const {
  const size_t n = points_.size();
  const double* px = sorted_.data();
  const double* py = px + n;
  const double* pz = py + n;
  const double* qx = pz + n;
  const double* qy = qx + n;
  const double* qz = qy + n;
  std::vector<double> hs(n, 0.0);  // in cell order
  for (size_t r = 0; r + 1 < path.size(); ++r) {
    const double dt = path[r + 1].t - path[r].t;
    if (!(dt > 0.0)) {
      throw PathRowError(static_cast<int>(r + 1), "t_s must be strictly increasing");
    }
    const ToolContact& c = contacts[r];
    // Lifted (force 0 at the segment's start), or lifting off at its end: no
    // removal. formats.md §6 makes the force linear between rows; a force
    // step to or from 0 is taken as instantaneous.
    if (!(c.p0 > 0.0) || path[r + 1].force == 0.0) continue;
    const Eigen::Vector3d d = path[r + 1].p - path[r].p;
    const double v_rel = (process_.belt_speed * path[r].tx + d / dt).norm();
    const double scale = process_.preston_coefficient * c.p0 * v_rel * dt;
    const double reach = std::max(c.a, c.b);
    // Bounding box of the ellipse swept along the segment, thickened by the
    // normal tolerance below: per axis, the ellipse's half-extent plus
    // reach times the normal's component.
    Eigen::Vector3d ext;
    for (int k = 0; k < 3; ++k) {
      ext(k) = std::hypot(c.a * c.e_a(k), c.b * c.e_b(k)) + reach * std::abs(c.n(k));
    }
    const Eigen::Vector3d lo = path[r].p.cwiseMin(path[r + 1].p) - ext;
    const Eigen::Vector3d hi = path[r].p.cwiseMax(path[r + 1].p) + ext;
    const int x0 = std::max(0, static_cast<int>(std::floor((lo.x() - origin_.x()) / cell_)));
    const int y0 = std::max(0, static_cast<int>(std::floor((lo.y() - origin_.y()) / cell_)));
    const int z0 = std::max(0, static_cast<int>(std::floor((lo.z() - origin_.z()) / cell_)));
    const int x1 = std::min(nx_ - 1, static_cast<int>(std::floor((hi.x() - origin_.x()) / cell_)));
    const int y1 = std::min(ny_ - 1, static_cast<int>(std::floor((hi.y() - origin_.y()) / cell_)));
    const int z1 = std::min(nz_ - 1, static_cast<int>(std::floor((hi.z() - origin_.z()) / cell_)));
    if (x0 > x1 || y0 > y1 || z0 > z1) continue;
    // Elliptic coordinates alpha = (q.e_a / a, q.e_b / b) of q = point - centre.
    const Eigen::Vector3d ea = c.e_a / c.a, eb = c.e_b / c.b;
    const Eigen::Vector2d beta(d.dot(ea), d.dot(eb));
    const double bb = beta.squaredNorm();
    const bool moving = bb > 1e-24;
    const double cx = c.p.x(), cy = c.p.y(), cz = c.p.z();
    for (int iz = z0; iz <= z1; ++iz) {
      for (int iy = y0; iy <= y1; ++iy) {
        const int row = (iz * ny_ + iy) * nx_;
        const int k1 = cell_start_[row + x1 + 1];
        for (int k = cell_start_[row + x0]; k < k1; ++k) {
          const double dx = px[k] - cx, dy = py[k] - cy, dz = pz[k] - cz;
          // Only the side the tool is on, within the contact's reach normal to it.
          if (std::abs(dx * c.n.x() + dy * c.n.y() + dz * c.n.z()) > reach ||
              qx[k] * c.n.x() + qy[k] * c.n.y() + qz[k] * c.n.z() <= 0.0) {
            continue;
          }
          const Eigen::Vector2d alpha(dx * ea.x() + dy * ea.y() + dz * ea.z(), dx * eb.x() + dy * eb.y() + dz * eb.z());
          // Cheap rejection: farther than 1 (elliptic units) from the segment's line.
          const double cross = alpha.x() * beta.y() - alpha.y() * beta.x();
          if (moving && cross * cross >= bb) continue;
          const double I = SegmentPressureIntegral(alpha, beta);
          if (I > 0.0) hs[k] += scale * I;
        }
      }
    }
  }
  std::vector<double> h(n, 0.0);
  for (size_t k = 0; k < n; ++k) h[order_[k]] = hs[k];
  return h;
}

RemovalStats ComputeRemovalStats(const std::vector<double>& removal, const std::vector<double>& area,
                                 const std::vector<char>& mask) {
  RemovalStats s;
  double w = 0, m = 0;
  s.min = 1e300;
  s.max = -1e300;
  for (size_t k = 0; k < removal.size(); ++k) {
    if (!mask.empty() && !mask[k]) continue;
    w += area[k];
    m += area[k] * removal[k];
    s.min = std::min(s.min, removal[k]);
    s.max = std::max(s.max, removal[k]);
  }
  if (!(w > 0)) return RemovalStats{};
  s.mean = m / w;
  double var = 0;
  long n = 0, covered = 0;
  for (size_t k = 0; k < removal.size(); ++k) {
    if (!mask.empty() && !mask[k]) continue;
    var += area[k] * (removal[k] - s.mean) * (removal[k] - s.mean);
    ++n;
    if (removal[k] > 0.1 * s.mean) ++covered;
    if (removal[k] < 0.01 * s.mean) s.unpolished_area += area[k];
  }
  s.variance = var / w;
  s.std = std::sqrt(s.variance);
  s.cv = s.mean > 0 ? s.std / s.mean : 0.0;
  s.peak_to_valley = s.max - s.min;
  s.coverage = n > 0 ? static_cast<double>(covered) / n : 0.0;
  return s;
}

Eigen::Isometry3d ContactFrame(const PathRow& row) {
  Eigen::Isometry3d X_PC = Eigen::Isometry3d::Identity();
  X_PC.linear().col(0) = row.tx;
  X_PC.linear().col(1) = row.n.cross(row.tx);
  X_PC.linear().col(2) = row.n;
  X_PC.translation() = row.p;
  return X_PC;
}

std::string DescribeUnpolished(const RemovalStats& stats, double region_area, const std::string& pattern) {
  if (!(stats.unpolished_area > 0.0)) return {};
  std::ostringstream m;
  m << 1e6 * stats.unpolished_area << " mm^2 of the region (" << 100 * stats.unpolished_area / region_area
    << " %) gets less than 1 % of the mean removal: gaps between rows, or necks and lobes of a trimmed face ";
  if (pattern == ToString(Pattern::kCycloid)) {
    m << "too narrow for the cycloid's circle to enter without leaving the face (a smaller radius or row "
         "spacing reaches them)";
  } else if (pattern == ToString(Pattern::kParallel)) {
    m << "that the parallel rows do not enter (a smaller row spacing, --offset-mm, or a line angle along the "
         "neck reaches them)";
  } else {
    m << "that the path does not enter (closer rows reach them)";
  }
  return m.str();
}

}  // namespace robomach::polishing
