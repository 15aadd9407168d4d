#include "dynamics/internal/body_on_springs.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "robomach/common/eigen_types.h"
#include "robomach/common/errors.h"

namespace robomach::dynamics::internal {
Matrix6d ShiftTwist(const Eigen::Vector3d& r) {
  Matrix6d X = Matrix6d::Identity();
  X.topRightCorner<3, 3>() = -Skew(r);
  return X;
}

Matrix6d SpatialInertiaAtCom(const kinematics::Inertial& b) {
  Matrix6d L = Matrix6d::Zero();
  L.topLeftCorner<3, 3>() = b.mass * Eigen::Matrix3d::Identity();
  L.bottomRightCorner<3, 3>() = b.inertia_com;
  return L;
}

Eigen::MatrixXd ModalDampingMatrix(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K,
                                   double zeta) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(K, M, Eigen::ComputeEigenvectors |
                                                                          Eigen::Ax_lBx);
  if (ges.info() != Eigen::Success) {
    throw NumericalError("modal damping: the mounted body's mass matrix is not positive definite");
  }
  const Eigen::VectorXd omega = ges.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  const Eigen::MatrixXd MPhi = M * ges.eigenvectors();
  return MPhi * (2.0 * zeta * omega).asDiagonal() * MPhi.transpose();
}

Matrix6Xd MountColumns(const SpringMount& mount) {
  const int k = static_cast<int>(mount.components.size());
  Matrix6Xd E = Matrix6Xd::Zero(6, k);
  for (int i = 0; i < k; ++i) {
    const int c = mount.components[i];
    if (c < 0 || c > 5) throw std::logic_error("SpringMount: component index out of [0, 5]");
    if (c < 3) E.block<3, 1>(0, i) = mount.R_BS.col(c);
    else E.block<3, 1>(3, i) = mount.R_BS.col(c - 3);
  }
  return E;
}

void MountBodyOnSprings(const SpringMount& mount, const Eigen::Vector3d& p_BT, double alpha,
                        int first_dof, AssembledSystem* sys) {
  const int k = static_cast<int>(mount.components.size());
  const int N = static_cast<int>(sys->M.rows());
  if (mount.K_S.rows() != k || mount.K_S.cols() != k || first_dof + k > N) {
    throw std::logic_error("SpringMount: stiffness size or DOF range does not fit the system");
  }
  // Twist map of the body at P over all coordinates, eq. (1).
  Matrix6Xd W = ShiftTwist(mount.p_BP - p_BT) * sys->V_T;
  const Matrix6Xd E = MountColumns(mount);
  W.middleCols(first_dof, k) += E;
  // ... and at its COM.
  const Matrix6Xd A = ShiftTwist(mount.body_B.com - mount.p_BP) * W;
  const Eigen::MatrixXd MA = A.transpose() * SpatialInertiaAtCom(mount.body_B) * A;
  // Eq. (2): the rows and columns of the new DOFs only.
  sys->M.middleRows(first_dof, k) += MA.middleRows(first_dof, k);
  sys->M.middleCols(first_dof, k) += MA.middleCols(first_dof, k);
  sys->M.block(first_dof, first_dof, k, k) -= MA.block(first_dof, first_dof, k, k);  // added twice
  sys->K.block(first_dof, first_dof, k, k) += mount.K_S;
  const Eigen::MatrixXd M_rr = MA.block(first_dof, first_dof, k, k);
  sys->C_extra.block(first_dof, first_dof, k, k) +=
      ModalDampingMatrix(M_rr, mount.K_S, mount.damping_ratio) - alpha * mount.K_S;
  if (mount.carries_tool_tip) {
    sys->V_T.middleCols(first_dof, k) = ShiftTwist(p_BT - mount.p_BP) * E;
    sys->B = sys->V_T.topRows<3>();
  }
}

}  // namespace robomach::dynamics::internal
