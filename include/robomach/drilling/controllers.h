#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace robomach::drilling {

/// A joint-space controller that could run in a real control loop: a fixed
/// period, link-angle measurements in, motor torques (before the gear) out,
/// saturated at the motor-torque limits. Step() does not allocate.
class JointController {
 public:
  virtual ~JointController() = default;
  /// Starts at rest at q0 with the motors holding tau_m0 (the static
  /// equilibrium torque), so the first step is bumpless.
  virtual void Reset(const Eigen::VectorXd& q0, const Eigen::VectorXd& tau_m0) = 0;
  /// One control period: desired link angle, rate and acceleration; the
  /// measured link angle q (link-side encoder) and motor angle referred to
  /// the link, theta / n (motor encoder) [rad]; writes the motor torques
  /// [N·m] (tau_m sized n).
  ///
  /// Position and integral action use the link error e = q_d - q (what the
  /// hole sees); rate and acceleration come from the motor encoder
  /// (collocated), e' = q_d' - (theta/n)'. Differentiating the link angle
  /// instead feeds the lightly damped joint resonances back through a
  /// non-collocated loop: with the seed's robot every derivative gain that
  /// does anything is then unstable (tried: a loop gain of ~70 at the
  /// free-motor resonance, from its 0.7 % damping).
  virtual void Step(const Eigen::VectorXd& q_d, const Eigen::VectorXd& qd_d,
                    const Eigen::VectorXd& qdd_d, const Eigen::VectorXd& q,
                    const Eigen::VectorXd& q_motor, Eigen::VectorXd* tau_m) = 0;
  /// "pid", "pd" or "pd-tdc".
  virtual std::string name() const = 0;
  /// The gains, by name with units, per joint (for summaries).
  virtual std::vector<std::pair<std::string, Eigen::VectorXd>> gains() const = 0;
  double period() const { return period_; }

 protected:
  explicit JointController(double period) : period_(period) {}
  double period_;
};

/// Per-joint gains of the PID/PD controllers, on motor torque per link
/// angle error: tau_m = tau_hold + K_P e + K_I int e + K_D e'.
struct PidGains {
  Eigen::VectorXd kp;   // [N·m/rad]
  Eigen::VectorXd ki;   // [N·m/(rad·s)]; zero for PD
  Eigen::VectorXd kd;   // [N·m·s/rad]
  double derivative_filter_time_constant{0.0};  // [s]; first-order low-pass on e'; 0 = none
};

/// PID with anti-windup by conditional integration: the integrator stops
/// while the output is saturated and the error would drive it further into
/// saturation [Åström & Hägglund 2006, §3.5]. e' is the backward difference
/// of e over one period, optionally low-pass filtered (first order): the
/// link-side derivative otherwise excites the lightly damped joint
/// resonances (non-collocated feedback). At Reset the integrator is loaded with the holding
/// torque (bumpless start), so there is no separate gravity feed-forward.
/// With ki = 0 it is a PD controller with the holding torque as constant
/// feed-forward (name "pd").
///
/// - [Åström & Hägglund 2006] K. J. Åström, T. Hägglund, Advanced PID
///   Control, ISA, 2006.
class PidController final : public JointController {
 public:
  /// @throws std::invalid_argument on size mismatch, negative gains or
  ///   limits, or a period <= 0.
  PidController(PidGains gains, Eigen::VectorXd torque_limit, double period);
  void Reset(const Eigen::VectorXd& q0, const Eigen::VectorXd& tau_m0) override;
  void Step(const Eigen::VectorXd& q_d, const Eigen::VectorXd& qd_d, const Eigen::VectorXd& qdd_d,
            const Eigen::VectorXd& q, const Eigen::VectorXd& q_motor, Eigen::VectorXd* tau_m) override;
  std::string name() const override { return gains_.ki.any() ? "pid" : "pd"; }
  std::vector<std::pair<std::string, Eigen::VectorXd>> gains() const override;

 private:
  PidGains gains_;
  Eigen::VectorXd limit_, tau_hold_, integral_, e_prev_, ed_, u_;
  bool first_{true};
};

/// Gains of PD with time-delay estimation.
struct PdTdcGains {
  Eigen::VectorXd kp;    // K_P [1/s²]
  Eigen::VectorXd kd;    // K_D [1/s]
  Eigen::VectorXd mbar;  // diag Mbar [N·m·s²/rad]: motor torque per link acceleration
  double accel_filter_time_constant{0.0};  // [s]; 0 = no filter on the q'' estimate
};

/// PD control with time-delay estimation (seed 003 eqs. 10-16,
/// [Youcef-Toumi & Ito 1990]):
/// <pre>
///   tau_m(t) = Mbar (q''_d + K_D e' + K_P e) + tau_m(t - L) - Mbar q''(t - L)   (16)
/// </pre>
/// with L the control period. The last two terms estimate everything Mbar
/// q'' does not explain (the rest of the inertia, gravity, the joint spring,
/// the drilling load) from one period ago. q''(t - L) is the second backward
/// difference (q_k - 2 q_{k-1} + q_{k-2}) / L² of the motor angle referred to
/// the link (see JointController::Step), optionally low-pass filtered (first
/// order, time constant T_f); e' is the first backward difference of
/// q_d - theta/n; e = q_d - q is the link error.
/// tau_m(t - L) is the torque actually applied (after saturation), which
/// also prevents wind-up of the estimate.
///
/// - [Youcef-Toumi & Ito 1990] K. Youcef-Toumi, O. Ito, A time delay
///   controller for systems with unknown dynamics, ASME J. Dyn. Syst. Meas.
///   Control 112(1), 133-142.
class PdTdcController final : public JointController {
 public:
  PdTdcController(PdTdcGains gains, Eigen::VectorXd torque_limit, double period);
  void Reset(const Eigen::VectorXd& q0, const Eigen::VectorXd& tau_m0) override;
  void Step(const Eigen::VectorXd& q_d, const Eigen::VectorXd& qd_d, const Eigen::VectorXd& qdd_d,
            const Eigen::VectorXd& q, const Eigen::VectorXd& q_motor, Eigen::VectorXd* tau_m) override;
  std::string name() const override { return "pd-tdc"; }
  std::vector<std::pair<std::string, Eigen::VectorXd>> gains() const override;

 private:
  PdTdcGains gains_;
  Eigen::VectorXd limit_, tau_prev_, q1_, q2_, e_prev_, qdd_est_, u_;
  int steps_{0};
};

/// The TDE stability measure ||I - M_eff^-1 Mbar||_2 [Youcef-Toumi & Ito
/// 1990; Hsia & Gao 1990]; the estimate converges when it is < 1. M_eff is
/// the inertia the motor torques see per link acceleration with rigid gears
/// (theta = n q): M_eff = diag(1/n) (M(q) + diag(n² J_m))
/// (DrillingScenario::effective_inertia()).
///
/// - [Hsia & Gao 1990] T. C. Hsia, L. S. Gao, Robot manipulator control using
///   decentralized linear time-invariant time-delayed joint controllers,
///   IEEE ICRA 1990, 2070-2075.
double TdeStabilityMeasure(const Eigen::MatrixXd& M_eff, const Eigen::VectorXd& mbar);

}  // namespace robomach::drilling
