#pragma once

// Modal parameter estimation from one measured FRF: peak picking with
// half-power damping (a quick estimate), and a least-squares complex
// frequency-domain (LSCF) pole fit with a stabilisation check across model
// orders, followed by a least-squares fit of the residues (LSFD).

#include <complex>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/solver_status.h"
#include "robomach/dynamics/measured_frf.h"

namespace robomach::calibration {

// ------------------------------------------------------------ peak picking --

struct PeakPickOptions {
  /// A peak must reach this fraction of the largest |H| in the FRF, in [0, 1].
  double min_relative_height{0.05};
  /// A peak must be the largest |H| within ± this many lines, >= 1.
  int half_window_lines{3};

  /// @throws OptionError naming the field, its value and the bound
  ///   ("min_relative_height: expected a value in [0, 1], got 2").
  void Validate() const;
};

/// One resonance found by peak picking.
struct PeakEstimate {
  double peak_freq_hz{0.0};    // frequency of the |H| maximum (parabolic interpolation) [Hz]
  double peak_magnitude{0.0};  // |H| at the peak line [m/N]
  /// Half-power estimate ζ ≈ (f2 − f1) / (2 f_peak), with f1, f2 where |H|²
  /// falls to half its peak value (linear interpolation of |H|² between
  /// lines) [Ewins 2000, §4.3]. Its relative error is O(ζ) for a receptance
  /// and grows when neighbouring modes overlap. NaN if neither side reaches
  /// half power; one-sided (doubled) if only one does.
  double damping_ratio{NAN};
  bool two_sided{false};
};

/// Local maxima of |H|, ascending in frequency.
std::vector<PeakEstimate> PickPeaks(const dynamics::Frf& frf, const PeakPickOptions& options = {});

// -------------------------------------------------------------- LSCF fit --

struct ModalFitOptions {
  /// Band to fit [Hz]; the default is the whole FRF.
  double fmin_hz{0.0};
  double fmax_hz{std::numeric_limits<double>::infinity()};
  /// Orders of the common-denominator polynomial (number of poles, physical
  /// and conjugate) tried in the stabilisation diagram.
  int min_order{2};
  int max_order{32};
  /// A pole is stable at order n if order n − 1 has a pole within these
  /// relative differences of frequency and damping ratio.
  double stable_freq_tol{0.01};
  double stable_damping_tol{0.10};
  /// A selected mode must have been stable over this many consecutive orders
  /// (the poles are taken from the one of the five highest orders that has
  /// the most such poles).
  int min_stable_orders{5};
  /// Physical poles: 0 < ζ < max_damping_ratio.
  double max_damping_ratio{0.3};
  /// A selected mode's peak contribution |A| / (2 ζ ω_n²) must reach this
  /// fraction of the measured |H| at its natural frequency; smaller ones are
  /// discarded as computational (they model noise, not structure). The
  /// comparison is local, not with the largest peak: with relative weights a
  /// weak high-frequency mode shapes the FRF where it lies and must be kept.
  double min_relative_contribution{0.005};
  /// At most this many modes are added where the refined fit's residual is
  /// structured rather than noise (see FitModes).
  int max_added_modes{4};

  /// The bounds: 0 <= fmin_hz < fmax_hz (fmax_hz may be inf); min_order
  /// >= 1 and max_order >= min_order (a band with too few lines for the
  /// orders is the data's, a status of the fit); stable_freq_tol and
  /// stable_damping_tol > 0; min_stable_orders >= 1; max_damping_ratio in
  /// (0, 1]; min_relative_contribution >= 0; max_added_modes >= 0.
  /// @throws OptionError naming the field, its value and the bound.
  void Validate() const;
};

/// One identified mode of a single FRF H_re, with the pole λ and residue R
/// of H(ω) = Σ [R / (iω − λ) + R* / (iω − λ*)] + residual terms.
struct FittedMode {
  double freq_hz{0.0};          // undamped natural frequency |λ| / 2π [Hz]
  double damping_ratio{0.0};    // −Re λ / |λ|
  std::complex<double> pole;    // λ [rad/s]
  std::complex<double> residue; // R [m/N · rad/s]
  /// Modal constant A = 2i ω_d R [m/N · (rad/s)²] with ω_d = Im λ: for
  /// proportional damping A is real and equals p_r p_e of the mass-normalised
  /// mode, as in H = Σ A / (ω_n² − ω² + 2iζω_nω) [Ewins 2000, §2.3].
  std::complex<double> modal_constant;
  /// |A| / (2ζω_n²): the mode's own peak receptance [m/N].
  double peak_contribution{0.0};
  /// Consecutive orders (ending at max_order) over which the pole was stable.
  int stable_orders{0};
};

/// One pole of the stabilisation diagram.
struct StabilisationPole {
  int order{0};
  double freq_hz{0.0};
  double damping_ratio{0.0};
  bool stable{false};  // matched a pole of order − 1 within the tolerances
};


struct ModalFitResult {
  SolverStatus status{SolverStatus::kFailed};
  std::string message;
  std::vector<FittedMode> modes;       // ascending frequency
  std::complex<double> upper_residual{0.0};  // constant term [m/N]
  std::complex<double> lower_residual{0.0};  // coefficient of 1/(iω)² [m/N · (rad/s)²]
  /// Coefficient of (iω)² [m/N · s²]: the curvature of the modes above the
  /// band (Σ A_r/(ω_r² − ω²) ≈ Σ A_r/ω_r² + ω² Σ A_r/ω_r⁴). The global fit
  /// (global_modal_fit.h) uses it; FitModes leaves it 0.
  std::complex<double> upper_residual_slope{0.0};
  /// Fit-quality figure: sqrt(Σ|H_fit − H|² / Σ|H|²) over the band.
  double relative_rms_error{NAN};
  double fmin_hz{0.0}, fmax_hz{0.0};
  int order_used{0};                   // LSCF order the poles were taken from
  std::vector<StabilisationPole> stabilisation;

  /// The fitted receptance at one frequency [m/N].
  std::complex<double> Evaluate(double freq_hz) const;
  /// The maximum of |H_fit| within [f_lo, f_hi]: a grid search refined by
  /// golden-section search. Returns {frequency [Hz], |H| [m/N]}.
  std::pair<double, double> PeakIn(double f_lo_hz, double f_hi_hz) const;
};

/// Fits poles by LSCF [Guillaume et al. 2003] on the z-domain basis
/// Ω_j(ω) = exp(iωΔt j), Δt = 1 / (2 f_max), unweighted: the linearised
/// equation error N(ω) − H(ω) D(ω) is minimised in least squares with the last
/// denominator coefficient fixed to 1, through the reduced normal equations
/// (T − Sᵀ R⁻¹ S) a = 0. R, S, T are Toeplitz in the basis index, so they are
/// formed once for max_order in O(N max_order) and every lower order uses
/// their leading blocks. Poles λ = ln(z)/Δt of each order feed the
/// stabilisation diagram; the stable physical poles are kept, and their
/// residues, an upper residual and (if the band starts above 20 % of the
/// lowest mode) a lower residual are found by linear least squares (LSFD)
/// with weights 1/|H|. Finally poles, residues and residuals are refined
/// together by Levenberg–Marquardt on the same weighted error (the
/// maximum-likelihood fit for noise proportional to |H|), which removes the
/// bias of the linearised LSCF estimate. This is done for the stable pole
/// sets of the five highest orders and the best fit is kept. Where its
/// weighted residual is still structured (local mean square above four times
/// the median), a pole is added there and kept if the Bayesian information
/// criterion 2N ln F + p ln 2N improves (F the weighted squared error, p the
/// number of real parameters); then the weakest modes are dropped while that
/// lowers the criterion, and poles closer than a fifth of their half-power
/// bandwidth are merged. If no pole is stable over min_stable_orders, the
/// peaks of |H| (PickPeaks, half-power damping) start the same refinement,
/// so that a clear resonance in noisy data still gives its mode. All weights
/// are those of ModalFitWeights (1/σ with a noise model, else 1/|H|).
/// Numerical trouble is a status, not an exception.
///
/// - [Guillaume et al. 2003] P. Guillaume, P. Verboven, S. Vanlanduit,
///   H. Van der Auweraer, B. Peeters, A poly-reference implementation of the
///   least-squares complex frequency-domain estimator, Proc. IMAC XXI, 2003.
/// - [Ewins 2000] D. J. Ewins, Modal Testing: Theory, Practice and
///   Application, 2nd ed., Research Studies Press, 2000.
ModalFitResult FitModes(const dynamics::Frf& frf, const ModalFitOptions& options = {});

/// The weights of the modal fit's complex residuals: 1/σ per line when the
/// FRF carries a noise model (Frf::noise_sigma, the maximum-likelihood
/// weights for that noise), else 1/|H| (noise proportional to |H|).
Eigen::VectorXd ModalFitWeights(const dynamics::Frf& frf);

/// Residues (and residual terms) for given poles by weighted linear least
/// squares; fills modes, residuals and the error of `result`. Exposed for
/// tests and for callers that fix the poles.
void FitResidues(const dynamics::Frf& frf, const std::vector<std::complex<double>>& poles,
                 bool lower_residual, ModalFitResult* result);

}  // namespace robomach::calibration
