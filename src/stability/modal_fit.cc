#include "robomach/stability/modal_fit.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "robomach/common/units.h"

namespace robomach::stability {

TipModalModel FitModesPeakPicking(const Eigen::VectorXd& freq_hz,
                                  const std::vector<Eigen::Matrix2cd>& Phi_C, int max_modes) {
  const Eigen::Index n = freq_hz.size();
  if (static_cast<size_t>(n) != Phi_C.size() || n < 3) {
    throw std::invalid_argument("modal fit: need at least 3 lines and one FRF per line");
  }
  Eigen::VectorXd s(n);
  for (Eigen::Index i = 0; i < n; ++i) s(i) = std::abs(Phi_C[i](0, 0).imag()) + std::abs(Phi_C[i](1, 1).imag());
  const double s_max = s.maxCoeff();
  std::vector<Eigen::Index> peaks;
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    if (s(i) > s(i - 1) && s(i) >= s(i + 1) && s(i) > 0.05 * s_max && freq_hz(i) > 0.0) peaks.push_back(i);
  }
  std::sort(peaks.begin(), peaks.end(), [&](auto a, auto b) { return s(a) > s(b); });
  if (static_cast<int>(peaks.size()) > max_modes) peaks.resize(std::max(0, max_modes));
  std::sort(peaks.begin(), peaks.end());

  std::vector<double> w, z;
  std::vector<Eigen::Vector3d> p;
  for (Eigen::Index i : peaks) {
    const int d = std::abs(Phi_C[i](0, 0)) >= std::abs(Phi_C[i](1, 1)) ? 0 : 1;
    const double level = std::abs(Phi_C[i](d, d)) / std::sqrt(2.0);
    // Half-power points, linearly interpolated in frequency.
    auto cross = [&](int dir) -> double {
      for (Eigen::Index j = i; j + dir >= 0 && j + dir < n; j += dir) {
        const double a = std::abs(Phi_C[j](d, d)), b = std::abs(Phi_C[j + dir](d, d));
        if (b < level) return freq_hz(j) + (a - level) / (a - b) * (freq_hz(j + dir) - freq_hz(j));
      }
      return NAN;
    };
    const double f1 = cross(-1), f2 = cross(+1);
    if (!std::isfinite(f1) || !std::isfinite(f2)) continue;  // peak at the edge of the band
    const double wk = HzToRadPerSec(freq_hz(i));
    const double zk = (f2 - f1) / (2.0 * freq_hz(i));
    Eigen::Matrix2d R = -2.0 * zk * wk * wk * Phi_C[i].imag();
    R = 0.5 * (R + R.transpose()).eval();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(R);
    const double lam = es.eigenvalues()(1);
    if (!(lam > 0.0)) continue;
    Eigen::Vector3d pk = Eigen::Vector3d::Zero();
    pk.head<2>() = std::sqrt(lam) * es.eigenvectors().col(1);
    w.push_back(wk);
    z.push_back(zk);
    p.push_back(pk);
  }
  TipModalModel m;
  m.omega_rad_s = Eigen::Map<Eigen::VectorXd>(w.data(), w.size());
  m.zeta = Eigen::Map<Eigen::VectorXd>(z.data(), z.size());
  m.p.resize(3, p.size());
  for (size_t k = 0; k < p.size(); ++k) m.p.col(k) = p[k];
  return m;
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
