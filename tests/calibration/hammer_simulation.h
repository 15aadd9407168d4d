#pragma once

// Impact-hammer records of a known 3-DOF mass-spring-damper chain, made by
// time integration, independent of the FFT code under test:
//
//   ground -k1,c1- m1 -k2,c2- m2 -k3,c3- m3,   force on m1.
//
// The state z = [x; v] obeys ż = A z + B f(t). Each fine step h is the
// exact solution for a force linear between samples (first-order hold),
// from one matrix exponential of the augmented system
//   d/dt [z; u; u̇] = [A z + B u; u̇; 0]
// [Franklin, Powell & Workman 1998, ch. 6]. The force is a half-sine pulse
// evaluated at the fine samples. The fine signals (force, displacement of
// m1, acceleration of m3) go through one anti-aliasing FIR filter, the same
// for every channel as in a data-acquisition system, and are decimated;
// the common filter cancels in the FRF ratio. Sensor noise is added at the
// output rate.
//
// The linear-between-samples force differs from the half-sine by the
// first-order-hold factor sinc²(ωh/2) ≈ 1 − (ωh)²/12 in its spectrum: with
// h = 1/(16 fs) this is 0.2 % at fs/2.56, the top of the compared band.
//
// - [Franklin, Powell & Workman 1998] G. F. Franklin, J. D. Powell,
//   M. Workman, Digital Control of Dynamic Systems, 3rd ed., 1998.

#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include "robomach/calibration/frf_estimate.h"
#include "robomach/common/units.h"

namespace robomach::testing {

struct ThreeDofChain {
  Eigen::Matrix3d M, C, K;

  static ThreeDofChain Default() {
    ThreeDofChain s;
    const double m1 = 2.0, m2 = 1.5, m3 = 1.0;            // [kg]
    const double k1 = 4e5, k2 = 6e5, k3 = 5e5;            // [N/m]
    const double c1 = 150.0, c2 = 100.0, c3 = 60.0;       // [N·s/m], not proportional
    s.M = Eigen::Vector3d(m1, m2, m3).asDiagonal();
    s.K << k1 + k2, -k2, 0, -k2, k2 + k3, -k3, 0, -k3, k3;
    s.C << c1 + c2, -c2, 0, -c2, c2 + c3, -c3, 0, -c3, c3;
    return s;
  }

  /// Receptance H(ω) = (K − ω²M + iωC)⁻¹ [m/N], evaluated at s = iω + a:
  /// a = 1/τ gives the FRF of h(t) e^{−t/τ} (the exponential window).
  Eigen::Matrix3cd Receptance(double f_hz, double a = 0.0) const {
    const std::complex<double> s(a, HzToRadPerSec(f_hz));
    const Eigen::Matrix3cd Z = M.cast<std::complex<double>>() * (s * s) + C.cast<std::complex<double>>() * s +
                               K.cast<std::complex<double>>();
    return Z.inverse();
  }
  /// Accelerance s² H [(m/s²)/N] at s = iω + a.
  Eigen::Matrix3cd Accelerance(double f_hz, double a = 0.0) const {
    const std::complex<double> s(a, HzToRadPerSec(f_hz));
    return Receptance(f_hz, a) * (s * s);
  }
  /// Natural frequencies [Hz] and damping ratios of the state matrix's
  /// eigenvalues λ (upper half-plane), ascending.
  std::vector<std::pair<double, double>> Modes() const {
    Eigen::Matrix<double, 6, 6> A = StateMatrix();
    Eigen::EigenSolver<Eigen::Matrix<double, 6, 6>> es(A);
    std::vector<std::pair<double, double>> out;
    for (int i = 0; i < 6; ++i) {
      const std::complex<double> l = es.eigenvalues()(i);
      if (l.imag() > 0) out.push_back({std::abs(l) / (2 * kPi), -l.real() / std::abs(l)});
    }
    std::sort(out.begin(), out.end());
    return out;
  }
  Eigen::Matrix<double, 6, 6> StateMatrix() const {
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    const Eigen::Matrix3d Mi = M.inverse();
    A.topRightCorner<3, 3>().setIdentity();
    A.bottomLeftCorner<3, 3>() = -Mi * K;
    A.bottomRightCorner<3, 3>() = -Mi * C;
    return A;
  }
};

struct HitSpec {
  double peak_N{200.0};
  double pulse_s{0.0006};       // half-sine duration
  double start_s{0.02};         // pre-trigger
  double second_peak_N{0.0};    // > 0: a double hit
  double second_delay_s{0.0};   // after the first pulse's start
};

struct AcquisitionSpec {
  double fs_hz{4096.0};
  int samples{4096};
  int oversample{16};
  // Sensor noise over the band, rms: a force transducer's 0.05 N, a
  // capacitive probe's 2 nm, an ICP accelerometer's 1 mg.
  double force_noise_N{0.05};
  double disp_noise_m{2e-9};
  double acc_noise_m_per_s2{0.01};
  double acc_clip_m_per_s2{0.0};        // > 0: the accelerometer clips here
};

/// Channels: 0 displacement of m1 [m] (drive point), 1 acceleration of m3
/// [m/s²] (transfer).
inline std::vector<calibration::ResponseChannel> SimulatedChannels() {
  return {{"x1", calibration::ResponseQuantity::kDisplacement},
          {"a3", calibration::ResponseQuantity::kAcceleration}};
}

class HammerSimulator {
 public:
  HammerSimulator(const ThreeDofChain& sys, const AcquisitionSpec& acq) : sys_(sys), acq_(acq) {
    const double h = 1.0 / (acq.fs_hz * acq.oversample);
    Eigen::Matrix<double, 8, 8> Aug = Eigen::Matrix<double, 8, 8>::Zero();
    Aug.topLeftCorner<6, 6>() = sys.StateMatrix();
    Eigen::Matrix<double, 6, 1> B = Eigen::Matrix<double, 6, 1>::Zero();
    B.tail<3>() = sys.M.inverse().col(0);
    Aug.block<6, 1>(0, 6) = B;
    Aug(6, 7) = 1.0;
    const Eigen::Matrix<double, 8, 8> E = (Aug * h).exp();
    phi_ = E.topLeftCorner<6, 6>();
    g0_ = E.block<6, 1>(0, 6);
    g1_ = E.block<6, 1>(0, 7) / h;
    b_ = B;
    // Windowed-sinc low-pass (Blackman), cutoff 0.45 fs, 32 taps per
    // output sample: transition ≈ 5.5/L of the fine rate ≈ 0.17 fs, stop
    // band from ≈ 0.54 fs (74 dB), so nothing above 0.61 fs folds into the
    // band below fs/2.56.
    const int L = 32 * acq.oversample + 1, mid = L / 2;
    const double fc = 0.45 / acq.oversample;  // cycles per fine sample
    fir_.resize(L);
    for (int i = 0; i < L; ++i) {
      const double t = i - mid;
      const double sinc = t == 0 ? 2 * fc : std::sin(2 * kPi * fc * t) / (kPi * t);
      const double w = 0.42 - 0.5 * std::cos(2 * kPi * i / (L - 1)) + 0.08 * std::cos(4 * kPi * i / (L - 1));
      fir_[i] = sinc * w;
    }
    double s = 0;
    for (double v : fir_) s += v;
    for (double& v : fir_) v /= s;
  }

  calibration::ImpactRecord Simulate(const HitSpec& hit, std::mt19937* rng, const std::string& id) const {
    const int R = acq_.oversample, L = static_cast<int>(fir_.size()), mid = L / 2;
    const int fine = acq_.samples * R + L;
    const double h = 1.0 / (acq_.fs_hz * R);
    std::vector<double> f(fine), x1(fine), a3(fine);
    const auto force = [&](double t) {
      double v = 0.0;
      if (t >= hit.start_s && t <= hit.start_s + hit.pulse_s) v += hit.peak_N * std::sin(kPi * (t - hit.start_s) / hit.pulse_s);
      const double t2 = hit.start_s + hit.second_delay_s;
      if (hit.second_peak_N > 0 && t >= t2 && t <= t2 + hit.pulse_s) v += hit.second_peak_N * std::sin(kPi * (t - t2) / hit.pulse_s);
      return v;
    };
    Eigen::Matrix<double, 6, 1> z = Eigen::Matrix<double, 6, 1>::Zero();
    const Eigen::Matrix<double, 6, 6> A = sys_.StateMatrix();
    for (int i = 0; i < fine; ++i) {
      f[i] = force(i * h);
      x1[i] = z(0);
      a3[i] = (A * z + b_ * f[i])(5);
      const double fn = force((i + 1) * h);
      z = phi_ * z + g0_ * f[i] + g1_ * (fn - f[i]);
    }
    std::normal_distribution<double> n01(0.0, 1.0);
    calibration::ImpactRecord rec;
    rec.id = id;
    rec.source = "simulated hit " + id;
    rec.sample_rate_hz = acq_.fs_hz;
    rec.force_N.resize(acq_.samples);
    rec.response.resize(acq_.samples, 2);
    for (int k = 0; k < acq_.samples; ++k) {
      double sf = 0, sx = 0, sa = 0;
      for (int j = 0; j < L; ++j) {
        const int i = k * R + j - mid;
        if (i < 0) continue;  // at rest before t = 0
        sf += fir_[j] * f[i];
        sx += fir_[j] * x1[i];
        sa += fir_[j] * a3[i];
      }
      rec.force_N(k) = sf + acq_.force_noise_N * n01(*rng);
      rec.response(k, 0) = sx + acq_.disp_noise_m * n01(*rng);
      double a = sa + acq_.acc_noise_m_per_s2 * n01(*rng);
      if (acq_.acc_clip_m_per_s2 > 0) a = std::clamp(a, -acq_.acc_clip_m_per_s2, acq_.acc_clip_m_per_s2);
      rec.response(k, 1) = a;
    }
    return rec;
  }

 private:
  ThreeDofChain sys_;
  AcquisitionSpec acq_;
  Eigen::Matrix<double, 6, 6> phi_;
  Eigen::Matrix<double, 6, 1> g0_, g1_, b_;
  std::vector<double> fir_;
};

}  // namespace robomach::testing
