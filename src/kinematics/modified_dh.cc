#include "robomach/kinematics/modified_dh.h"

#include <stdexcept>

namespace robomach::kinematics {

SerialChain BuildModifiedDhChain(const std::vector<ModifiedDhRow>& rows,
                                 const Eigen::Isometry3d& X_B0, const Eigen::Isometry3d& X_nT,
                                 const std::string& base_name, const std::string& tip_name) {
  KDL::Chain chain;
  std::vector<std::string> names;
  std::vector<JointLimits> limits;
  if (!X_B0.isApprox(Eigen::Isometry3d::Identity(), 0.0)) {
    chain.addSegment(KDL::Segment("dh_base", KDL::Joint("dh_base", KDL::Joint::None), ToKdl(X_B0)));
  }
  for (const ModifiedDhRow& r : rows) {
    if (auto problem = CheckInertial(r.inertial)) {
      throw std::invalid_argument("link of joint '" + r.joint_name + "': " + *problem);
    }
    // f = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_offset) Tz(d_i); the joint
    // rotates about f's z axis through f's origin, so the segment pose is
    // f · Rz(q), which equals T_{i-1,i} with theta_i = q + offset.
    const KDL::Frame f = KDL::Frame::DH_Craig1989(r.a_prev, r.alpha_prev, r.d, r.theta_offset);
    const KDL::Joint joint(r.joint_name, f.p, f.M.UnitZ(), KDL::Joint::RotAxis);
    chain.addSegment(KDL::Segment(r.joint_name, joint, f, ToKdl(r.inertial)));
    names.push_back(r.joint_name);
    limits.push_back(r.limits);
  }
  chain.addSegment(KDL::Segment(tip_name, KDL::Joint(tip_name, KDL::Joint::None), ToKdl(X_nT)));
  return SerialChain(std::move(chain), std::move(names), std::move(limits), base_name, tip_name);
}

}  // namespace robomach::kinematics
