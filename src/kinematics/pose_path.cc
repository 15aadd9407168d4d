#include "robomach/kinematics/pose_path.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/SVD>

#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"

namespace robomach::kinematics {

void PosePathOptions::Validate() const {
  ValidateNested("ik", ik);
  CheckOptionAbove("max_joint_step_rad", max_joint_step_rad, 0.0);
}

PosePathCheck CheckPosePath(const SerialChain& chain, const std::vector<Eigen::Isometry3d>& X_BT,
                            const Eigen::VectorXd& seed, const PosePathOptions& options) {
  options.Validate();
  const int n = chain.num_joints();
  if (seed.size() != n) {
    throw std::invalid_argument("CheckPosePath: the seed has " + std::to_string(seed.size()) + " joints, the chain " +
                                std::to_string(n));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  IkSolver ik(chain, options.ik);
  PosePathCheck c;
  const size_t N = X_BT.size();
  c.q.resize(N);
  c.reachable.assign(N, 0);
  c.limit_margin.assign(N, nan);
  c.condition.assign(N, nan);
  auto flag = [&](size_t r) {
    if (c.first_bad_row < 0) c.first_bad_row = static_cast<int>(r);
  };
  Eigen::VectorXd prev = seed;
  Eigen::VectorXd q;
  for (size_t r = 0; r < N; ++r) {
    bool reached = ik.Solve(X_BT[r], prev, &q);
    if (!reached) reached = ik.Solve(X_BT[r], seed, &q);
    if (!reached) {
      ++c.num_unreachable;
      flag(r);
      continue;
    }
    // Of the 2π branches of each joint, one inside its limits if there is one.
    for (int j = 0; j < n; ++j) {
      const JointLimits& lim = chain.limits()[j];
      if (!lim.bounded) continue;
      for (int k = -2; k <= 2 && (q(j) < lim.lower || q(j) > lim.upper); ++k) {
        const double alt = q(j) + 2.0 * kPi * k;
        if (alt >= lim.lower && alt <= lim.upper) q(j) = alt;
      }
    }
    if (r > 0 && c.reachable[r - 1] && (q - c.q[r - 1]).cwiseAbs().maxCoeff() > options.max_joint_step_rad) {
      ++c.num_jumps;
      flag(r);
    }
    c.reachable[r] = 1;
    c.q[r] = q;
    prev = q;
    double margin = 1e300;
    for (int j = 0; j < n; ++j) {
      const JointLimits& lim = chain.limits()[j];
      if (lim.bounded) margin = std::min({margin, q(j) - lim.lower, lim.upper - q(j)});
    }
    c.limit_margin[r] = margin;
    c.min_limit_margin = std::min(c.min_limit_margin, margin);
    if (margin < 0) {
      ++c.num_outside_limits;
      flag(r);
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Jacobian(chain, q));
    const Eigen::VectorXd& s = svd.singularValues();
    c.condition[r] = s(s.size() - 1) > 0 ? s(0) / s(s.size() - 1) : 1e300;
    c.max_condition = std::max(c.max_condition, c.condition[r]);
  }
  return c;
}

}  // namespace robomach::kinematics
