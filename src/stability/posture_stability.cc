#include "robomach/stability/posture_stability.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "robomach/common/enum_names.h"
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

Mechanism ParseMechanism(const std::string& name) {
  constexpr Mechanism kAll[] = {Mechanism::kModeCoupling, Mechanism::kRegenerative, Mechanism::kNone};
  return ParseByName("mechanism", name, kAll);
}

void PostureStabilityOptions::Validate() const {
  if (spindle_speed_rad_s.size() == 0) {
    throw OptionError("spindle_speed_rad_s", "spindle_speed_rad_s: expected at least one spindle speed, got none");
  }
  for (const double speed : spindle_speed_rad_s) {
    CheckOptionFinite("spindle_speed_rad_s", speed);
    CheckOptionAbove("spindle_speed_rad_s", speed, 0.0);
  }
  CheckOptionAtLeast("freq_lines", freq_lines, 2);
  ValidateNested("zoa", zoa);
  ValidateNested("mode_coupling", mode_coupling);
}

PostureStability AnalysePosture(const dynamics::PostureDynamics& d, const Eigen::Matrix3d& R_BC,
                                const MillingProcess& process, const PostureStabilityOptions& options) {
  process.Validate();
  options.Validate();
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

namespace {

bool ModalRoute(const dynamics::PostureDynamics& d) { return d.proportional_damping && !d.modes.empty(); }

// The growth of the mode-coupling search (SearchCriticalDepth) at depth a,
// and its derivative with respect to a when asked.
double Growth(const dynamics::PostureDynamics& d, const TipModalModel& modes, const Eigen::Matrix3d& Kc_B, double a,
              double* dg_da = nullptr) {
  std::complex<double> dl;
  const std::complex<double> l =
      ModalRoute(d) ? RightmostEigenvalueModal(modes, Kc_B, a, dg_da ? &dl : nullptr)
                    : RightmostEigenvalueAndDerivative(d.system.M, d.system.C, d.system.K,
                                                       d.system.B.transpose() * Kc_B * d.system.B, a,
                                                       dg_da ? &dl : nullptr);
  if (dg_da != nullptr) {
    const double r = std::abs(l);
    *dg_da = dl.real() - (r > 0.0 ? 1e-9 * (std::conj(l) * dl).real() / r : 0.0);
  }
  return l.real() - 1e-9 * std::abs(l);
}

}  // namespace

LocalCriticalDepth::LocalCriticalDepth(const dynamics::PostureDynamics& d, const Eigen::Matrix3d& R_BC,
                                       const MillingProcess& process, const PostureStabilityOptions& options,
                                       const PostureStability& analysis)
    : Kc_B_(R_BC * CuttingStiffnessPerDepth(process) * R_BC.transpose()) {
  // `options` are those `analysis` came from: AnalysePosture validated them.
  if (analysis.limiting == Mechanism::kNone || !std::isfinite(analysis.critical_depth)) {
    why_not_ = "no critical depth at the estimates";
    return;
  }
  const bool mc_limits = analysis.limiting == Mechanism::kModeCoupling;
  const double mc_depth = analysis.mode_coupling.critical_depth, rg_depth = analysis.regenerative.critical_depth;
  const TipModalModel modes = ModalModelFromPosture(d);
  // The limiting mechanism, and the other one when it is within 10 % (a
  // switch within the propagation's steps is then possible); a mechanism
  // that cannot be followed is dropped unless it limits.
  if (analysis.mode_coupling.status == ModeCouplingStatus::kFound) {
    a_star_ = mc_depth;
    g_star_ = Growth(d, modes, Kc_B_, a_star_, &dg_da_);
    const bool transversal = dg_da_ > 0.0 && std::isfinite(dg_da_);
    // The search brackets the root to a relative 1e-4 (ModeCouplingOptions):
    // much farther, and the analysis is not of these dynamics. Checked
    // whichever mechanism limits: the crossing is the analysis' fingerprint.
    if (transversal &&
        !(std::abs(g_star_ / dg_da_) <= std::max(10.0 * options.mode_coupling.depth_tolerance, 1e-6) * a_star_)) {
      why_not_ = "the analysis' mode-coupling depth is not a crossing of these dynamics (an analysis of another model)";
      return;
    }
    if (!transversal && mc_limits) {
      why_not_ = "the rightmost eigenvalue does not cross the imaginary axis transversally at the mode-coupling depth";
      return;
    }
    use_mc_ = transversal && (mc_limits || mc_depth <= 1.1 * rg_depth);
  }
  if (analysis.regenerative.status == LobeStatus::kOk && (!mc_limits || rg_depth <= 1.1 * mc_depth)) {
    lobe_.emplace(d, R_BC, process, analysis.regenerative);
    use_rg_ = lobe_->ok();
    if (!use_rg_ && !mc_limits) {
      why_not_ = "the lobe at the best speed is not found again by continuing it from its chatter frequency";
      return;
    }
  }
}

double LocalCriticalDepth::ModeCoupling(const dynamics::PostureDynamics& d, const TipModalModel& modes) const {
  return a_star_ - (Growth(d, modes, Kc_B_, a_star_) - g_star_) / dg_da_;
}

ZoaLobeContinuation::ZoaLobeContinuation(const dynamics::PostureDynamics& d, const Eigen::Matrix3d& R_BC,
                                         const MillingProcess& process, const LobePoint& point)
    : R_BC_(R_BC),
      H0_(AverageDirectionalMatrix(process).topRows<2>()),
      teeth_(process.teeth),
      speed_rad_s_(point.spindle_speed_rad_s),
      depth_(point.critical_depth),
      lobe_index_(point.lobe_index) {
  if (point.status != LobeStatus::kOk) return;
  const double fc = point.chatter_freq_hz;
  // The branch at the point's chatter frequency whose lobe k passes nearest
  // its speed there, then continued exactly to that speed.
  const TipModalModel modes_C = ModalModelFromPosture(d).Rotated(R_BC);
  const auto [l1, l2] = PhaseEigenvalues(d, modes_C, fc);
  const double s1 = LobeSpeed(fc, l1), s2 = LobeSpeed(fc, l2);
  const bool first = std::abs(s1 - speed_rad_s_) <= std::abs(s2 - speed_rad_s_) || !std::isfinite(s2);
  const Solution at = Solve(d, modes_C, fc, first ? l1 : l2, 1e-13);
  // The same lobe near the same chatter frequency: a grid of 1200 lines
  // interpolates it within a few percent (2.1 % next to a cusp of the demo
  // region at 150-1200 rpm).
  if (!at.ok || !(std::abs(at.freq_hz - fc) <= 0.01 * fc) || !(std::abs(at.depth - depth_) <= 0.1 * depth_)) return;
  exact_ = at;
}

double ZoaLobeContinuation::operator()(const dynamics::PostureDynamics& d, const TipModalModel& modes) const {
  if (!ok()) throw std::logic_error("ZoaLobeContinuation: the lobe was not found at construction");
  const Solution at = Solve(d, modes.Rotated(R_BC_), exact_.freq_hz, exact_.lambda, std::max(1e-13, exact_.residual));
  return at.ok ? depth_ + (at.depth - exact_.depth) : NAN;
}

std::pair<std::complex<double>, std::complex<double>> ZoaLobeContinuation::PhaseEigenvalues(
    const dynamics::PostureDynamics& d, const TipModalModel& modes_C, double freq_hz) const {
  const Eigen::VectorXd f = Eigen::VectorXd::Constant(1, freq_hz);
  const Eigen::Matrix2cd Phi = ModalRoute(d) ? InPlaneModalReceptance(modes_C, f)[0]
                                             : OrientInCuttingPlane(dynamics::Receptance(d, f), R_BC_)[0];
  const Eigen::Matrix2cd A = Phi * H0_.cast<std::complex<double>>();
  const std::complex<double> half_tr = 0.5 * (A(0, 0) + A(1, 1)), det = A.determinant();
  const std::complex<double> disc = std::sqrt(half_tr * half_tr - det);
  // The larger root directly, the smaller as det / larger (no cancellation;
  // as ComputeZoaLobes).
  std::complex<double> l1 = half_tr + disc, l2 = half_tr - disc;
  if (std::norm(l2) > std::norm(l1)) std::swap(l1, l2);
  if (std::norm(l1) > 0.0) l2 = det / l1;
  return {l1, l2};
}

double ZoaLobeContinuation::LobeSpeed(double freq_hz, std::complex<double> lambda) const {
  // As ComputeZoaLobes: L = −1/λ, θ = atan2(−Re λ, Im λ) where Re λ < 0,
  // Ω = 2π ω_c / (N (2θ + 2πk)).
  if (!(lambda.real() < 0.0)) return NAN;
  const double theta = std::atan2(-lambda.real(), lambda.imag());
  return 2.0 * kPi * HzToRadPerSec(freq_hz) / teeth_ / (2.0 * theta + 2.0 * kPi * lobe_index_);
}

ZoaLobeContinuation::Solution ZoaLobeContinuation::Solve(const dynamics::PostureDynamics& d,
                                                         const TipModalModel& modes_C, double f_start,
                                                         std::complex<double> lambda_near, double done) const {
  // The branch followed by continuity: the eigenvalue nearest the last one.
  std::complex<double> last = lambda_near;
  auto residual = [&](double f) {
    const auto [a, b] = PhaseEigenvalues(d, modes_C, f);
    last = std::abs(a - last) <= std::abs(b - last) ? a : b;
    return LobeSpeed(f, last) / speed_rad_s_ - 1.0;
  };
  // Secant iterations on the lobe's relative speed error, each step at most
  // 1 % of f, until it is below 1e-13 or the step below 1e-12 f (the
  // residual's rounding); accepted below 1e-9. A start within `done` is the
  // answer: the dynamics of construction then give its value exactly.
  Solution out;
  double f1 = f_start, r1 = residual(f1);
  if (std::isfinite(r1) && std::abs(r1) > done) {
    double f0 = f1, r0 = r1;
    f1 = f_start * (1.0 + 1e-6);
    r1 = residual(f1);
    for (int it = 0; it < 40 && std::isfinite(r1) && std::abs(r1) > 1e-13 && r1 != r0; ++it) {
      const double step = std::clamp(-r1 * (f1 - f0) / (r1 - r0), -0.01 * f1, 0.01 * f1);
      if (std::abs(step) <= 1e-12 * f1) break;
      f0 = f1;
      r0 = r1;
      f1 += step;
      r1 = residual(f1);
    }
  }
  out.freq_hz = f1;
  out.lambda = last;  // the eigenvalue at f1 (the last evaluation)
  out.residual = std::abs(r1);
  out.depth = -0.5 / last.real();
  out.ok = std::isfinite(r1) && std::abs(r1) <= 1e-9 && last.real() < 0.0;
  return out;
}

double LocalCriticalDepth::operator()(const dynamics::PostureDynamics& d) const {
  if (!usable()) throw std::logic_error("LocalCriticalDepth: not usable (" + why_not_ + ")");
  const TipModalModel modes = ModalModelFromPosture(d);
  const double mc = use_mc_ ? ModeCoupling(d, modes) : NAN;
  const double rg = use_rg_ ? (*lobe_)(d, modes) : NAN;
  if (use_mc_ && use_rg_) return std::isnan(mc) || std::isnan(rg) ? NAN : std::min(mc, rg);
  return use_mc_ ? mc : rg;
}

}  // namespace robomach::stability
