#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <kdl/chain.hpp>

#include "robomach/common/eigen_types.h"

namespace robomach::kinematics {

/// Rigid-body inertial parameters of one body, expressed in the body's frame.
struct Inertial {
  double mass{0.0};                                      // [kg]
  Eigen::Vector3d com{Eigen::Vector3d::Zero()};          // [m], in the body frame
  Eigen::Matrix3d inertia_com{Eigen::Matrix3d::Zero()};  // [kg·m²] about the COM, body axes
};

/// Why `inertial` is not physical, or nullopt if it is: negative mass, a
/// non-symmetric or non-positive-definite inertia, or principal moments that
/// violate the triangle inequality (I1 + I2 >= I3 for every permutation).
/// A zero mass with a zero inertia is a valid massless body.
std::optional<std::string> CheckInertial(const Inertial& inertial);

/// The same body seen from another frame: `X_AB` is the pose of the body
/// frame B in A; the result is expressed in A.
Inertial TransformInertial(const Inertial& in_B, const Eigen::Isometry3d& X_AB);

/// Sum of rigid bodies expressed in the same frame (parallel-axis theorem).
Inertial CombineInertials(const Inertial& a, const Inertial& b);

/// Joint position limits [rad]; `bounded` is false for continuous joints.
struct JointLimits {
  double lower{-1e300};
  double upper{1e300};
  bool bounded{false};
};

/// A serial chain of rigid links joined by revolute joints, built on
/// KDL::Chain. Immutable; copies share the KDL chain. KDL::Joint caches its
/// last pose in mutable members, so never run a KDL solver on kdl() from two
/// threads: bind solvers to a private copy (as the functions below and
/// dynamics::PostureEvaluator do).
///
/// Conventions: the chain starts at the base frame B and ends at the tip
/// frame of its last segment. Jacobians refer to the tip of the last segment,
/// expressed in B, rows [v; ω] (frames.h).
class SerialChain {
 public:
  SerialChain() = default;
  /// @throws std::invalid_argument if the numbers of movable joints, names
  ///   and limits differ, or a joint is prismatic (not supported).
  SerialChain(KDL::Chain chain, std::vector<std::string> joint_names,
              std::vector<JointLimits> limits, std::string base_name, std::string tip_name);

  int num_joints() const { return static_cast<int>(joint_names_.size()); }
  int num_segments() const { return static_cast<int>(chain_->getNrOfSegments()); }
  const KDL::Chain& kdl() const { return *chain_; }
  const std::vector<std::string>& joint_names() const { return joint_names_; }
  const std::vector<JointLimits>& limits() const { return limits_; }
  const std::string& base_name() const { return base_name_; }
  const std::string& tip_name() const { return tip_name_; }

  /// Inertial of segment `i`, in the segment's tip frame.
  Inertial segment_inertial(int i) const;
  /// Index of the last segment with a movable joint (-1 if none).
  int last_moving_segment() const;

  /// A copy with segment i's inertia replaced.
  SerialChain WithSegmentInertial(int i, const Inertial& inertial) const;
  /// A copy with a fixed segment appended: its frame is `X_tip_new` in the
  /// current tip frame, its body `inertial` in the new frame.
  SerialChain WithFixedSegment(const std::string& name, const Eigen::Isometry3d& X_tip_new,
                               const Inertial& inertial) const;

  /// Indices of joints outside their limits at q (with a tolerance of 1e-9 rad).
  std::vector<int> JointsOutsideLimits(const Eigen::VectorXd& q) const;

 private:
  std::shared_ptr<const KDL::Chain> chain_;
  std::vector<std::string> joint_names_;
  std::vector<JointLimits> limits_;
  std::string base_name_;
  std::string tip_name_;
};

/// Pose of the chain's tip in the base frame at q [rad].
Eigen::Isometry3d ForwardKinematics(const SerialChain& chain, const Eigen::VectorXd& q);
/// Pose of the tip frame of segment `segment` (0-based) in the base frame.
Eigen::Isometry3d SegmentPose(const SerialChain& chain, const Eigen::VectorXd& q, int segment);
/// Geometric Jacobian J_BT of the tip at q (6×n, rows [v; ω], in B).
Matrix6Xd Jacobian(const SerialChain& chain, const Eigen::VectorXd& q);

/// Conversions between KDL and Eigen.
Eigen::Isometry3d ToEigen(const KDL::Frame& f);
KDL::Frame ToKdl(const Eigen::Isometry3d& X);
KDL::RigidBodyInertia ToKdl(const Inertial& inertial);

/// Throws std::invalid_argument "q has 5 entries, the robot has 6 joints".
void CheckJointVector(const SerialChain& chain, const Eigen::VectorXd& q);

}  // namespace robomach::kinematics
