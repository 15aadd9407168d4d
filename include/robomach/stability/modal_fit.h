#pragma once

#include <vector>

#include <Eigen/Core>

#include "robomach/stability/tool_tip_model.h"

namespace robomach::stability {

/// Modes fitted to a measured or predicted in-plane FRF by peak picking
/// [Ewins 2000, peak picking]: each local maximum of |Im Φ_xx| + |Im Φ_yy| above
/// 5 % of the largest is a mode at that line; its damping ratio is the
/// half-power bandwidth of the larger direct FRF, ζ = (f₂ − f₁)/(2 f_k);
/// its shape follows from the residue at resonance, where a single mode
/// gives Φ(ω_k) = −i p pᵀ/(2 ζ ω_k²), so p pᵀ = −2 ζ ω_k² Im Φ(ω_k)
/// (symmetrised; p is its dominant eigenvector scaled by √λ).
/// Neglects the other modes' contribution at each peak: good for
/// well-separated, lightly damped modes, the case of tap-test data the
/// semi-discretization is used with.
/// @param freq_hz grid [Hz], strictly increasing; Phi_C 2×2 per line [m/N].
/// @param max_modes at most this many modes (the largest peaks).
/// @returns modes with shapes in C (z component 0); none if no peak.
TipModalModel FitModesPeakPicking(const Eigen::VectorXd& freq_hz,
                                  const std::vector<Eigen::Matrix2cd>& Phi_C, int max_modes);

/// The `count` modes with the largest in-plane static compliance
/// |p_xy|²/ω² (the ones that dominate chatter in the plane), in the order
/// of frequency; all if count >= the number of modes.
TipModalModel DominantModes(const TipModalModel& modes_C, int count);

}  // namespace robomach::stability
