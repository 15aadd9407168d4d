#include "robomach/dynamics/gravity_torque.h"

#include <kdl/chaindynparam.hpp>

#include "kinematics/internal/kdl_status.h"

namespace robomach::dynamics {

Eigen::VectorXd GravityTorque(const RobotModel& model, const Eigen::VectorXd& q, double gravity) {
  kinematics::CheckJointVector(model.chain(), q);
  // A private copy: KDL::Joint caches its last pose in mutable members
  // (serial_chain.h), so solvers must not run on the shared chain.
  const KDL::Chain chain = model.chain().kdl();
  KDL::ChainDynParam dyn(chain, KDL::Vector(0.0, 0.0, -gravity));
  KDL::JntArray jq(chain.getNrOfJoints()), g(chain.getNrOfJoints());
  jq.data = q;
  kinematics::internal::ThrowIfKdlFailed(dyn.JntToGravity(jq, g), dyn, "GravityTorque");
  return g.data;
}

}  // namespace robomach::dynamics
