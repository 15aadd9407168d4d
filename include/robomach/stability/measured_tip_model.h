#pragma once

// The tool-tip modal model of a measured FRF for the semi-discretization
// (issue #18): the noise model and usable band of issue #10
// (calibration/frf_noise.h) and the stabilised modal fit
// (calibration/modal_fit.h) of each direct FRF, turned into the real modes
// of tool_tip_model.h. One modal fitter serves the calibration and the
// stability lobes.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/stability/tool_tip_model.h"

namespace robomach::stability {

struct DirectFrfFitOptions {
  /// The noise model of the measured FRF; the wide floor is on, since a
  /// measured tool-tip FRF is typically a tap test whose integrated
  /// accelerometer drifts below ~100 Hz (see NoiseOptions::wide_floor).
  calibration::NoiseOptions noise = [] {
    calibration::NoiseOptions n;
    n.wide_floor = true;
    return n;
  }();
  calibration::ModalFitOptions fit;
  /// The fit is flagged poor when its residual on the usable lines, in
  /// units of the noise σ (rms of |H_fit − H| / σ, 1 for a perfect model),
  /// exceeds this. 3: a model within the noise gives 1 ± a few percent on
  /// thousands of lines, and a missed mode or an unmodelled drift pushes
  /// the rms far above 3 in the band where it lies.
  double max_noise_rms{3.0};
  /// See DirectFrfFit::active_fraction. 0.05: with the 2σ threshold, noise
  /// alone puts about 2 % of the lines of a lightly damped receptance above
  /// it (Im H ≈ 0 only far from the modes; P(N(0,1) > 2) = 2.3 %).
  double max_active_fraction{0.05};

  /// @throws OptionError naming the field, its value and the bound:
  /// max_active_fraction in [0, 1] (a fraction of lines), max_noise_rms
  /// finite >= 1 (1 is a perfect model), and the nested noise.* and fit.*
  /// fields (calibration::NoiseOptions::Validate,
  /// calibration::ModalFitOptions::Validate, field prefixed).
  void Validate() const;
};

/// One direct FRF, its noise model and its modal fit.
struct DirectFrfFit {
  dynamics::Frf measured;        // all lines as given
  calibration::FrfNoise noise;   // per line of `measured`
  calibration::ModalFitResult fit;  // on the usable lines
  /// rms of |H_fit − H| / σ over the usable lines (1: within the noise).
  double noise_rms{NAN};
  /// No mode, a failed fit, or noise_rms above the option's limit.
  bool poor{true};
  /// For people, when poor: what went wrong.
  std::string problem;
  /// Fraction of the usable lines where Im H > 2σ. A driving-point
  /// receptance of a passive structure has Im H(ω) ≤ 0 at every ω > 0 (the
  /// power it absorbs, ½ω|F|² (−Im H), is not negative) [Ewins 2000, §2.3],
  /// so more than `max_active_fraction` of such lines means the FRF is not
  /// one: response and excitation at different points (a transfer FRF), in
  /// opposite directions, or another sign convention. Neither the SD's modes
  /// nor the ZOA's lobes from it describe a tool tip then.
  double active_fraction{0.0};
  bool not_driving_point{false};
  /// Fitted modes whose half-power band f (1 ± ζ) reaches below the lowest
  /// usable line or above the highest: the fit saw only one flank, so the
  /// mode may model the drift or the floor beyond the band rather than the
  /// structure [Hz].
  std::vector<double> edge_modes_hz;
};

/// The noise model (EstimateFrfNoise), then FitModes on the usable lines
/// with their σ (the drift of an integrated accelerometer signal and the
/// floor are outside that band). Numerical trouble is in the result
/// (`poor`, `problem`), not an exception.
/// @throws OptionError for bad options (DirectFrfFitOptions::Validate);
///   std::invalid_argument for an FRF of fewer than 8 lines.
DirectFrfFit FitDirectFrf(const dynamics::Frf& measured, const DirectFrfFitOptions& options = {});

/// The real modes of a direct (driving-point) FRF H_aa, as tool-tip modes
/// along the unit direction `e` (in whatever frame e is given).
///
/// For proportionally damped real modes [Ewins 2000, §2.3]
///     H_ab(ω) = Σ_r φ_ar φ_br / (ω_r² − ω² + 2iζ_r ω_r ω),
/// φ_r the mass-normalised mode shape [1/√kg]. A direct FRF therefore has
/// the modal constants A_r = φ_ar² (FittedMode::modal_constant, real for
/// proportional damping), i.e. a modal mass 1/A_r and a modal stiffness
/// ω_r²/A_r seen at the tool tip along a, and the mode's tool-tip shape
/// p_r = φ_ar e = √A_r e of (1) in tool_tip_model.h reproduces H_aa
/// exactly. Only Re A enters: its imaginary part is the non-proportional
/// damping or the noise the fit absorbed, not a shape. A mode with
/// Re A ≤ 0 cannot belong to a driving point (it would be a negative mass)
/// and is left out, with its frequency in `dropped_hz`. The fit's residual
/// terms are not modes and are left out too: the upper residual is the
/// static compliance of modes above the band, which shifts the level but
/// not the dynamics the semi-discretization needs, and the lower residual
/// stands for rigid-body or lower modes outside the band.
/// Modes in one direction give no cross FRF: a model built from the direct
/// FRFs of two directions has H_xy = 0, as the ZOA assumes when the file
/// has no cross FRF.
TipModalModel ModesAlong(const calibration::ModalFitResult& fit, const Eigen::Vector3d& e,
                         std::vector<double>* dropped_hz = nullptr);

/// The modes of two direct FRFs H_aa and H_bb (fits `fit_a`, `fit_b`) with
/// their cross FRF H_ab, along the orthogonal unit directions e_a, e_b: a
/// mode found in both direct FRFs (natural frequencies within a fifth of
/// the half-power bandwidth 2ζf of each other) is one mode of shape
/// p = √A_aa e_a ± √A_bb e_b, the sign that of the cross FRF's modal
/// constant A_ab = φ_a φ_b at that pole (a linear least-squares fit of the
/// cross FRF's residues with the poles fixed, FitResidues, on `cross`'s
/// lines); a mode found in one direction only stays along it. Without the
/// cross FRF the sign, and so the coupling, is unknown: use ModesAlong for
/// each direction (H_ab = 0). The frequency and damping of a shared mode
/// are the means of the two fits'.
TipModalModel ModesOfTwoDirections(const calibration::ModalFitResult& fit_a, const Eigen::Vector3d& e_a,
                                   const calibration::ModalFitResult& fit_b, const Eigen::Vector3d& e_b,
                                   const dynamics::Frf& cross, std::vector<double>* dropped_hz = nullptr);

/// Concatenates the modes of several models (same frame).
TipModalModel Concatenate(const std::vector<TipModalModel>& models);

}  // namespace robomach::stability
