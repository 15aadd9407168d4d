#include "robomach/stability/zoa_lobes.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "robomach/common/units.h"

namespace robomach::stability {

const char* ToString(LobeStatus s) {
  switch (s) {
    case LobeStatus::kOk: return "ok";
    case LobeStatus::kNotCovered: return "not_covered";
    case LobeStatus::kStableUpToMax: return "stable_up_to_max";
    case LobeStatus::kUnstableAtZero: return "unstable_at_zero";
  }
  return "?";
}

namespace {

using cd = std::complex<double>;

// The principal square root (Re ≥ 0, the branch of std::sqrt) by the
// textbook formula t = √((|x| + |z|)/2), without the special-value handling
// of libm's csqrt (which calls hypot: 7 % of a stability map). Falls back to
// std::sqrt where x² + y² could overflow or underflow (|z| outside
// 1e-150..1e150; ZOA's discriminants are near 1e-16..1e-4) or is not finite.
cd PrincipalSqrt(const cd& z) {
  const double x = z.real(), y = z.imag();
  const double r2 = x * x + y * y;
  if (!(r2 > 1e-300 && r2 < 1e300)) return std::sqrt(z);
  const double t = std::sqrt(0.5 * (std::abs(x) + std::sqrt(r2)));
  return x >= 0.0 ? cd(t, 0.5 * y / t) : cd(0.5 * std::abs(y) / t, std::copysign(t, y));
}

// Eigenvalues of a 2×2 complex matrix from its trace and determinant.
std::pair<cd, cd> Eigenvalues2(const Eigen::Matrix2cd& A) {
  const cd half_tr = 0.5 * (A(0, 0) + A(1, 1));
  const cd det = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  const cd disc = PrincipalSqrt(half_tr * half_tr - det);
  cd l1 = half_tr + disc, l2 = half_tr - disc;
  // Avoid cancellation in the smaller root: l1 l2 = det.
  if (std::norm(l2) > std::norm(l1)) std::swap(l1, l2);
  if (std::norm(l1) > 0.0) l2 = det * std::conj(l1) / std::norm(l1);
  return {l1, l2};
}

}  // namespace

ZoaLobes ComputeZoaLobes(const Eigen::VectorXd& freq_hz, const std::vector<Eigen::Matrix2cd>& Phi_C,
                         const MillingProcess& process, const ZoaOptions& options) {
  process.Validate();
  if (static_cast<size_t>(freq_hz.size()) != Phi_C.size() || freq_hz.size() < 2) {
    throw std::invalid_argument("ZOA lobes: need at least 2 frequency lines and one FRF per line");
  }
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    if (!(freq_hz(i) > 0.0) || (i > 0 && !(freq_hz(i) > freq_hz(i - 1)))) {
      throw std::invalid_argument("ZOA lobes: frequencies must be > 0 and strictly increasing");
    }
  }
  const Eigen::Matrix2cd H0 = AverageDirectionalMatrix(process).topRows<2>().cast<cd>();
  int K = std::max(0, options.max_lobe_index);
  if (options.min_spindle_speed_rad_s > 0.0) {
    const double f_tooth_min = process.teeth * options.min_spindle_speed_rad_s / (2.0 * kPi);
    K = std::min(K, static_cast<int>(std::ceil(freq_hz(freq_hz.size() - 1) / f_tooth_min)));
  }
  const int N = process.teeth;

  ZoaLobes out;
  out.freq_hz_ = freq_hz;
  out.max_lobe_index_ = K;
  for (auto& br : out.branch_) {
    br.depth.resize(freq_hz.size());
    br.theta.resize(freq_hz.size());
    br.speed_numerator.resize(freq_hz.size());
  }
  cd prev1, prev2;
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    auto [l1, l2] = Eigenvalues2(Phi_C[i] * H0);
    // Follow each branch by continuity with the previous line.
    if (i > 0 && std::norm(l1 - prev2) + std::norm(l2 - prev1) <
                     std::norm(l1 - prev1) + std::norm(l2 - prev2)) {
      std::swap(l1, l2);
    }
    prev1 = l1;
    prev2 = l2;
    const double w = HzToRadPerSec(freq_hz(i));
    const cd lam[2] = {l1, l2};
    for (int b = 0; b < 2; ++b) {
      double depth = NAN, theta = NAN;
      const double n2 = std::norm(lam[b]);
      if (n2 > 0.0) {
        const cd L = -std::conj(lam[b]) / n2;  // −1/λ without a library complex division
        if (L.real() > 0.0) {
          depth = std::norm(L) / (2.0 * L.real());
          theta = std::atan2(L.real(), L.imag());  // in (0, π)
        }
      }
      out.branch_[b].depth[i] = depth;
      out.branch_[b].theta[i] = theta;
      out.branch_[b].speed_numerator[i] = 2.0 * kPi * w / N;  // Ω = this / (2θ + 2πk)
    }
  }
  return out;
}

std::vector<LobeCurve> ZoaLobes::curves() const {
  std::vector<LobeCurve> out;
  for (int b = 0; b < 2; ++b) {
    const Branch& br = branch_[b];
    for (int k = 0; k <= max_lobe_index_; ++k) {
      LobeCurve c;
      c.lobe_index = k;
      c.branch = b;
      for (Eigen::Index i = 0; i < freq_hz_.size(); ++i) {
        c.chatter_freq_hz.push_back(freq_hz_(i));
        c.critical_depth.push_back(br.depth[i]);
        c.spindle_speed_rad_s.push_back(std::isfinite(br.depth[i])
                                            ? br.speed_numerator[i] / (2.0 * br.theta[i] + 2.0 * kPi * k)
                                            : NAN);
      }
      out.push_back(std::move(c));
    }
  }
  return out;
}

std::vector<LobePoint> ZoaLobes::At(const Eigen::VectorXd& speeds) const {
  const Eigen::Index n = speeds.size();
  std::vector<LobePoint> out(n);
  for (Eigen::Index j = 0; j < n; ++j) out[j].spindle_speed_rad_s = speeds(j);
  std::vector<Eigen::Index> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return speeds(a) < speeds(b); });
  std::vector<double> sorted(n);
  for (Eigen::Index j = 0; j < n; ++j) sorted[j] = speeds(order[j]);
  if (n == 0) return out;
  const double s_lo = sorted.front(), s_hi = sorted.back();

  // Lobe k at line i lies at Ω = num_i/(2θ_i + 2πk) with θ_i in (0, π], so
  // within [num_i/(2π(k + 1)), num_i/(2πk)]; num_i = speed_numerator[i]
  // grows with i. The lines of lobe k wholly below s_lo or above s_hi
  // cannot give a point and are not visited (a relative margin of 1e-9
  // covers the rounding of θ, of the sum and of the division, ~1e-16): the
  // result is the same as visiting them (stability_map_test.cc checks it
  // against a plain scan of every curve).
  constexpr double kMargin = 1e-9;
  for (const Branch& br : branch_) {
    const size_t m = br.depth.size();
    for (int k = 0; k <= max_lobe_index_; ++k) {
      const double two_pi_k = 2.0 * kPi * k;
      const double num_above = 2.0 * kPi * (k + 1) * s_hi * (1.0 + kMargin);  // beyond: Ω > s_hi
      size_t i0 = 0;
      if (k > 0) {
        // The first segment whose upper line can reach s_lo.
        const double num_below = two_pi_k * s_lo * (1.0 - kMargin);
        const size_t j = static_cast<size_t>(
            std::lower_bound(br.speed_numerator.begin(), br.speed_numerator.end(), num_below) -
            br.speed_numerator.begin());
        i0 = j > 0 ? j - 1 : 0;
      }
      double sb = NAN;
      for (size_t i = i0; i + 1 < m; ++i) {
        if (br.speed_numerator[i] > num_above) break;
        const double sa = i == 0 || !std::isfinite(sb) ? br.speed_numerator[i] / (2.0 * br.theta[i] + two_pi_k) : sb;
        sb = br.speed_numerator[i + 1] / (2.0 * br.theta[i + 1] + two_pi_k);  // NaN where no boundary
        if (!std::isfinite(sa) || !std::isfinite(sb)) continue;
        const double lo = std::min(sa, sb), hi = std::max(sa, sb);
        if (hi < s_lo || lo > s_hi) continue;
        auto it = std::lower_bound(sorted.begin(), sorted.end(), lo);
        for (; it != sorted.end() && *it <= hi; ++it) {
          const double s = *it;
          const double t = hi > lo ? (s - sa) / (sb - sa) : 0.0;
          const double depth = br.depth[i] + t * (br.depth[i + 1] - br.depth[i]);
          LobePoint& p = out[order[it - sorted.begin()]];
          if (p.status != LobeStatus::kOk || depth < p.critical_depth) {
            p.critical_depth = depth;
            p.chatter_freq_hz = freq_hz_(i) + t * (freq_hz_(i + 1) - freq_hz_(i));
            p.lobe_index = k;
            p.status = LobeStatus::kOk;
          }
        }
      }
    }
  }
  return out;
}

LobePoint ZoaLobes::At(double spindle_speed_rad_s) const {
  Eigen::VectorXd s(1);
  s(0) = spindle_speed_rad_s;
  return At(s)[0];
}

}  // namespace robomach::stability
