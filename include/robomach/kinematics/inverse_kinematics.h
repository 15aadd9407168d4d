#pragma once

// Position inverse kinematics of a serial chain: the tool pose X_BT
// reached from a seed posture by Newton steps on the geometric Jacobian,
// damped near singularities (Levenberg-Marquardt on the 6 × n Jacobian).
//
// Why not KDL's ChainIkSolverPos_LMA, which the stability map used before:
// it takes an SVD of the Jacobian at every iteration and stops at a weighted
// error of 1e-6 (about 1e-6 m); here each iteration is one forward-kinematics
// and Jacobian pass (KDL's solvers) and one 6 × 6 Cholesky solve, and the
// Newton steps converge quadratically from a nearby seed, so a map point
// costs 3-4 iterations to 1e-12 m (bench_stability; a third of the LMA's
// time). tests/kinematics/inverse_kinematics_test.cc compares the solutions
// with KDL's LMA and with forward kinematics.
#include <memory>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/kinematics/serial_chain.h"

namespace robomach::kinematics {

struct IkOptions {
  /// A solution is accepted when the tip is this close to the target (> 0).
  double position_tolerance_m{1e-5};
  double rotation_tolerance_rad{1e-4};
  /// Newton iterations stop below these errors (far below the tolerances:
  /// a map's dynamics then do not depend on where the iteration stopped);
  /// > 0.
  double converged_position_m{1e-12};
  double converged_rotation_rad{1e-12};
  int max_iterations{100};  // >= 1

  /// The bounds above.
  /// @throws OptionError naming the field, its value and the bound
  ///   ("position_tolerance_m: expected a value > 0, got 0").
  void Validate() const;
};

/// Solves X_BT(q) = X from a seed. One solver per thread: it binds KDL
/// solvers to its own copy of the chain (KDL joints cache their last pose).
class IkSolver {
 public:
  explicit IkSolver(const SerialChain& chain, IkOptions options = {});
  ~IkSolver();
  IkSolver(const IkSolver&) = delete;
  IkSolver& operator=(const IkSolver&) = delete;

  /// Solves from `seed` (n entries, radians); every joint of the result is
  /// wrapped to the 2π branch nearest its seed. Returns true if the pose was
  /// reached within the tolerances with finite joint values (joint limits
  /// are not checked: SerialChain::JointsOutsideLimits). *q holds the last
  /// iterate either way.
  bool Solve(const Eigen::Isometry3d& X, const Eigen::VectorXd& seed, Eigen::VectorXd* q);

  /// Iterations of the last Solve.
  int last_iterations() const { return last_iterations_; }

 private:
  struct Kdl;
  int n_;
  IkOptions options_;
  std::unique_ptr<Kdl> kdl_;
  int last_iterations_{0};
};

/// The error of pose X against target T in B: [p_T − p_X; ω] with R_T =
/// exp([ω]×) R_X, |ω| ≤ π (an accurate rotation log: atan2 of the sine and
/// cosine parts, not acos).
Vector6d PoseError(const Eigen::Isometry3d& T, const Eigen::Isometry3d& X);

}  // namespace robomach::kinematics
