#include "robomach/stability/tool_tip_model.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>
#include <stdexcept>
#include <string>

#include "robomach/common/units.h"

namespace robomach::stability {

Eigen::Matrix3d CuttingFrame(const Eigen::Vector3d& tool_axis_B, const Eigen::Vector3d& feed_B) {
  if (!tool_axis_B.allFinite() || !feed_B.allFinite() || tool_axis_B.norm() == 0.0 ||
      feed_B.norm() == 0.0) {
    throw std::invalid_argument("tool axis and feed direction must be finite, non-zero vectors");
  }
  const Eigen::Vector3d z = tool_axis_B.normalized();
  const Eigen::Vector3d f = feed_B.normalized();
  const Eigen::Vector3d x_raw = f - f.dot(z) * z;
  // |x_raw| = sin(angle between feed and axis); below 1e-6 the in-plane
  // direction is lost in rounding of a 1e-16 relative product.
  if (x_raw.norm() < 1e-6) {
    throw std::invalid_argument("the feed direction is parallel to the tool axis");
  }
  Eigen::Matrix3d R;
  R.col(0) = x_raw.normalized();
  R.col(2) = z;
  R.col(1) = z.cross(R.col(0));
  return R;
}

Eigen::Matrix3d CuttingFrameAtPosture(const Eigen::Isometry3d& X_BT, const Eigen::Vector3d& feed_B) {
  return CuttingFrame(-X_BT.linear().col(2), feed_B);
}

TipModalModel TipModalModel::Rotated(const Eigen::Matrix3d& R_BC) const {
  TipModalModel out = *this;
  out.p = R_BC.transpose() * p;
  return out;
}

void TipModalModel::Validate() const {
  const auto n = omega_rad_s.size();
  if (zeta.size() != n || p.cols() != n) {
    throw std::invalid_argument("modal model: frequencies, damping ratios and shapes differ in count");
  }
  if (n == 0) throw std::invalid_argument("modal model: no modes");
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!(std::isfinite(omega_rad_s(k)) && omega_rad_s(k) > 0.0)) {
      throw std::invalid_argument("modal model: mode " + std::to_string(k + 1) +
                                  ": natural frequency must be > 0");
    }
    if (!(zeta(k) >= 0.0 && zeta(k) < 1.0)) {
      throw std::invalid_argument("modal model: mode " + std::to_string(k + 1) +
                                  ": damping ratio must be in [0, 1)");
    }
    if (!p.col(k).allFinite()) {
      throw std::invalid_argument("modal model: mode " + std::to_string(k + 1) + ": shape not finite");
    }
  }
}

TipModalModel ModalModelFromPosture(const dynamics::PostureDynamics& d) {
  TipModalModel m;
  const int n = static_cast<int>(d.modes.size());
  m.omega_rad_s.resize(n);
  m.zeta.resize(n);
  m.p.resize(3, n);
  for (int k = 0; k < n; ++k) {
    m.omega_rad_s(k) = HzToRadPerSec(d.modes[k].freq_hz);
    m.zeta(k) = d.modes[k].damping_ratio;
    m.p.col(k) = d.modes[k].p_T;
  }
  return m;
}

std::vector<Eigen::Matrix3cd> ModalReceptance(const TipModalModel& m, const Eigen::VectorXd& freq_hz) {
  std::vector<Eigen::Matrix3cd> H(freq_hz.size(), Eigen::Matrix3cd::Zero());
  std::vector<Eigen::Matrix3d> pp(m.num_modes());
  for (int k = 0; k < m.num_modes(); ++k) pp[k] = m.p.col(k) * m.p.col(k).transpose();
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    const double w = HzToRadPerSec(freq_hz(i));
    for (int k = 0; k < m.num_modes(); ++k) {
      const double wk = m.omega_rad_s(k);
      const std::complex<double> g = 1.0 / std::complex<double>(wk * wk - w * w, 2.0 * m.zeta(k) * wk * w);
      H[i] += g * pp[k].cast<std::complex<double>>();
    }
  }
  return H;
}

std::vector<Eigen::Matrix2cd> InPlaneModalReceptance(const TipModalModel& m,
                                                     const Eigen::VectorXd& freq_hz) {
  // Lines innermost, in plain arrays, so the compiler vectorises the loop;
  // the 2×2 is symmetric (p pᵀ per mode), so three entries are summed. The
  // sum over the modes runs in the same order as a per-line loop would.
  const Eigen::Index L = freq_hz.size();
  const int n = m.num_modes();
  Eigen::ArrayXd w(L), w2(L);
  for (Eigen::Index i = 0; i < L; ++i) w(i) = HzToRadPerSec(freq_hz(i));
  w2 = w.square();
  Eigen::ArrayXd re_xx = Eigen::ArrayXd::Zero(L), re_xy = Eigen::ArrayXd::Zero(L), re_yy = Eigen::ArrayXd::Zero(L);
  Eigen::ArrayXd im_xx = Eigen::ArrayXd::Zero(L), im_xy = Eigen::ArrayXd::Zero(L), im_yy = Eigen::ArrayXd::Zero(L);
  for (int k = 0; k < n; ++k) {
    const double wk = m.omega_rad_s(k), wk2 = wk * wk, c = 2.0 * m.zeta(k) * wk;
    const double pxx = m.p(0, k) * m.p(0, k), pxy = m.p(0, k) * m.p(1, k), pyy = m.p(1, k) * m.p(1, k);
    const double* wp = w.data();
    const double* w2p = w2.data();
    double *rxx = re_xx.data(), *rxy = re_xy.data(), *ryy = re_yy.data();
    double *ixx = im_xx.data(), *ixy = im_xy.data(), *iyy = im_yy.data();
    for (Eigen::Index i = 0; i < L; ++i) {
      const double a = wk2 - w2p[i], b = c * wp[i], inv = 1.0 / (a * a + b * b);
      const double ra = a * inv, rb = b * inv;  // 1/(a + ib) = (a − ib)/(a² + b²)
      rxx[i] += ra * pxx;
      rxy[i] += ra * pxy;
      ryy[i] += ra * pyy;
      ixx[i] -= rb * pxx;
      ixy[i] -= rb * pxy;
      iyy[i] -= rb * pyy;
    }
  }
  std::vector<Eigen::Matrix2cd> H(L);
  for (Eigen::Index i = 0; i < L; ++i) {
    H[i](0, 0) = {re_xx(i), im_xx(i)};
    H[i](0, 1) = H[i](1, 0) = {re_xy(i), im_xy(i)};
    H[i](1, 1) = {re_yy(i), im_yy(i)};
  }
  return H;
}

std::vector<Eigen::Matrix2cd> OrientInCuttingPlane(const std::vector<Eigen::Matrix3cd>& H_B,
                                                   const Eigen::Matrix3d& R_BC) {
  std::vector<Eigen::Matrix2cd> out(H_B.size());
  const Eigen::Matrix<std::complex<double>, 3, 2> R = R_BC.leftCols<2>().cast<std::complex<double>>();
  for (size_t i = 0; i < H_B.size(); ++i) out[i] = R.transpose() * H_B[i] * R;
  return out;
}

Eigen::VectorXd LogFrequencyGrid(double f_lo_hz, double f_hi_hz, int lines) {
  if (!(f_lo_hz > 0.0 && f_hi_hz > f_lo_hz) || lines < 2) {
    throw std::invalid_argument("frequency grid: expected 0 < f_lo < f_hi and at least 2 lines");
  }
  Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(lines, std::log(f_lo_hz), std::log(f_hi_hz));
  return f.array().exp();
}

Eigen::VectorXd LobeFrequencyGrid(const TipModalModel& m, int teeth, double max_speed_rad_s,
                                  int lines) {
  m.Validate();
  const double f_lo = 0.5 * RadPerSecToHz(m.omega_rad_s.minCoeff());
  const double f_hi = std::max(1.5 * RadPerSecToHz(m.omega_rad_s.maxCoeff()),
                               1.05 * teeth * max_speed_rad_s / (2.0 * kPi));
  return LogFrequencyGrid(f_lo, std::max(f_hi, 2.0 * f_lo), lines);
}

TipModalModel DominantModes(const TipModalModel& modes_C, int count) {
  const int n = modes_C.num_modes();
  if (count >= n) return modes_C;
  std::vector<int> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  auto compliance = [&](int k) {
    return modes_C.p.col(k).head<2>().squaredNorm() / std::pow(modes_C.omega_rad_s(k), 2);
  };
  std::sort(idx.begin(), idx.end(), [&](int a, int b) { return compliance(a) > compliance(b); });
  idx.resize(std::max(0, count));
  std::sort(idx.begin(), idx.end());
  TipModalModel out;
  out.omega_rad_s.resize(idx.size());
  out.zeta.resize(idx.size());
  out.p.resize(3, idx.size());
  for (size_t j = 0; j < idx.size(); ++j) {
    out.omega_rad_s(j) = modes_C.omega_rad_s(idx[j]);
    out.zeta(j) = modes_C.zeta(idx[j]);
    out.p.col(j) = modes_C.p.col(idx[j]);
  }
  return out;
}

}  // namespace robomach::stability
