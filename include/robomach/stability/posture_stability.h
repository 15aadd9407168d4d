#pragma once

#include <Eigen/Core>

#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/stability/milling.h"
#include "robomach/stability/mode_coupling.h"
#include "robomach/stability/zoa_lobes.h"

namespace robomach::stability {

struct PostureStabilityOptions {
  /// Spindle speeds considered [rad/s]; one entry means "at this speed",
  /// several mean "the best speed of the range" (largest regenerative depth).
  Eigen::VectorXd spindle_speed_rad_s;
  int freq_lines{1200};  // lines of the log grid of the ZOA (LobeFrequencyGrid)
  ZoaOptions zoa;
  ModeCouplingOptions mode_coupling;
};

enum class Mechanism { kModeCoupling, kRegenerative, kNone };
const char* ToString(Mechanism m);

/// Chatter limits of one posture for one cut (both mechanisms).
struct PostureStability {
  ModeCouplingResult mode_coupling;      // eigenvalue criterion on the full system
  ClosedFormModeCoupling closed_form;    // the simplified 2-DOF criterion
  LobePoint regenerative;                // ZOA, at the given or best speed
  double critical_depth{NAN};            // min of the two mechanisms [m]
  Mechanism limiting{Mechanism::kNone};
  double chatter_freq_hz{NAN};           // of the limiting mechanism
};

/// Evaluates both mechanisms at a posture: mode coupling on the assembled
/// system (joint space with the B map, so it stays valid near
/// singularities), the closed form from the static compliance, and the ZOA
/// lobes of the tool-tip FRF oriented into the cutting frame R_BC.
/// Numerical outcomes are statuses in the result.
PostureStability AnalysePosture(const dynamics::PostureDynamics& d, const Eigen::Matrix3d& R_BC,
                                const MillingProcess& process, const PostureStabilityOptions& options);

}  // namespace robomach::stability
