#pragma once

#include <vector>

#include <Eigen/Core>

#include "robomach/common/eigen_types.h"
#include "robomach/dynamics/posture_dynamics.h"

namespace robomach::stability {

/// Rotation R_BC of the cutting frame C in the base frame B (columns x_C, y_C,
/// z_C): z_C is the tool axis pointing from the tool tip into the spindle,
/// x_C the feed direction projected onto the plane normal to z_C, y_C = z_C × x_C.
/// @param tool_axis_B tool axis from tip to spindle, in B (any length > 0).
/// @param feed_B feed direction in B; its component along the tool axis is dropped.
/// @throws std::invalid_argument if the feed is (nearly, within 1e-6 rad)
///   parallel to the tool axis or a vector is not finite.
Eigen::Matrix3d CuttingFrame(const Eigen::Vector3d& tool_axis_B, const Eigen::Vector3d& feed_B);

/// R_BC for a robot posture: the tool axis is −z of the TCP frame (the TCP
/// frame's z points from the spindle to the tool tip, config/kr210.yaml).
Eigen::Matrix3d CuttingFrameAtPosture(const Eigen::Isometry3d& X_BT, const Eigen::Vector3d& feed_B);

/// Tool-tip dynamics as real modes, in whatever frame p is expressed:
/// <pre>
///   H(ω) = Σ_k p_k p_kᵀ / (ω_k² − ω² + 2i ζ_k ω_k ω)                     (1)
/// </pre>
/// [Ewins 2000]; p_k is the tool-tip part of the mass-normalised mode
/// shape [1/√kg] (a unit shape u with modal mass m gives p = u/√m).
struct TipModalModel {
  Eigen::VectorXd omega_rad_s;  // undamped natural frequencies [rad/s]
  Eigen::VectorXd zeta;         // damping ratios [-]
  Matrix3Xd p;                  // one column per mode [1/√kg]

  int num_modes() const { return static_cast<int>(omega_rad_s.size()); }
  /// The same modes with shapes expressed in C: p_C = R_BCᵀ p_B.
  TipModalModel Rotated(const Eigen::Matrix3d& R_BC) const;
  /// @throws std::invalid_argument if sizes differ, a frequency is not > 0,
  ///   a damping ratio is outside [0, 1) or anything is not finite.
  void Validate() const;
};

/// The tool-tip modes of a posture (PostureDynamics::modes, p_T in B).
TipModalModel ModalModelFromPosture(const dynamics::PostureDynamics& d);

/// (1) on a frequency grid [Hz]; one 3×3 receptance per line [m/N].
std::vector<Eigen::Matrix3cd> ModalReceptance(const TipModalModel& m, const Eigen::VectorXd& freq_hz);

/// (1) restricted to the in-plane 2×2 block (rows x, y of p), for a model
/// already expressed in the cutting frame C.
std::vector<Eigen::Matrix2cd> InPlaneModalReceptance(const TipModalModel& modes_C,
                                                     const Eigen::VectorXd& freq_hz);

/// The 2×2 in-plane block Φ_C = [R_BCᵀ H_B R_BC]_{xy} of each line.
std::vector<Eigen::Matrix2cd> OrientInCuttingPlane(const std::vector<Eigen::Matrix3cd>& H_B,
                                                   const Eigen::Matrix3d& R_BC);

/// A logarithmic grid of `lines` frequencies [Hz] from f_lo to f_hi, fine
/// enough to resolve a mode when lines / ln(f_hi/f_lo) ≫ 1/(2ζ).
Eigen::VectorXd LogFrequencyGrid(double f_lo_hz, double f_hi_hz, int lines);

/// The grid the lobe computations use for a modal model and a spindle speed
/// range: from half the lowest mode to above both 1.5× the highest mode
/// and the highest tooth-passing frequency N Ω_max / 2π (lobe 0 of speed Ω
/// chatters below N Ω / 2π, so this covers every lobe of the range).
Eigen::VectorXd LobeFrequencyGrid(const TipModalModel& m, int teeth, double max_speed_rad_s,
                                  int lines);

/// The `count` modes with the largest in-plane static compliance
/// |p_xy|²/ω² (the ones that dominate chatter in the plane), in the order
/// of frequency; all if count >= the number of modes.
TipModalModel DominantModes(const TipModalModel& modes_C, int count);

/// - [Ewins 2000] D. J. Ewins, Modal Testing: Theory, Practice and
///   Application, 2nd ed., Research Studies Press, 2000.

}  // namespace robomach::stability
