#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/common/eigen_types.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

/// Above this condition number of J_BT the Cartesian matrices are not formed.
/// M_X = J⁻ᵀ M_q J⁻¹ amplifies relative errors by about cond(J)², so at
/// cond = 1e5 a double-precision result keeps only ~1e-6 relative accuracy
/// (eps · 1e10), and its entries grow as 1/σ_min²: beyond that they are noise.
inline constexpr double kNearSingularCondition = 1e5;

/// One vibration mode of the assembled system.
struct Mode {
  double freq_hz{0.0};         // undamped natural frequency [Hz]
  double damping_ratio{0.0};   // [-]
  /// Effective mass at the tool tip along shape_T [kg]: 1/|p_T|² for the
  /// mass-normalised mode; infinite if the mode does not move the tip.
  double modal_mass_kg{0.0};
  Eigen::Vector3d shape_T{Eigen::Vector3d::Zero()};  // unit tool-tip translation, largest entry > 0
  Eigen::Vector3d p_T{Eigen::Vector3d::Zero()};      // B φ of the mass-normalised mode [1/√kg]
  Eigen::VectorXd phi;                               // mass-normalised mode shape (φᵀMφ = 1)
};

/// Poles and residues of the tool-tip receptance,
/// H(ω) = Σ_k R_k / (iω − λ_k) over all 2N state-space poles. Exact for any
/// damping, proportional or not.
struct ComplexModalModel {
  Eigen::VectorXcd poles;             // λ_k [rad/s]
  std::vector<Eigen::Matrix3cd> residues;
};

/// What PostureEvaluator::Evaluate computes. The defaults compute everything
/// (what every caller got before these flags existed); a caller that needs
/// less says so and does not pay for the rest. Always computed, because the
/// assembly needs them and they come from the same pass: q, X_BT, J_BT,
/// `system`, proportional_damping. An output not asked for is NaN (numbers),
/// false (near_singular) or empty (modes, complex_modes).
/// Fields are appended, never reordered: callers initialise the first two
/// positionally (PostureOptions{false, true}).
struct PostureOptions {
  bool cartesian{true};           // M_X, K_X, C_X (n == 6 and not near-singular); implies jacobian_condition
  bool modes{true};               // undamped modes: freq_hz, phi, p_T
  bool jacobian_condition{true};  // jacobian_condition and near_singular
  bool static_compliance{true};   // static_compliance
  bool modal_masses{true};        // Mode::modal_mass_kg and shape_T (with modes)
  /// Mode::damping_ratio (with modes), and complex_modes when the damping is
  /// not proportional. ReceptanceModal needs them.
  bool damping_ratios{true};

  /// Every combination of the flags is valid (an output that needs another,
  /// modal_masses without modes, is simply not computed; ReceptanceModal
  /// refuses dynamics without damping ratios where it is called): nothing
  /// to check. Declared so that every options struct has a Validate()
  /// (issue #36); PostureEvaluator::Evaluate, called per posture in the
  /// maps' inner loops, does not call it.
  void Validate() const;
};

/// Everything that depends on the posture q. Plain data, cheap to copy.
struct PostureDynamics {
  Eigen::VectorXd q;                   // [rad]
  Eigen::Isometry3d X_BT{Eigen::Isometry3d::Identity()};
  Matrix6Xd J_BT;                      // TCP Jacobian, rows [v; ω]
  AssembledSystem system;              // joints first, then effect DOFs
  double jacobian_condition{NAN};      // σ_max/σ_min of J_BT (meters and radians mixed, as is)
  bool near_singular{false};           // jacobian_condition > kNearSingularCondition
  bool proportional_damping{true};     // C_extra == 0
  /// Cartesian matrices at T, in B, [v; ω]; NaN when near singular or n != 6.
  Matrix6d M_X, K_X, C_X;
  Eigen::Matrix3d static_compliance;   // H_T(0) = B K⁻¹ Bᵀ [m/N]
  std::vector<Mode> modes;             // ascending frequency
  /// Poles and residues of the damped system when the damping is not
  /// proportional and modes were asked for (empty otherwise); computed once
  /// here because the damping ratios of `modes` need them anyway.
  ComplexModalModel complex_modes;
  /// What was asked for when these data were computed.
  PostureOptions options;

  /// Joint-space blocks of the assembled system (n × n).
  Eigen::MatrixXd M_q() const { return system.M.topLeftCorner(system.num_joints, system.num_joints); }
  Eigen::MatrixXd K_q() const { return system.K.topLeftCorner(system.num_joints, system.num_joints); }
  Eigen::MatrixXd C_q() const { return system.C.topLeftCorner(system.num_joints, system.num_joints); }
};

/// Evaluates postures of one model with reusable buffers and solvers.
/// Not thread-safe: use one evaluator per thread (they may share the model).
class PostureEvaluator {
 public:
  explicit PostureEvaluator(std::shared_ptr<const RobotModel> model);
  ~PostureEvaluator();
  PostureEvaluator(const PostureEvaluator&) = delete;
  PostureEvaluator& operator=(const PostureEvaluator&) = delete;

  /// @throws std::invalid_argument if q has the wrong size or is not finite;
  ///   std::runtime_error if the assembled mass matrix is not positive
  ///   definite (a bad model, not a bad posture).
  PostureDynamics Evaluate(const Eigen::VectorXd& q, const PostureOptions& options = {});

  /// The same into `out`, reusing its storage: when `out` last held a posture
  /// of this model, nothing is allocated (for the six-joint robot without
  /// effect DOFs; effects and the general N-DOF path may allocate inside
  /// Eigen). The fast path for loops over many postures.
  ///
  /// How it is computed: pose, J_BT and M_q in one pass over the segments
  /// (composite-rigid-body algorithm in the base frame, Featherstone 2008
  /// §6.2; KDL is the reference in tests/dynamics/rigid_chain_test.cc). With
  /// six DOFs and K diagonal (joint stiffness only, the usual case) the
  /// generalized problem K φ = λ M φ becomes one standard symmetric problem
  /// A u = μ u, A = K^{-1/2} M K^{-1/2}, μ = 1/λ, φ = K^{-1/2} u / √μ, solved
  /// with a fixed-size Eigen::SelfAdjointEigenSolver; otherwise Eigen's
  /// GeneralizedSelfAdjointEigenSolver (Cholesky of M) as before.
  void Evaluate(const Eigen::VectorXd& q, const PostureOptions& options, PostureDynamics* out);

  const RobotModel& model() const { return *model_; }

 private:
  struct Workspace;
  std::shared_ptr<const RobotModel> model_;
  std::unique_ptr<Workspace> ws_;
};

/// Convenience: a one-off evaluation.
PostureDynamics EvaluatePosture(std::shared_ptr<const RobotModel> model, const Eigen::VectorXd& q,
                                const PostureOptions& options = {});

}  // namespace robomach::dynamics
