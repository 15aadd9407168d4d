#pragma once

#include <complex>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/progress.h"
#include "robomach/stability/milling.h"
#include "robomach/stability/tool_tip_model.h"
#include "robomach/stability/zoa_lobes.h"

namespace robomach::stability {

/// The piecewise-constant coefficients of step i of a periodic delay
/// differential equation
/// <pre>
///   y'(t) = A(t) y(t) + B(t) u(t − τ),   u = first n_u entries of y,     (1)
///   A(t + T) = A(t),  B(t + T) = B(t)
/// </pre>
/// on [t_i, t_{i+1}] (usually their means there). A is d×d, B is d×n_u.
using SdStepCoefficients =
    std::function<void(int step, double t0, double t1, Eigen::MatrixXd* A, Eigen::MatrixXd* B)>;

/// Result of one monodromy evaluation.
struct SdMonodromy {
  double spectral_radius{NAN};
  std::complex<double> critical_multiplier;  // the eigenvalue of largest modulus
  int dimension{0};                          // d + m n_u
};

/// First-order semi-discretization [Insperger, Stepan & Turi 2008]: the
/// period T is split into k steps Δt = T/k, the delay into m =
/// round(τ/Δt) steps; on step i the coefficients are frozen and the delayed
/// term is the linear interpolation
/// <pre>
///   u(t − τ) ≈ u_{i−m} + (t − t_i)/Δt · (u_{i−m+1} − u_{i−m}),           (2)
/// </pre>
/// so that the step is solved exactly:
/// <pre>
///   y_{i+1} = e^{A_i Δt} y_i + (Γ0 − Γ1/Δt) B_i u_{i−m} + (Γ1/Δt) B_i u_{i−m+1},
///   Γ0 = ∫₀^Δt e^{A_i(Δt−s)} ds,  Γ1 = ∫₀^Δt e^{A_i(Δt−s)} s ds          (3)
/// </pre>
/// (e^{A_i Δt}, Γ0 B_i and Γ1 B_i from one exponential of a (d + 2n_u)²
/// block matrix [Van Loan 1978]). The monodromy matrix Φ is the product of
/// the k step matrices on z_i = [y_i; u_{i−1}; …; u_{i−m}]; (1) is
/// asymptotically stable iff its spectral radius is < 1. Φ is never formed:
/// its dominant eigenvalue comes from Arnoldi's method on products Φ z
/// (O(k d (d + n_u)) each), accepted at a Ritz residual of 1e-12 relative,
/// else with a larger Krylov space, up to all of it (issue #34: 7 x faster
/// than the dense eigenvalues of Φ on a tap test's six modes, D = 396).
/// @throws std::invalid_argument if k < 1, m < 1 or sizes are inconsistent.
SdMonodromy FirstOrderSdMonodromy(int d, int n_u, double period, double delay, int steps,
                                  const SdStepCoefficients& coefficients);

/// Milling on a modal model in the cutting plane (modes.p rows x, y of C):
/// <pre>
///   η'' + 2ZΩ η' + Ω² η = −a Pᵀ H(t) P (η − η(t − τ)),   τ = 2π/(N Ω_s)
/// </pre>
/// with H(t) the 2×2 in-plane block of milling.h (2), averaged exactly over
/// each step. Returns the monodromy over one tooth period.
SdMonodromy MillingMonodromy(const TipModalModel& modes_C, const MillingProcess& process,
                             double spindle_speed_rad_s, double depth, int steps);

struct SdOptions {
  /// Steps per tooth period k. 0 (the default) chooses k per spindle speed
  /// by SdStepsPerPeriod; a positive value overrides that choice.
  int steps_per_period{0};
  /// The automatic choice: this many steps per period of the highest
  /// retained mode, at least min_steps_per_period (the fixed default before
  /// issue #10) per tooth period, and at most what keeps the monodromy
  /// matrix (dimension 2n + k n for n modes) within max_monodromy_dimension:
  /// the step matrices cost k exponentials of (2n + 2n)² blocks per depth
  /// tried (the dominant eigenvalue is found without forming the matrix),
  /// and the bound keeps that and the Krylov space of FirstOrderSdMonodromy
  /// small. The first-order method's error
  /// in the critical depth falls like (ω Δt)² [Insperger, Stepan & Turi
  /// 2008]; on the Insperger-Stepan benchmark 40 steps per mode period keep
  /// it below ~0.3 % (README, stability-lobes), where a fixed 30 steps per
  /// tooth period were 15 % off at 5000 rpm.
  double steps_per_mode_period{40.0};
  int min_steps_per_period{30};
  int max_monodromy_dimension{400};
  double max_depth{0.02};     // [m] search range of the depth
  int depth_scan_points{20};  // coarse scan of [0, max_depth] before the bracketing search
  double depth_tolerance{1e-3};  // relative width of the final bracket

  /// @throws OptionError naming the field, its value and the bound:
  /// steps_per_period >= 0 (0: automatic), steps_per_mode_period finite
  /// > 0, min_steps_per_period >= 1, max_monodromy_dimension >= 1 (the
  /// automatic choice's terms), max_depth finite > 0, depth_scan_points
  /// >= 1 (the scan of [0, max_depth] in that many steps), depth_tolerance
  /// finite > 0 (the search stops at a bracket that narrow; 0 would never
  /// stop).
  void Validate() const;
};

/// The steps per tooth period SdCriticalDepth uses at one spindle speed:
/// options.steps_per_period if positive, otherwise
/// <pre>
///   k = max(min_steps_per_period, min(ceil(steps_per_mode_period · f_max · τ), k_max)),
///   k_max = (max_monodromy_dimension − 2n) / n
/// </pre>
/// with f_max the highest natural frequency of the n retained modes [Hz]
/// and τ = 2π/(N Ω) the tooth period. `capped`, if not null, is set when
/// k_max was hit (the result is then less accurate than intended).
int SdStepsPerPeriod(const TipModalModel& modes_C, const MillingProcess& process, double spindle_speed_rad_s,
                     const SdOptions& options, bool* capped = nullptr);

/// The smallest depth with spectral radius 1 at one spindle speed: a
/// coarse scan of [0, max_depth] for the first unstable depth, then a
/// bracketing search (Illinois regula falsi with bisection as a safeguard)
/// down to depth_tolerance. Unstable islands narrower than max_depth/depth_scan_points can
/// be missed. The steps per tooth period are SdStepsPerPeriod's, returned
/// in LobePoint::sd_steps. The chatter frequency is the member of the family
/// (±arg μ + 2πj)/τ closest to a natural frequency of the model.
LobePoint SdCriticalDepth(const TipModalModel& modes_C, const MillingProcess& process,
                          double spindle_speed_rad_s, const SdOptions& options = {});

/// SdCriticalDepth for each speed, in parallel on `threads` threads (0 = all
/// cores); `progress` (may be empty) is called from the calling thread only.
std::vector<LobePoint> SdLobes(const TipModalModel& modes_C, const MillingProcess& process,
                               const Eigen::VectorXd& spindle_speed_rad_s, const SdOptions& options,
                               int threads = 0, const ProgressCallback& progress = {});

/// - [Insperger, Stepan & Turi 2008] T. Insperger, G. Stepan, J. Turi, On the
///   higher-order semi-discretizations for periodic delayed systems, J. Sound
///   Vib. 313:334-341, 2008.
/// - [Insperger & Stepan 2004] see milling.h.
/// - [Van Loan 1978] C. F. Van Loan, Computing integrals involving the matrix
///   exponential, IEEE Trans. Automatic Control 23(3):395-404, 1978.

}  // namespace robomach::stability
