#include "dynamics/internal/taper_contact.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

#include "robomach/common/units.h"

namespace robomach::dynamics::internal {
namespace {

void Require(bool ok, const std::string& what, double value) {
  if (!ok) {
    throw std::invalid_argument("spindle-toolholder interface: " + what + ", got " +
                                std::to_string(value));
  }
}

// Euler–Bernoulli element on (w1, w1', w2, w2') [Przemieniecki 1968, §5.3].
Eigen::Matrix4d BeamElement(double EI, double l) {
  Eigen::Matrix4d k;
  k << 12, 6 * l, -12, 6 * l,
       6 * l, 4 * l * l, -6 * l, 2 * l * l,
       -12, -6 * l, 12, -6 * l,
       6 * l, 2 * l * l, -6 * l, 4 * l * l;
  return EI / (l * l * l) * k;
}

}  // namespace

Eigen::Matrix2d RingStiffness(double A, double r, double alpha, double kn, double kt) {
  const double s = std::sin(alpha), c = std::cos(alpha);
  Eigen::Matrix2d k;
  k(0, 0) = 0.5 * A * (kn * c * c + kt * s * s + kt);
  k(0, 1) = k(1, 0) = 0.5 * A * r * s * c * (kn - kt);
  k(1, 1) = 0.5 * A * r * r * (kn * s * s + kt * c * c);
  return k;
}

Eigen::Matrix4d BothPlanes(const Eigen::Matrix2d& K) {
  // DOF order [u_x, u_y, θ_x, θ_y]: x–z plane (0, 3), y–z plane (1, 2) with θ → −θ_x.
  Eigen::Matrix4d K4 = Eigen::Matrix4d::Zero();
  K4(0, 0) = K(0, 0);
  K4(0, 3) = K4(3, 0) = K(0, 1);
  K4(3, 3) = K(1, 1);
  K4(1, 1) = K(0, 0);
  K4(1, 2) = K4(2, 1) = -K(0, 1);
  K4(2, 2) = K(1, 1);
  return K4;
}

TaperContact ComputeTaperContact(const TaperContactOptions& o) {
  Require(o.elements >= 1 && o.elements <= 1000, "elements must be in [1, 1000]", o.elements);
  Require(o.friction_coefficient >= 0.0, "friction_coefficient must be >= 0", o.friction_coefficient);
  Require(o.alpha_prime > 0.0, "alpha_prime must be > 0", o.alpha_prime);
  Require(o.beta_prime >= 0.0, "beta_prime must be >= 0", o.beta_prime);
  Require(o.tangential_to_normal > 0.0, "tangential_to_normal must be > 0", o.tangential_to_normal);
  Require(o.drawbar_force_N > 0.0, "drawbar_force_N must be > 0", o.drawbar_force_N);
  Require(o.length_m > 0.0, "taper_length_m must be > 0", o.length_m);
  Require(o.taper_ratio > 0.0 && o.taper_ratio * o.length_m < o.large_diameter_m,
          "taper_ratio must be > 0 and leave a positive small diameter", o.taper_ratio);
  Require(o.shank_bore_diameter_m >= 0.0 &&
              o.shank_bore_diameter_m < o.large_diameter_m - o.taper_ratio * o.length_m,
          "shank_bore_diameter_m must be >= 0 and below the taper's small diameter",
          o.shank_bore_diameter_m);
  Require(o.shank_modulus_Pa > 0.0, "shank_modulus_Pa must be > 0", o.shank_modulus_Pa);

  TaperContact out;
  const int N = o.elements;
  const double alpha = std::atan(0.5 * o.taper_ratio);
  const double s = std::sin(alpha), c = std::cos(alpha), t = std::tan(alpha);
  const double R1 = 0.5 * o.large_diameter_m;
  const double L = o.length_m;
  const double R2 = R1 - L * t;
  out.half_angle_rad = alpha;
  out.contact_area_m2 = kPi * (R1 + R2) * L / c;
  out.pressure_Pa = o.drawbar_force_N / (out.contact_area_m2 * (s + o.friction_coefficient * c));
  out.normal_stiffness_N_per_m3 = o.alpha_prime * std::pow(out.pressure_Pa, o.beta_prime);
  out.tangential_stiffness_N_per_m3 = o.tangential_to_normal * out.normal_stiffness_N_per_m3;
  const double kn = out.normal_stiffness_N_per_m3, kt = out.tangential_stiffness_N_per_m3;

  const double h = L / N;
  out.node_depth_m.resize(N + 1);
  out.node_depth_m(0) = 0.0;
  for (int i = 1; i <= N; ++i) out.node_depth_m(i) = (i - 0.5) * h;
  auto ring = [&](int i) {  // element i = 1..N
    const double r = R1 - out.node_depth_m(i) * t;
    return RingStiffness(2.0 * kPi * r * h / c, r, alpha, kn, kt);
  };

  if (std::isinf(o.shank_modulus_Pa)) {
    out.K_plane.setZero();
    for (int i = 1; i <= N; ++i) {
      Eigen::Matrix2d T;
      T << 1.0, -out.node_depth_m(i), 0.0, 1.0;
      out.K_plane += T.transpose() * ring(i) * T;
    }
  } else {
    const int n = 2 * (N + 1);
    out.K_full.setZero(n, n);
    const Eigen::Vector4d flip(1.0, -1.0, 1.0, -1.0);  // (w, w') -> (w, θ), θ = −dw/dz
    for (int j = 0; j < N; ++j) {
      const double l = out.node_depth_m(j + 1) - out.node_depth_m(j);
      const double zm = 0.5 * (out.node_depth_m(j + 1) + out.node_depth_m(j));
      const double D = 2.0 * (R1 - zm * t), d = o.shank_bore_diameter_m;
      const double EI = o.shank_modulus_Pa * kPi / 64.0 * (std::pow(D, 4) - std::pow(d, 4));
      out.K_full.block<4, 4>(2 * j, 2 * j) +=
          flip.asDiagonal() * BeamElement(EI, l) * flip.asDiagonal();
    }
    for (int i = 1; i <= N; ++i) out.K_full.block<2, 2>(2 * i, 2 * i) += ring(i);
    // Guyan: the ring nodes are slaves, the gauge line is the master.
    const Eigen::MatrixXd Kss = out.K_full.bottomRightCorner(n - 2, n - 2);
    const Eigen::MatrixXd Ksm = out.K_full.bottomLeftCorner(n - 2, 2);
    out.K_plane = out.K_full.topLeftCorner<2, 2>() - Ksm.transpose() * Kss.llt().solve(Ksm);
    out.K_plane = 0.5 * (out.K_plane + out.K_plane.transpose()).eval();
  }
  out.K_master = BothPlanes(out.K_plane);
  return out;
}

}  // namespace robomach::dynamics::internal
