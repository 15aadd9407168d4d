#include "robomach/stability/posture_stability.h"

#include <cmath>
#include <stdexcept>

#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/stability/tool_tip_model.h"

namespace robomach::stability {

const char* ToString(Mechanism m) {
  switch (m) {
    case Mechanism::kModeCoupling: return "mode_coupling";
    case Mechanism::kRegenerative: return "regenerative";
    case Mechanism::kNone: return "none";
  }
  return "?";
}

PostureStability AnalysePosture(const dynamics::PostureDynamics& d, const Eigen::Matrix3d& R_BC,
                                const MillingProcess& process, const PostureStabilityOptions& options) {
  process.Validate();
  if (options.spindle_speed_rad_s.size() == 0 || !(options.spindle_speed_rad_s.minCoeff() > 0.0)) {
    throw std::invalid_argument("posture stability: need at least one spindle speed > 0");
  }
  PostureStability out;
  const Eigen::Matrix3d Kc_C = CuttingStiffnessPerDepth(process);
  const Eigen::Matrix3d Kc_B = R_BC * Kc_C * R_BC.transpose();
  // The posture's modes, once for both mechanisms and every speed.
  const TipModalModel modes = ModalModelFromPosture(d);
  out.mode_coupling = d.proportional_damping && !d.modes.empty()
                          ? CriticalDepthModeCouplingModal(modes, Kc_B, options.mode_coupling)
                          : CriticalDepthModeCoupling(d.system.M, d.system.C, d.system.K, d.system.B, Kc_B,
                                                      options.mode_coupling);
  out.closed_form = ModeCouplingClosedForm(R_BC.transpose() * d.static_compliance * R_BC,
                                           Kc_C.topLeftCorner<2, 2>());

  const Eigen::VectorXd f = LobeFrequencyGrid(modes, process.teeth,
                                              options.spindle_speed_rad_s.maxCoeff(), options.freq_lines);
  // With proportional damping the real modes are exact (tool_tip_frf.h
  // (2)) and only the in-plane 2×2 block is needed; otherwise the
  // complex-mode receptance of the dynamics module.
  const auto Phi = d.proportional_damping ? InPlaneModalReceptance(modes.Rotated(R_BC), f)
                                          : OrientInCuttingPlane(dynamics::Receptance(d, f), R_BC);
  ZoaOptions zo = options.zoa;
  zo.min_spindle_speed_rad_s = options.spindle_speed_rad_s.minCoeff();
  const ZoaLobes lobes = ComputeZoaLobes(f, Phi, process, zo);
  const std::vector<LobePoint> pts = lobes.At(options.spindle_speed_rad_s);
  out.regenerative = pts.front();
  for (const LobePoint& p : pts) {
    if (p.status != LobeStatus::kOk) continue;
    if (out.regenerative.status != LobeStatus::kOk || p.critical_depth > out.regenerative.critical_depth) {
      out.regenerative = p;
    }
  }

  const bool mc = out.mode_coupling.status == ModeCouplingStatus::kFound;
  const bool rg = out.regenerative.status == LobeStatus::kOk;
  if (mc && (!rg || out.mode_coupling.critical_depth <= out.regenerative.critical_depth)) {
    out.limiting = Mechanism::kModeCoupling;
    out.critical_depth = out.mode_coupling.critical_depth;
    out.chatter_freq_hz = out.mode_coupling.chatter_freq_hz;
  } else if (rg) {
    out.limiting = Mechanism::kRegenerative;
    out.critical_depth = out.regenerative.critical_depth;
    out.chatter_freq_hz = out.regenerative.chatter_freq_hz;
  }
  return out;
}

}  // namespace robomach::stability
