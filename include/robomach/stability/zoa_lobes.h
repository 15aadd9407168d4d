#pragma once

#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/stability/milling.h"

namespace robomach::stability {

/// How a point of a lobe diagram came out.
enum class LobeStatus {
  kOk,             // a stability boundary was found
  kNotCovered,     // no lobe of the frequency grid reaches this speed (widen the grid)
  kStableUpToMax,  // SD: stable for every depth up to the maximum searched
  kUnstableAtZero, // SD: unstable without cutting (a non-physical model)
};
const char* ToString(LobeStatus s);
/// The inverse of ToString. @throws std::invalid_argument naming the four.
LobeStatus ParseLobeStatus(const std::string& name);

/// One point of the stability boundary.
struct LobePoint {
  double spindle_speed_rad_s{0.0};
  double critical_depth{NAN};   // axial depth of cut a_lim [m]
  double chatter_freq_hz{NAN};  // [Hz]
  int lobe_index{-1};           // full vibration waves between two teeth, k
  LobeStatus status{LobeStatus::kNotCovered};
  int sd_steps{0};              // semi-discretization only: steps per tooth period used
};

/// One lobe (one eigenvalue branch and one lobe index k) traced over the
/// chatter frequencies of the grid where it exists.
struct LobeCurve {
  int lobe_index{0};
  int branch{0};
  std::vector<double> chatter_freq_hz;
  std::vector<double> spindle_speed_rad_s;
  std::vector<double> critical_depth;  // [m]
};

struct ZoaOptions {
  int max_lobe_index{30};  // lobes k = 0..max_lobe_index are traced
  /// If > 0, lobes that cannot reach this speed within the grid are skipped:
  /// lobe k chatters above k N Ω / 2π, so k < f_max 2π / (N Ω_min).
  double min_spindle_speed_rad_s{0.0};

  /// @throws OptionError naming the field, its value and the bound:
  /// max_lobe_index >= 0 (a lobe index k counts waves between two teeth),
  /// min_spindle_speed_rad_s >= 0 (0: no speed to reach; a NaN is refused).
  void Validate() const;
};

/// The zero-order (Altintas-Budak) lobes.
///
/// With the oriented FRF Φ_C(ω) (2×2, in-plane, cutting frame) and the
/// average directional matrix H0 (milling.h (3), upper 2×2 block), the
/// regenerative loop F = −a H0 (1 − e^{−iωτ}) x, x = Φ F has a
/// non-trivial solution when
/// <pre>
///   det(I + a (1 − e^{−iωτ}) Φ_C(ω) H0) = 0                              (1)
/// </pre>
/// [Altintas & Budak 1995]. For each eigenvalue λ of Φ_C H0,
/// Λ = −1/λ = a (1 − e^{−iωτ}) must be real-positive-scaled, which gives
/// <pre>
///   a_lim = |Λ|² / (2 Re Λ),   ωτ = 2θ + 2πk,  θ = atan2(Re Λ, Im Λ)     (2)
/// </pre>
/// for Re Λ > 0 ((2) is Altintas-Budak's a_lim = −2π Λ_R (1+κ²)/(N K_t)
/// with their Λ scaled by N K_t / 4π), and the spindle speed Ω = 2π/(N τ).
class ZoaLobes {
 public:
  /// Every lobe k = 0..max of both branches (built on request).
  std::vector<LobeCurve> curves() const;
  /// The lowest boundary over all curves at each speed [rad/s] (linear
  /// interpolation between grid lines); kNotCovered where no curve reaches.
  std::vector<LobePoint> At(const Eigen::VectorXd& spindle_speed_rad_s) const;
  /// At() for one speed.
  LobePoint At(double spindle_speed_rad_s) const;

 private:
  friend ZoaLobes ComputeZoaLobes(const Eigen::VectorXd&, const std::vector<Eigen::Matrix2cd>&,
                                  const MillingProcess&, const ZoaOptions&);
  // Per eigenvalue branch and frequency line: a_lim [m] (NaN where
  // Re Λ <= 0), θ, and 2πω/N, so that lobe k has Ω = (2πω/N)/(2θ + 2πk).
  struct Branch {
    std::vector<double> depth, theta, speed_numerator;
  };
  Eigen::VectorXd freq_hz_;
  Branch branch_[2];
  int max_lobe_index_{0};
};

/// Traces (2) on the grid `freq_hz` (strictly increasing, > 0) of the
/// oriented FRF `Phi_C` [m/N].
/// @throws std::invalid_argument if sizes differ, the grid is not
///   increasing or the process is invalid; OptionError for bad options
///   (ZoaOptions::Validate).
ZoaLobes ComputeZoaLobes(const Eigen::VectorXd& freq_hz, const std::vector<Eigen::Matrix2cd>& Phi_C,
                         const MillingProcess& process, const ZoaOptions& options = {});

/// - [Altintas & Budak 1995] Y. Altintas, E. Budak, Analytical prediction of
///   stability lobes in milling, CIRP Annals 44(1):357-362, 1995.

}  // namespace robomach::stability
