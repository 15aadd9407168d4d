#include "robomach/stability/zoa_lobes.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "robomach/common/enum_names.h"
#include "stability/internal/batch_atan2.h"

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

LobeStatus ParseLobeStatus(const std::string& name) {
  constexpr LobeStatus kAll[] = {LobeStatus::kOk, LobeStatus::kNotCovered, LobeStatus::kStableUpToMax,
                                 LobeStatus::kUnstableAtZero};
  return ParseByName("lobe status", name, kAll);
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

double Norm2(double re, double im) { return re * re + im * im; }

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

void ZoaOptions::Validate() const {
  CheckOptionAtLeast("max_lobe_index", max_lobe_index, 0);
  CheckOptionAtLeast("min_spindle_speed_rad_s", min_spindle_speed_rad_s, 0.0);
}

ZoaLobes ComputeZoaLobes(const Eigen::VectorXd& freq_hz, const std::vector<Eigen::Matrix2cd>& Phi_C,
                         const MillingProcess& process, const ZoaOptions& options) {
  process.Validate();
  options.Validate();
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
  // 1. The eigenvalues λ of Φ H₀ per line (H₀ real: 8 products per line),
  //    each branch followed by continuity with the previous line.
  const Eigen::Index L = freq_hz.size();
  std::vector<double> re[2], im[2];
  for (int b = 0; b < 2; ++b) {
    re[b].resize(L);
    im[b].resize(L);
  }
  // In plain doubles, line by line without branches (the compiler
  // vectorises it); a line whose discriminant is outside the safe range of
  // PrincipalSqrt is redone by Eigenvalues2 afterwards.
  const double h00 = H0(0, 0).real(), h01 = H0(0, 1).real(), h10 = H0(1, 0).real(), h11 = H0(1, 1).real();
  const double* P = reinterpret_cast<const double*>(Phi_C.data());  // column-major (re, im) pairs, 8 per line
  std::vector<char> redo(L);
  for (Eigen::Index i = 0; i < L; ++i) {
    const double* p = P + 8 * i;
    // Φ = [p00 p01; p10 p11] (column-major: p00, p10, p01, p11), A = Φ H₀.
    const double p00r = p[0], p00i = p[1], p10r = p[2], p10i = p[3], p01r = p[4], p01i = p[5], p11r = p[6],
                 p11i = p[7];
    const double a00r = p00r * h00 + p01r * h10, a00i = p00i * h00 + p01i * h10;
    const double a01r = p00r * h01 + p01r * h11, a01i = p00i * h01 + p01i * h11;
    const double a10r = p10r * h00 + p11r * h10, a10i = p10i * h00 + p11i * h10;
    const double a11r = p10r * h01 + p11r * h11, a11i = p10i * h01 + p11i * h11;
    const double htr = 0.5 * (a00r + a11r), hti = 0.5 * (a00i + a11i);
    const double detr = (a00r * a11r - a00i * a11i) - (a01r * a10r - a01i * a10i);
    const double deti = (a00r * a11i + a00i * a11r) - (a01r * a10i + a01i * a10r);
    const double zr = (htr * htr - hti * hti) - detr, zi = 2.0 * htr * hti - deti;
    // PrincipalSqrt, branch-free.
    const double r2 = zr * zr + zi * zi;
    redo[i] = !(r2 > 1e-300 && r2 < 1e300);
    const double t = std::sqrt(0.5 * (std::abs(zr) + std::sqrt(r2)));
    const double t_safe = t > 0.0 ? t : 1.0;
    const double dr = zr >= 0.0 ? t : 0.5 * std::abs(zi) / t_safe;
    const double di = zr >= 0.0 ? 0.5 * zi / t_safe : std::copysign(t, zi);
    double l1r = htr + dr, l1i = hti + di, l2r = htr - dr, l2i = hti - di;
    const bool swap = l2r * l2r + l2i * l2i > l1r * l1r + l1i * l1i;
    const double s1r = swap ? l2r : l1r, s1i = swap ? l2i : l1i;
    l1r = s1r;
    l1i = s1i;
    // The smaller root as det/l1 (no cancellation): det·conj(l1)/|l1|².
    const double n1 = l1r * l1r + l1i * l1i;
    const double inv = n1 > 0.0 ? 1.0 / n1 : 0.0;
    const double q2r = (detr * l1r + deti * l1i) * inv, q2i = (deti * l1r - detr * l1i) * inv;
    re[0][i] = l1r;
    im[0][i] = l1i;
    re[1][i] = n1 > 0.0 ? q2r : (swap ? htr + dr : l2r);
    im[1][i] = n1 > 0.0 ? q2i : (swap ? hti + di : l2i);
  }
  for (Eigen::Index i = 0; i < L; ++i) {
    if (!redo[i]) continue;
    Eigen::Matrix2cd A;
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 2; ++c) A(r, c) = Phi_C[i](r, 0) * H0(0, c).real() + Phi_C[i](r, 1) * H0(1, c).real();
    }
    const auto [l1, l2] = Eigenvalues2(A);
    re[0][i] = l1.real();
    im[0][i] = l1.imag();
    re[1][i] = l2.real();
    im[1][i] = l2.imag();
  }
  // Each branch followed by continuity with the previous line.
  for (Eigen::Index i = 1; i < L; ++i) {
    const double d12 = Norm2(re[0][i] - re[1][i - 1], im[0][i] - im[1][i - 1]) +
                       Norm2(re[1][i] - re[0][i - 1], im[1][i] - im[0][i - 1]);
    const double d11 = Norm2(re[0][i] - re[0][i - 1], im[0][i] - im[0][i - 1]) +
                       Norm2(re[1][i] - re[1][i - 1], im[1][i] - im[1][i - 1]);
    if (d12 < d11) {
      std::swap(re[0][i], re[1][i]);
      std::swap(im[0][i], im[1][i]);
    }
  }
  // 2. Per branch and line: with L = −1/λ, a_lim = |L|²/(2 Re L) and
  //    θ = atan2(Re L, Im L) where Re L > 0. Since −1/λ = −λ̄/|λ|², Re L > 0
  //    is Re λ < 0, a_lim = −1/(2 Re λ) and θ = atan2(−Re λ, Im λ) (a
  //    positive factor does not change atan2). The phases in one batch
  //    (BatchAtan2: glibc's vector atan2 where it is available).
  for (int b = 0; b < 2; ++b) {
    auto& br = out.branch_[b];
    std::vector<double> y(L), x(L);
    for (Eigen::Index i = 0; i < L; ++i) {
      const bool ok = re[b][i] < 0.0;
      br.depth[i] = ok ? -0.5 / re[b][i] : NAN;
      y[i] = ok ? -re[b][i] : 1.0;  // a dummy where there is no boundary
      x[i] = ok ? im[b][i] : 1.0;
    }
    internal::BatchAtan2(y.data(), x.data(), br.theta.data(), L);
    for (Eigen::Index i = 0; i < L; ++i) {
      if (!(re[b][i] < 0.0)) br.theta[i] = NAN;
      br.speed_numerator[i] = 2.0 * kPi * HzToRadPerSec(freq_hz(i)) / N;  // Ω = this / (2θ + 2πk)
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
  if (n == 0) return out;
  // The speeds in ascending order (a map passes the same sorted grid at
  // every point: no sort then).
  std::vector<Eigen::Index> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (!std::is_sorted(speeds.data(), speeds.data() + n)) {
    std::sort(order.begin(), order.end(), [&](auto a, auto b) { return speeds(a) < speeds(b); });
  }
  std::vector<double> sorted(n);
  for (Eigen::Index j = 0; j < n; ++j) sorted[j] = speeds(order[j]);
  const double s_lo = sorted.front(), s_hi = sorted.back();

  // Lobe k at line i lies at Ω = num_i/(2θ_i + 2πk) with θ_i in (0, π], so
  // within [num_i/(2π(k + 1)), num_i/(2πk)]; num_i = speed_numerator[i]
  // grows with i. The lines of lobe k wholly below s_lo or above s_hi
  // cannot give a point and are not visited (a relative margin of 1e-9
  // covers the rounding of θ, of the sum and of the division, ~1e-16): the
  // result is the same as visiting them (stability_map_test.cc checks it
  // against a plain scan of every curve). The speeds of one lobe's lines are
  // computed in one loop (no branches: vectorised divisions), then scanned.
  constexpr double kMargin = 1e-9;
  std::vector<double> speed;
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
      // Segments (i, i + 1) for i < i_end: the first line beyond num_above
      // starts no segment, as in a scan that stops there.
      const size_t i_end = static_cast<size_t>(
          std::upper_bound(br.speed_numerator.begin() + std::min(i0, m), br.speed_numerator.end(), num_above) -
          br.speed_numerator.begin());
      if (i_end <= i0 || i0 + 1 >= m) continue;
      const size_t last = std::min(i_end, m - 1);  // the segments' upper lines reach `last`
      speed.resize(last - i0 + 1);
      const double* num = br.speed_numerator.data();
      const double* th = br.theta.data();
      for (size_t i = i0; i <= last; ++i) speed[i - i0] = num[i] / (2.0 * th[i] + two_pi_k);  // NaN: no boundary
      // The first sorted speed >= lo, found by walking from the previous
      // segment's (neighbouring segments have neighbouring speeds): the
      // same index as std::lower_bound, in a step or two instead of eight.
      size_t pos = 0;
      for (size_t i = i0; i < last && i + 1 < m; ++i) {
        const double sa = speed[i - i0], sb = speed[i + 1 - i0];
        if (!std::isfinite(sa) || !std::isfinite(sb)) continue;
        const double lo = std::min(sa, sb), hi = std::max(sa, sb);
        if (hi < s_lo || lo > s_hi) continue;
        while (pos > 0 && sorted[pos - 1] >= lo) --pos;
        while (pos < sorted.size() && sorted[pos] < lo) ++pos;
        for (auto it = sorted.begin() + static_cast<std::ptrdiff_t>(pos); it != sorted.end() && *it <= hi; ++it) {
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
