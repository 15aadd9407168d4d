#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "robomach/kinematics/serial_chain.h"

namespace robomach::kinematics {

/// One row of a modified Denavit-Hartenberg table [Craig 2005, §3.4]:
/// the transform from frame i-1 to frame i is
/// <pre>
///   T_{i-1,i} = Rx(alpha_{i-1}) · Tx(a_{i-1}) · Rz(theta_i) · Tz(d_i),
///   theta_i   = q_i + theta_offset_i.                                (3.6)
/// </pre>
/// The link's inertial is expressed in frame i.
struct ModifiedDhRow {
  std::string joint_name;
  double alpha_prev{0.0};    // alpha_{i-1} [rad]
  double a_prev{0.0};        // a_{i-1} [m]
  double d{0.0};             // d_i [m]
  double theta_offset{0.0};  // [rad]
  JointLimits limits;
  Inertial inertial;         // link i, in frame i
};

/// Builds a revolute serial chain from a modified-DH table.
/// `X_B0` places DH frame 0 in the robot base frame B; `X_nT` places the tip
/// frame in the last DH frame (both fixed).
///
/// KDL's `Segment(Joint(RotZ), Frame::DH_Craig1989(...))` would apply the
/// joint rotation *before* the DH transform, which is wrong for Craig's
/// convention; each segment is therefore a rotation about the z axis of frame
/// i, placed at the origin of T_{i-1,i} (style.md §4), and the offset lives in
/// the frame, because KDL cancels a joint offset passed to Joint().
///
/// - [Craig 2005] J. J. Craig, Introduction to Robotics: Mechanics and
///   Control, 3rd ed., Pearson, 2005.
SerialChain BuildModifiedDhChain(const std::vector<ModifiedDhRow>& rows,
                                 const Eigen::Isometry3d& X_B0,
                                 const Eigen::Isometry3d& X_nT,
                                 const std::string& base_name = "base",
                                 const std::string& tip_name = "tip");

}  // namespace robomach::kinematics
