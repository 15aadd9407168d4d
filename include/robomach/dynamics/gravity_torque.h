#pragma once

#include <Eigen/Core>

#include "robomach/common/units.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

/// Static gravity torque on the joints at posture q: the generalised force
/// G(q) = ∂V/∂q of the gravitational potential V(q) = −Σ_i m_i gᵀ c_i(q) of
/// the model's chain (the arm's links and the end effector as built with m6
/// and d6), with g = (0, 0, −gravity) in the base frame B (a floor-mounted
/// robot, base z up). G_j is the torque the drive of joint j must supply to
/// hold the posture [N·m]; it is what the robot's own weight loads its
/// gears with. Bodies that effects add (tip_mass, an interface-mounted
/// holder) are not in the chain and not included.
///
/// Computed by KDL's recursive Newton–Euler gravity term
/// (ChainDynParam::JntToGravity) on a private copy of the chain, so a shared
/// model is safe across threads.
///
/// @param model   robot model; not modified.
/// @param q       joint angles [rad], size model.num_joints().
/// @param gravity magnitude of gravity along −z of B [m/s²].
/// @returns G(q), one entry per joint [N·m].
/// @throws std::invalid_argument if q has the wrong size or is not finite.
Eigen::VectorXd GravityTorque(const RobotModel& model, const Eigen::VectorXd& q,
                              double gravity = kStandardGravity);

}  // namespace robomach::dynamics
