#pragma once

// Modal parameter estimation of several FRFs that share their poles (the
// directions of one posture, the points of a roving-hammer or roving-sensor
// test, the direct and cross FRFs of a tap test): one set of poles for all,
// residues per FRF, and from them the mode shapes (issue #34 §1-2).
//
// The single-FRF fit (FitModes, modal_fit.h) stays the fit of one curve;
// this is the fit modal software calls "global" or "poly-reference".

#include <complex>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/calibration/modal_fit.h"
#include "robomach/dynamics/measured_frf.h"

namespace robomach::calibration {

struct GlobalModalFitOptions {
  /// Band to fit [Hz]; the default is the whole of the FRFs.
  double fmin_hz{0.0};
  double fmax_hz{std::numeric_limits<double>::infinity()};
  /// Orders of the common denominator (number of poles, physical and
  /// conjugate) of the stabilisation diagram. Capped at a third of the
  /// lines in the band.
  int min_order{4};
  int max_order{100};
  /// A pole is stable at order n if order n − 1 has a pole within these
  /// relative differences of frequency and damping ratio.
  double stable_freq_tol{0.01};
  double stable_damping_tol{0.05};
  /// Stable poles within this relative frequency of a cluster's mean join
  /// it; a cluster is a mode if it holds stable poles of at least
  /// max(min_stable_orders, min_cluster_fraction × orders tried) orders.
  double cluster_freq_tol{0.005};
  int min_stable_orders{5};
  double min_cluster_fraction{0.2};
  /// Physical poles: 0 < ζ < max_damping_ratio.
  double max_damping_ratio{0.3};
  /// A mode is kept if in at least one FRF its peak contribution reaches
  /// this fraction of the measured |H| at its frequency.
  double min_relative_contribution{0.005};
  /// Refine the poles (common to all FRFs) by Levenberg–Marquardt on the
  /// weighted residuals of all FRFs, residues eliminated (variable
  /// projection).
  bool refine{true};
  /// At most this many modes added where the residual of the FRFs together
  /// is structured rather than noise; kept if the BIC falls.
  int max_added_modes{4};
  /// Weights of the residues and the refinement: −1 (default) those of
  /// ModalFitWeights, 1/σ with a noise model (the maximum-likelihood fit for
  /// the noise measured), else 1/|H|; p = 0, 1, 2: every line of the
  /// receptance, mobility or accelerance alike (each FRF scaled to unit
  /// rms), the least-squares fit of that quantity without weights, as
  /// modal software does, which favours the peaks.
  int uniform_weights_power{-1};
  /// A dense FRF (more than `dense_modes` clusters of stable poles over the
  /// band) is fitted band by band: the clusters are split into groups of at
  /// most `max_modes_per_band` at the gaps between them, each group fitted
  /// (LSCF, clustering, refinement, BIC) on its own band widened to its
  /// neighbour modes, the modes of each band's core kept, and the residues
  /// of all modes fitted over the whole band. Modal software leaves the
  /// bands to the user. On dataset58 (about 30 modes, 21 clusters at order
  /// 100) one band placed the 81.5 Hz mode at 80.1 Hz (the clusters of the
  /// lowest modes were too short to count at that order); bands of 4-8
  /// modes all put its five named peaks within 0.5 % in frf-modes, 5 with
  /// the smallest misfit (0.079 relative, 0.093 in one band) and 8 missing
  /// two by 0.5-0.75 % on all lines. The banded fit has no refinement over
  /// the whole band (tried: it raised the misfit), so it is less exact than
  /// one band where one band resolves the modes: on clean model FRFs of the
  /// KR210 (6-12 modes) bands of 5 left 0.4 % misfit against 1e-4; hence
  /// the threshold of 12 (order 100 holds 50 poles, about four per mode with
  /// the noise poles). max_modes_per_band 0: never.
  int dense_modes{12};
  int max_modes_per_band{5};
  /// Index of the driving-point FRF (response = reference) among the FRFs,
  /// or −1: with it the mode shapes are mass-normalised
  /// (φ_j = A_j / sqrt(A_driving)); without it they are unit-normalised.
  int driving_point{-1};
  /// Model error. With the noise model's weights (uniform_weights_power
  /// −1), a fit that leaves more than `model_error_ratio` times the noise
  /// on an FRF (misfit_in_noise) is missing something the noise does not
  /// explain: a mode outside the band, the leakage of a peak one line wide,
  /// a nonlinearity. Such model error is not the measurement's and is not
  /// relative to |H|, so 1/σ weights (σ mostly relative at the peaks) put
  /// the fit's error where |H| is large, and the fit misses the peaks by
  /// several percent. With model_error_power p >= 0 the fit estimates a
  /// model error τ per FRF, white in (iω)^p H (p = 0, 1, 2: receptance,
  /// mobility, accelerance; the file's quantity), chosen so that the misfit
  /// in units of sqrt(σ² + τ²/ω^2p) equals its degrees of freedom (the
  /// random-effects estimate of meta-analysis, Paule and Mandel 1982), and
  /// fits again with those weights: between the noise's weights (τ = 0)
  /// and modal software's unweighted least squares (τ ≫ σ). −1: off.
  /// pyuff's beam (2.4 noise units on FRFs 2 and 3 with the noise's
  /// weights alone): relative misfit 0.045 / 0.062 / 0.050 to 0.034 /
  /// 0.048 / 0.034 (docs/testing.md).
  int model_error_power{-1};
  double model_error_ratio{2.0};
  /// A band that starts below a fifth of the lowest mode gets a lower
  /// residual (1/ω² in the receptance: the mass line of a free or
  /// soft-mounted structure, or modes below the band) only if the Bayesian
  /// information criterion falls with it; above a fifth it always has one.
  bool lower_residual_by_bic{true};

  /// The bounds: 0 <= fmin_hz < fmax_hz (fmax_hz may be inf); min_order >=
  /// 2 and max_order >= min_order + 2 (the diagram's fewest orders; a band
  /// with too few lines for them is the data's, a status of the fit);
  /// stable_freq_tol, stable_damping_tol and cluster_freq_tol > 0;
  /// min_stable_orders >= 1; min_cluster_fraction in [0, 1];
  /// max_damping_ratio in (0, 1]; min_relative_contribution >= 0;
  /// max_added_modes, dense_modes and max_modes_per_band >= 0;
  /// uniform_weights_power and model_error_power in [-1, 2]; driving_point
  /// >= -1; model_error_ratio > 0.
  /// @throws OptionError naming the field, its value and the bound.
  void Validate() const;
};

/// One mode of the global fit.
struct GlobalMode {
  double freq_hz{0.0};        // undamped natural frequency |λ| / 2π [Hz]
  double damping_ratio{0.0};  // −Re λ / |λ|
  std::complex<double> pole;  // λ [rad/s]
  /// Number of orders of the stabilisation diagram in the pole's cluster
  /// (0 for a pole added from the residual).
  int stable_orders{0};
};

struct GlobalModalFitResult {
  SolverStatus status{SolverStatus::kFailed};
  std::string message;
  std::vector<GlobalMode> modes;  // ascending frequency
  /// Per FRF, in the order given: the modes with the common poles and the
  /// FRF's own residues (FittedMode::modal_constant), its residual terms and
  /// relative_rms_error. per_frf[i].modes[r] is mode r of `modes`.
  std::vector<ModalFitResult> per_frf;
  /// Per FRF: sqrt(mean |H_fit − H|² / σ²) over the band when the FRF
  /// carries a noise model (Frf::noise_sigma), else NaN. About 1 when the
  /// model explains the data to within the noise.
  std::vector<double> misfit_in_noise;
  /// Per FRF: the model error τ the weights included (see
  /// GlobalModalFitOptions::model_error_power), in the quantity
  /// `model_error_power` names ([m/N]·(rad/s)^p), 0 when the fit was within
  /// model_error_ratio of the noise or the option was off.
  std::vector<double> model_error;
  /// The power p of the model error's quantity when a refit with it was
  /// taken, else −1 (also when the option was on and every FRF was within
  /// model_error_ratio of its noise).
  int model_error_power{-1};
  /// Per FRF: misfit_in_noise of the fit with the noise's weights alone (the
  /// first pass, which decides the model error and is how well a modal
  /// model explains the data); equal to misfit_in_noise when no refit was
  /// taken. The refit trades misfit in noise units for the peaks.
  std::vector<double> misfit_in_noise_weights_alone;
  /// Power p of iω the LSCF stage multiplied the receptances by (0, 1 or 2:
  /// receptance, mobility or accelerance), the one with the flattest
  /// magnitude; the poles do not depend on it.
  int lscf_power{0};
  int min_order{0}, max_order{0};  // orders of the stabilisation diagram
  int orders_tried{0};
  /// Bands the fit was made in (1 unless the FRFs were dense: see
  /// GlobalModalFitOptions::max_modes_per_band).
  int bands{1};
  double fmin_hz{0.0}, fmax_hz{0.0};
  std::vector<StabilisationPole> stabilisation;

  /// Modal constants A (rows: FRFs, columns: modes) [m/N · (rad/s)²].
  Eigen::MatrixXcd ModalConstants() const;
  /// Mode shapes (rows: FRFs = points, columns: modes). With a driving
  /// point, mass-normalised φ_j = A_j / sqrt(A_dd) [1/sqrt(kg)]; else each
  /// column is scaled so that its largest component is 1 (real, positive).
  Eigen::MatrixXcd ModeShapes(int driving_point = -1) const;
};

/// Fits common poles to `frfs` (which must share their frequency lines in
/// the band): a common-denominator LSCF [Guillaume et al. 2003] on the
/// stacked FRFs, each scaled to unit rms and multiplied by (iω)^p with p the
/// power that makes the data flattest, through the reduced normal equations
/// Σ_o (T_o − S_oᵀ R⁻¹ S_o) a = 0 (numerator coefficients eliminated, so the
/// cost per order is that of one (n+1)² system per FRF). The poles of each
/// order form the stabilisation diagram; stable poles are clustered across
/// orders (frequency within cluster_freq_tol) and a cluster that spans
/// enough orders is a mode, its pole the median of the cluster. Residues
/// per FRF (LSFD with ModalFitWeights: 1/σ with a noise model, else 1/|H|),
/// then the poles are refined together on the weighted residuals of every
/// FRF (residues eliminated), weak or redundant modes are dropped and modes
/// are added where the residual is structured, both judged by the Bayesian
/// information criterion of all FRFs together. Numerical trouble is a
/// status, not an exception.
/// @throws std::invalid_argument if `frfs` is empty or the FRFs' lines in
///   the band differ.
GlobalModalFitResult FitModesGlobal(const std::vector<dynamics::Frf>& frfs,
                                    const GlobalModalFitOptions& options = {});

/// One FRF through the global fitter (the fit frf-modes makes), as a
/// ModalFitResult with its stabilisation diagram: what the tools that take
/// one FRF at a time use (stability-lobes --frf). From `options` it takes
/// the band, max_damping_ratio, min_relative_contribution and
/// max_added_modes; the orders are the global fit's (to 100).
ModalFitResult FitOneFrf(const dynamics::Frf& frf, const ModalFitOptions& options = {});

/// Modal assurance criterion between the columns of two shape matrices
/// (same number of rows): MAC_ij = |a_iᴴ b_j|² / ((a_iᴴ a_i)(b_jᴴ b_j)),
/// in [0, 1]; 1 for shapes that are multiples of each other.
/// @throws std::invalid_argument if the row counts differ.
Eigen::MatrixXd ModalAssuranceCriterion(const Eigen::MatrixXcd& a, const Eigen::MatrixXcd& b);

/// Relative rms misfit of a fit on an FRF in the quantity (iω)^p H
/// (p = 0 receptance, 1 mobility, 2 accelerance):
/// sqrt(Σ |(iω)^p (H_fit − H)|² / Σ |(iω)^p H|²) over the FRF's lines.
double RelativeMisfit(const ModalFitResult& fit, const dynamics::Frf& frf, int power = 0);

}  // namespace robomach::calibration
