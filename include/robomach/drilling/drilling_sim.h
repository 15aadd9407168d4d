#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/progress.h"
#include "robomach/common/solver_status.h"
#include "robomach/drilling/controllers.h"
#include "robomach/drilling/drill_forces.h"
#include "robomach/drilling/drilling_process.h"
#include "robomach/drilling/flexible_joint_robot.h"

namespace robomach::drilling {

/// Time series of one run, one sample per control period (formats.md §9.4).
struct SimSeries {
  std::vector<double> t;         // [s]
  Eigen::MatrixXd q, e, tau_m;   // n x samples: link angle, q_d - q [rad], motor torque [N·m]
  std::vector<double> thrust;    // [N]
  std::vector<double> torque;    // [N·m]
  std::vector<double> offset;    // angle between drill axis and hole axis [rad]
};

struct ThrustStats {
  double min{NAN}, max{NAN}, mean{NAN};
  bool available{false};         // false if the lips never fully engaged
};

struct SimResult {
  std::string controller;
  std::vector<std::pair<std::string, Eigen::VectorXd>> gains;
  SimSeries series;
  /// Last time any |e_i| exceeds the band; 0 if never; NaN if the last
  /// sample is still outside (formats.md §9.4: null).
  double settling_time{NAN};
  Eigen::VectorXd max_abs_error;            // per joint, whole run [rad]
  Eigen::VectorXd max_abs_error_last_10pc;  // per joint, last 10 % of the run [rad]
  ThrustStats thrust;                       // after full engagement of the lips
  double cost{NAN};                         // the tuning cost of this run
  bool diverged{false};                     // non-finite state or |e| > 10 deg
  int substeps{0};                          // plant steps per control period
};

/// The tuning cost shared by all controllers (so the comparison is fair):
/// the time-weighted absolute joint error
/// <pre>
///   J = sum_k t_k sum_i |e_i(t_k)| L      [rad s²]
/// </pre>
/// over the run (ITAE); the motor-torque limits are hard (the controllers
/// saturate), and a run that diverges costs 1e6.
double TuningCost(const SimSeries& series, double period);

struct SimOptions {
  Eigen::VectorXd motor_torque_limit;  // [N·m] per joint
  double max_omega_h{0.07};             // RK4 substep rule (Rk4Integrator)
  bool record{true};                   // keep the time series (tuning does not need it)
  ProgressCallback progress;           // called every ~1 % of the run

  /// The bounds (issue #36); the size of motor_torque_limit is the run's
  /// check (it needs the robot):
  /// - motor_torque_limit, each >= 0 and finite [N m]: the controllers
  ///   saturate at it.
  /// - max_omega_h in (0, 2.8]: it divides the substep count, and RK4 is
  ///   stable on an undamped mode up to omega h = 2 sqrt 2 = 2.83.
  /// @throws OptionError(field, "FIELD: expected ..., got VALUE") naming the bound.
  void Validate() const;
};

/// The seed's scenario: the robot starts at rest in static equilibrium at
/// the initial posture q0, the drill touching; the desired tool tip then
/// moves along the hole axis at the feed speed f N while keeping its
/// orientation (q_d(t) by resolved rates with a Newton correction on
/// the full 6-D pose); thrust and torque follow the force model with the
/// current tilt of the drill; the wrench reaches the joints through J^T.
///
/// Choices: the penetration is the nominal one, f N t (as in seed eq. 6);
/// the drill axis is the hole-axis direction of the tip frame, turned by the
/// initial tilt about the tip frame's next axis; the load is held over each
/// control period. The drill's torque reacts on the robot as -T about the
/// drill axis; the imbalance force acts at the tip in the plane normal to
/// the drill axis.
class DrillingScenario {
 public:
  /// @throws std::invalid_argument if q0 has the wrong size or the robot
  ///   cannot move its tip along the hole axis at q0 (the message says so).
  DrillingScenario(FlexibleJointRobot* robot, DrillGeometry drill, DrillingMaterial material,
                   DrillingProcess process);

  int num_samples() const { return static_cast<int>(q_d_.cols()); }
  const Eigen::MatrixXd& desired() const { return q_d_; }
  /// Inertia seen by the motor torques per link acceleration at q0 with
  /// rigid gears: M_eff = diag(1/n) (M(q0) + diag(n² J_m)) [N·m·s²/rad].
  const Eigen::MatrixXd& effective_inertia() const { return M_eff_; }
  const Eigen::VectorXd& holding_torque() const { return tau_hold_; }
  const Eigen::VectorXd& plant_modes_hz() const { return modes_hz_; }
  const DrillingProcess& process() const { return process_; }
  /// Time after which the lips are fully engaged [s].
  double full_engagement_time() const { return t_full_; }

  SimResult Run(JointController& controller, const SimOptions& options);

 private:
  FlexibleJointRobot* robot_;
  DrillGeometry drill_;
  DrillingMaterial material_;
  DrillingProcess process_;
  Eigen::Vector3d axis_tip_;        // hole axis in the tip frame
  Eigen::Vector3d drill_axis_tip_;  // drill axis in the tip frame (initial tilt)
  Eigen::Vector3d x_drill_tip_;     // reference radial direction in the tip frame
  Eigen::Vector3d hole_axis_B_;
  Eigen::MatrixXd q_d_, qd_d_, qdd_d_;
  Eigen::MatrixXd M_eff_;
  Eigen::VectorXd tau_hold_, modes_hz_;
  double omega_max_{0.0};
  double t_full_{0.0};
};

/// How controller gains are parameterised for tuning: three numbers per
/// controller, scaled per joint by the effective inertia m_i = M_eff(i, i)
/// so one set fits all joints.
///   pid:    kp = m w², kd = 2 zeta m w, ki = kp w / r     (x = w, zeta, r)
///   pd:     kp = m w², kd = 2 zeta m w                    (x = w, zeta, -)
///   pd-tdc: kp = w², kd = 2 zeta w, Mbar = alpha m        (x = w, zeta, alpha)
struct ControllerParameters {
  std::string kind;        // "pid", "pd" or "pd-tdc"
  double omega{60.0};      // w [rad/s]
  double zeta{1.0};        // zeta
  double third{4.0};       // r (pid), alpha (pd-tdc)
  double filter_time_constant{0.005};  // [s]: derivative (pid, pd) or q'' (pd-tdc) low-pass
};

/// Builds the controller for a scenario. @throws std::invalid_argument for
/// an unknown kind.
std::unique_ptr<JointController> MakeController(const ControllerParameters& p,
                                                const DrillingScenario& scenario,
                                                const Eigen::VectorXd& torque_limit);

/// Gains of `kind` from the numbers a user gives (drill-sim's --gains
/// KIND=OMEGA,ZETA[,THIRD[,FILTER_S]]): omega [rad/s] and zeta, then the
/// third parameter and the filter time constant [s]; the others keep
/// DefaultParameters(kind).
/// @throws std::invalid_argument for an unknown kind, fewer than 2 or more
///   than 4 numbers, or a value that is not finite and positive (the
///   filter time constant may be 0).
ControllerParameters ParametersFromGains(const std::string& kind, const std::vector<double>& values);

/// Defaults found by TuneController on the default scenario
/// (config/drilling/, see README).
ControllerParameters DefaultParameters(const std::string& kind);

struct TuneResult {
  ControllerParameters parameters;
  double cost{NAN};
  int evaluations{0};
  /// How the tuning ended (TuneController says when each applies).
  SolverStatus status{SolverStatus::kFailed};
  /// NLopt's reason for stopping beside the status: "converged",
  /// "max_evaluations" or "roundoff_limited".
  std::string message;
};

/// Tunes the three parameters with NLopt (derivative-free BOBYQA on their
/// logarithms, within bounds) to minimise TuningCost() on the scenario. The
/// tuning runs use RK4 substeps with omega_max h <= 0.2 (enough to rank
/// gains, 3x faster); the filter time constant is kept.
/// `start` gives the kind and the starting point.
/// The status: kFailed when every simulation diverged (the best cost is
/// the divergence cost, or not finite: no usable gains); else kNotImproved
/// when the best cost is no lower than that of the first simulation (the
/// start as BOBYQA places it within the bounds; it is then returned); else
/// kConverged when BOBYQA met its tolerance on the parameters, and
/// kNotConverged when it stopped at max_evaluations or on round-off (the
/// best parameters so far).
TuneResult TuneController(const ControllerParameters& start, DrillingScenario& scenario,
                          const SimOptions& options, int max_evaluations = 60);

}  // namespace robomach::drilling
