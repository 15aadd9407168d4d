#pragma once

#include <complex>
#include <optional>
#include <string>
#include <utility>

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

  /// @throws OptionError naming the field, its value and the bound:
  /// spindle_speed_rad_s at least one speed, each finite > 0 (the tooth
  /// period 2π/(NΩ) and the ZOA's grid need it), freq_lines >= 2 (a grid of
  /// one line has no spacing), and the nested zoa.* and mode_coupling.*
  /// fields (their Validate, field prefixed). The default has no speed and
  /// is not valid: the caller gives the speeds.
  void Validate() const;
};

enum class Mechanism { kModeCoupling, kRegenerative, kNone };
const char* ToString(Mechanism m);
/// The inverse of ToString. @throws std::invalid_argument naming the three.
Mechanism ParseMechanism(const std::string& name);

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

/// One point of the ZOA lobes (a speed Ω, its lobe k and chatter frequency
/// f_c, as ZoaLobes::At gives it for dynamics d) followed exactly to other
/// dynamics at the same speed: secant steps on the lobe's phase condition
/// Ω (2θ(f) + 2πk) = 2π (2πf) / N on the branch of Φ(f) H₀'s eigenvalues
/// through the point, the receptance at one frequency per step, and
/// a_lim = −1/(2 Re λ) there, shifted so that the point's own dynamics give
/// the point's depth. A grid of lines interpolates the lobe: its value is
/// good to a fraction of a percent, but its lines move with the modes, so
/// its derivative with respect to the model's parameters is not
/// (local_critical_depth_test.cc: by up to the largest derivative on 1200
/// lines). This one is smooth: what a first-order propagation needs.
class ZoaLobeContinuation {
 public:
  ZoaLobeContinuation(const dynamics::PostureDynamics& d, const Eigen::Matrix3d& R_BC, const MillingProcess& process,
                      const LobePoint& point);
  /// False when the point is not kOk or its lobe is not found again from
  /// its chatter frequency (within 1 % of it and 10 % of its depth).
  bool ok() const { return exact_.ok; }
  /// The depth [m] at the point's speed with dynamics d (`modes`: its
  /// ModalModelFromPosture); NaN where the lobe is lost.
  double operator()(const dynamics::PostureDynamics& d, const TipModalModel& modes) const;

 private:
  struct Solution {
    double depth{NAN}, freq_hz{NAN}, residual{NAN};
    std::complex<double> lambda;
    bool ok{false};
  };
  std::pair<std::complex<double>, std::complex<double>> PhaseEigenvalues(const dynamics::PostureDynamics& d,
                                                                         const TipModalModel& modes_C,
                                                                         double freq_hz) const;
  double LobeSpeed(double freq_hz, std::complex<double> lambda) const;
  Solution Solve(const dynamics::PostureDynamics& d, const TipModalModel& modes_C, double f_start,
                 std::complex<double> lambda_near, double done) const;

  Eigen::Matrix3d R_BC_;
  Eigen::Matrix2d H0_;
  int teeth_;
  double speed_rad_s_, depth_;
  int lobe_index_;
  Solution exact_;  // at the dynamics of construction
};

/// AnalysePosture's critical depth near one of its analyses, for posture
/// dynamics whose parameters differ a little (same posture, cut, speeds):
/// exact at the analysis and first-order accurate around it, at a small
/// part of an analysis' cost. What a first-order propagation needs
/// (StabilityMapIntervals): its differences see the derivative of the
/// analysis' depth without the noise of its search tolerance and lines.
/// - Mode coupling: the implicit function theorem on the growth
///   g(a, p) = Re λ − 1e-9 |λ| of the rightmost eigenvalue at the analysis'
///   critical depth a*: a(p) = a* − (g(a*, p) − g(a*, p₀)) / (∂g/∂a), with
///   ∂g/∂a from the eigenvectors (RightmostEigenvalueModal): one eigenvalue
///   problem per evaluation instead of a search of 15-30.
/// - Regenerative: the ZOA depth at the analysis' best speed on its lobe,
///   by ZoaLobeContinuation: the derivative of a maximum over the speed
///   grid is the derivative at the grid speed that attains it, as long as
///   that speed stays the best. Next to a cusp two grid speeds can nearly
///   tie, and the maximum has a kink there (Monte Carlo sees it; first
///   order takes the side of the analysis' best speed).
/// The limiting mechanism is chosen as AnalysePosture chooses it; the other
/// mechanism is followed only when it is within 10 % of the limiting one.
class LocalCriticalDepth {
 public:
  LocalCriticalDepth(const dynamics::PostureDynamics& d, const Eigen::Matrix3d& R_BC, const MillingProcess& process,
                     const PostureStabilityOptions& options, const PostureStability& analysis);
  /// False where the depth has no such model; why_not() says why (a
  /// crossing that is not transversal, a lobe not found again). The caller
  /// then repeats the analysis.
  bool usable() const { return why_not_.empty(); }
  const std::string& why_not() const { return why_not_; }
  /// The critical depth [m] with dynamics `d` (NaN where the model does not
  /// reach: the best speed's lobe was lost).
  double operator()(const dynamics::PostureDynamics& d) const;

 private:
  double ModeCoupling(const dynamics::PostureDynamics& d, const TipModalModel& modes) const;

  Eigen::Matrix3d Kc_B_;
  bool use_mc_{false}, use_rg_{false};
  double a_star_{NAN}, g_star_{NAN}, dg_da_{NAN};
  std::optional<ZoaLobeContinuation> lobe_;
  std::string why_not_;
};

}  // namespace robomach::stability
