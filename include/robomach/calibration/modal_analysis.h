#pragma once

// Modal analysis of measured FRFs, posture by posture (frf-modes' work,
// issue #34 §3): the FRFs of one posture share their poles and are fitted
// together (global_modal_fit.h) on the lines every one of them can use (the
// noise models' usable bands); from the residues of the direct FRFs comes
// the tool-tip modal model of formats.md §4 (modal mass and unit shape), the
// table stability-lobes --modal-table reads.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/global_modal_fit.h"
#include "robomach/dynamics/measured_frf.h"

namespace robomach::calibration {

struct ModalAnalysisOptions {
  GlobalModalFitOptions fit;
  /// Fit each FRF alone (its own poles) instead of one set of poles per
  /// posture.
  bool per_frf{false};
  /// Weights of the fit: false (the default) the noise model's 1/σ (the
  /// maximum-likelihood fit for the noise measured, a fit to within the
  /// noise over the whole band); true every line of the FRF in the file's
  /// quantity alike (receptance, mobility or accelerance: the unweighted
  /// least squares of modal software, which the relative misfit measures
  /// and which favours the peaks). See
  /// GlobalModalFitOptions::uniform_weights_power.
  bool weights_in_file_quantity{false};
  /// With the noise's weights: a fit that leaves more than twice the noise
  /// on an FRF is made again with a model error white in the file's
  /// quantity added to σ (GlobalModalFitOptions::model_error_power).
  bool model_error{true};
  /// A posture's FRFs are fitted together only if at least this many lines
  /// are usable in all of them; else each alone, with a warning. >= 0.
  int min_common_lines{40};

  /// fit valid (GlobalModalFitOptions::Validate, its fields named
  /// "fit.max_order", ...); min_common_lines >= 0.
  /// @throws OptionError naming the field, its value and the bound.
  void Validate() const;
};

/// One tool-tip mode of a posture from the direct FRFs' modal constants:
/// A_dd = u_d² / m for each measured direction d, so 1/m = Σ_d A_dd and
/// u_d = sqrt(A_dd m), the signs of the cross FRFs' A_de giving the relative
/// signs (formats.md §4: modal_mass_kg and a unit shape ux, uy, uz).
struct TipMode {
  double freq_hz{0.0};
  double damping_ratio{0.0};
  double modal_mass_kg{NAN};    // NaN if no direct FRF has a positive A_dd
  Eigen::Vector3d shape{Eigen::Vector3d::Zero()};  // unit, in the FRFs' frame
  /// Directions that entered (a subset of "xyz"): the mass is that of the
  /// mode as seen in those directions only.
  std::string directions;
};

/// One fit: the FRFs of a posture fitted together (or one FRF alone).
struct ModalGroup {
  std::string pose_id;
  std::vector<dynamics::FrfKey> keys;  // the FRFs, in the order of fit.per_frf
  std::vector<dynamics::Frf> data;     // the lines fitted, with σ when a noise model was given
  GlobalModalFitResult fit;
  /// Per FRF: the relative rms misfit in the file's quantity (receptance,
  /// mobility or accelerance: see file_power).
  std::vector<double> misfit;
};

struct PoseModes {
  std::string pose_id;
  std::vector<ModalGroup> groups;  // one per posture, or one per FRF with per_frf
  std::vector<TipMode> tip_modes;  // from the first group (ascending frequency)
  std::vector<std::string> warnings;
};

/// The modal analysis of every posture of `measured` (all lines),
/// `noise` its noise models (may be empty: every line, weights 1/|H|).
/// `file_power` is the power of iω of the file's quantity (0 receptance,
/// 1 mobility, 2 accelerance), used for the misfit only.
std::vector<PoseModes> AnalyseModes(const dynamics::FrfSet& measured, const NoiseModels& noise,
                                    const ModalAnalysisOptions& options = {}, int file_power = 0);

/// The mode shapes of a roving test from one fit (issue #34 §2): the FRFs
/// share one fixed end (the response point and direction of a roving-hammer
/// test, the excitation's of a roving sensor) and the other end roves over
/// the points. The shape at a point is its FRF's modal constant A_j, scaled
/// by 1/sqrt(A_dd) of the driving-point FRF (fixed end = roving end), if the
/// test has one: φ_j = A_j/sqrt(A_dd), mass-normalised [1/sqrt(kg)], as
/// A_j = φ_fixed φ_j. Without a driving point the largest component is 1.
struct RovingShapes {
  std::string roving;   // "excitation" (roving hammer) or "response" (roving sensor)
  int fixed_point{0};
  Axis fixed_direction{Axis::kX};
  std::vector<int> points;        // the roving end of each FRF (rows of shapes)
  std::vector<Axis> directions;   // its direction
  Eigen::MatrixXcd shapes;        // rows: the fit's FRFs, columns: modes
  bool mass_normalised{false};    // false: unit-normalised (largest component 1)
};

/// The shapes of `group` if it is a roving test (several FRFs with one end
/// in common); otherwise nullopt with the reason in `why`.
std::optional<RovingShapes> ShapesOfRovingTest(const ModalGroup& group, std::string* why = nullptr);

/// The shapes of one fit of a posture that is a roving test.
struct FitRovingShapes {
  size_t pose{0};  // index in the postures
  size_t fit{0};   // index in that posture's groups
  RovingShapes shapes;
};

/// The shapes of every converged fit of `poses` that is a roving test
/// (ShapesOfRovingTest), posture by posture and fit by fit: frf-modes'
/// --shapes. A converged fit that is no roving test adds "posture P, fit N:
/// no mode shapes: why" (N from 1) to `notes`.
std::vector<FitRovingShapes> ShapesOfRovingTests(const std::vector<PoseModes>& poses,
                                                 std::vector<std::string>* notes = nullptr);

/// The tool-tip modes from one fit's direct and cross FRFs (see TipMode).
/// With point numbers, only the FRFs between the driving point's point and
/// itself enter (the tool tip of a roving test is its driving point).
std::vector<TipMode> TipModes(const ModalGroup& group, std::vector<std::string>* warnings = nullptr);

}  // namespace robomach::calibration
