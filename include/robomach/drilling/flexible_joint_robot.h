#pragma once

#include <memory>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/common/eigen_types.h"
#include "robomach/kinematics/serial_chain.h"

namespace robomach::drilling {

/// The drive behind one joint (formats.md §9.3), SI.
struct JointDrive {
  double stiffness{60000.0};      // K [N·m/rad], link side
  double damping{0.0};            // D [N·m·s/rad], link side
  double rotor_inertia{1.98e-4};  // J_m [kg·m²], the rotor's own (not reflected)
  double gear_ratio{120.0};       // n > 0
};

/// State of the flexible-joint robot: link angles q, motor angles theta
/// (motor shaft, before the gear) and their rates. SI, radians.
struct FlexibleJointState {
  Eigen::VectorXd q, qd, theta, thetad;
};

/// Spong's reduced model of a robot with elastic joints [Spong 1987]
/// (seed 003 eq. 1, formats.md §9.3):
/// <pre>
///   M(q) q'' + C(q, q') q' + G(q) = tau + tau_ext,                     (1)
///   J_m theta'' + tau / n = tau_m,                                       (2)
///   tau = K (theta / n - q) + D (theta' / n - q'),                       (3)
///   tau_ext = J(q)^T w_tip,                                              (4)
/// </pre>
/// with K, D, J_m, n diagonal and gravity -z of the base frame (9.80665
/// m/s²). LinkTerms(), MassMatrix() and Gravity() use KDL's solvers
/// (ChainDynParam); Derivative(), the integrator's inner loop, computes
/// M(q) and C(q, q') q' + G(q) of the same KDL chain itself (composite rigid
/// bodies and recursive Newton-Euler with every body in the base frame,
/// one pass over the segment poses for both): 0.84 us per Derivative() on
/// config/drilling/planar3r.yaml against 2.5 us for KDL's ChainDynParam mass
/// matrix plus ChainIdSolver_RNE alone (bench_drilling); tests check it
/// against KDL to rounding. Not thread safe (solvers cache state): use one
/// instance per thread.
class FlexibleJointRobot {
 public:
  /// @throws std::invalid_argument if the drive count differs from the
  ///   joint count, or a stiffness, gear ratio or rotor inertia is not > 0,
  ///   or a damping is negative.
  FlexibleJointRobot(kinematics::SerialChain chain, std::vector<JointDrive> drives);
  ~FlexibleJointRobot();
  FlexibleJointRobot(const FlexibleJointRobot&) = delete;
  FlexibleJointRobot& operator=(const FlexibleJointRobot&) = delete;

  int num_joints() const { return n_; }
  const kinematics::SerialChain& chain() const { return chain_; }
  const std::vector<JointDrive>& drives() const { return drives_; }
  const Eigen::VectorXd& stiffness() const { return K_; }
  const Eigen::VectorXd& damping() const { return D_; }
  const Eigen::VectorXd& rotor_inertia() const { return Jm_; }
  const Eigen::VectorXd& gear_ratio() const { return gear_; }

  /// Link-side terms at (q, q'): M(q) [kg·m²], C(q, q') q' and G(q) [N·m].
  void LinkTerms(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, Eigen::MatrixXd* M,
                 Eigen::VectorXd* c, Eigen::VectorXd* g);
  Eigen::VectorXd Gravity(const Eigen::VectorXd& q);
  Eigen::MatrixXd MassMatrix(const Eigen::VectorXd& q);

  /// Time derivative of the state for motor torques tau_m and the joint
  /// torques tau_ext of the external wrench (eqs. 1-3). No allocation.
  void Derivative(const FlexibleJointState& x, const Eigen::VectorXd& tau_m,
                  const Eigen::VectorXd& tau_ext, FlexibleJointState* dx);

  /// Total mechanical energy: link and rotor kinetic energy, spring energy
  /// 1/2 (theta/n - q)^T K (theta/n - q), and the links' gravity potential
  /// sum m_i g z_com,i computed from the forward kinematics (independent of
  /// G(q)) [J].
  double Energy(const FlexibleJointState& x);

  /// Rest state in static equilibrium at q0 under tau_ext:
  /// theta = n (q0 + K^-1 (G(q0) - tau_ext)), rates zero; the holding motor
  /// torque is tau_m = (G(q0) - tau_ext) / n.
  FlexibleJointState EquilibriumAt(const Eigen::VectorXd& q0, const Eigen::VectorXd& tau_ext,
                                   Eigen::VectorXd* tau_m_hold);

  /// Undamped natural frequencies with the motor angles held fixed,
  /// sqrt(eig(diag K, M(q0))) / 2 pi, ascending [Hz] (formats.md §9.4;
  /// gravity stiffness left out).
  Eigen::VectorXd PlantModesHz(const Eigen::VectorXd& q0);

  /// Highest undamped frequency with the motors free (links and rotors
  /// coupled by the springs) [rad/s]: sets the integrator's substep.
  double HighestFreeModeRadS(const Eigen::VectorXd& q0);

  /// Tool-tip pose and Jacobian J_BT (rows [v; w], in B).
  Eigen::Isometry3d TipPose(const Eigen::VectorXd& q) const;
  Matrix6Xd TipJacobian(const Eigen::VectorXd& q) const;

 private:
  struct Kdl;
  struct Bodies;  // the chain's bodies for Derivative()
  kinematics::SerialChain chain_;
  std::vector<JointDrive> drives_;
  int n_;
  Eigen::VectorXd K_, D_, Jm_, gear_;
  std::unique_ptr<Kdl> kdl_;
  std::unique_ptr<Bodies> bodies_;
  // Scratch for Derivative().
  Eigen::MatrixXd M_;
  Eigen::VectorXd h_, tau_, rhs_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
};

/// Fourth-order Runge-Kutta over one interval of length h with tau_m and
/// tau_ext held (zero-order hold of the controller and the drilling load).
///
/// Why RK4 with substeps: the joint modes are stiff (a few hundred Hz at
/// 60 kN·m/rad) against a 1 kHz control rate, but they are lightly damped
/// oscillations, not fast decays, so the integrator must follow them, not
/// just stay stable (an L-stable implicit method would damp them away). On
/// the imaginary axis RK4 has amplitude error |R(iy)| = 1 - y^6/144 + ... and
/// phase error y^5/120 per step (y = omega h). The default rule
/// omega_max h <= 0.07 keeps the energy drift of a free, undamped run below
/// 1e-6 relative over 1 s (the acceptance test; at 0.2 it was 7.5e-5), and
/// the phase error of the highest mode below 1.4e-8 rad per step. Substeps are
/// chosen by SubstepsFor().
class Rk4Integrator {
 public:
  explicit Rk4Integrator(int num_joints);
  void Step(FlexibleJointRobot& robot, const Eigen::VectorXd& tau_m, const Eigen::VectorXd& tau_ext,
            double h, FlexibleJointState* x);

 private:
  FlexibleJointState k1_, k2_, k3_, k4_, tmp_;
};

/// Substeps per control period so that omega_max h <= max_omega_h.
int SubstepsFor(double omega_max_rad_s, double control_period, double max_omega_h = 0.07);

}  // namespace robomach::drilling
