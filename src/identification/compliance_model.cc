#include "robomach/identification/compliance_model.h"

#include <cmath>
#include <stdexcept>

#include "robomach/common/eigen_types.h"
#include "robomach/common/errors.h"
#include "robomach/kinematics/serial_chain.h"

namespace robomach::identification {
Matrix6Xd ShiftJacobian(const Matrix6Xd& J_BT, const Eigen::Vector3d& r_TP_B) {
  Matrix6Xd J = J_BT;
  // v_P = v_T + ω × r = v_T − r × ω = v_T − [r]× ω.
  J.topRows<3>() -= Skew(r_TP_B) * J_BT.bottomRows<3>();
  return J;
}

Eigen::Vector3d TcpInTip(const dynamics::RobotModel& model) {
  // The TCP chain is the arm plus fixed segments; its pose relative to the
  // arm's tip is the same at every q, so q = 0 is as good as any.
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(model.num_joints());
  const Eigen::Isometry3d X_B_tip = kinematics::ForwardKinematics(model.description().arm, q0);
  const Eigen::Isometry3d X_B_tcp = kinematics::ForwardKinematics(model.chain(), q0);
  return (X_B_tip.inverse() * X_B_tcp).translation();
}

namespace {

CaseKinematics EvaluateAt(const dynamics::RobotModel& model, const Eigen::VectorXd& q,
                          const Eigen::Vector3d& p_L_tip, const Eigen::Vector3d& p_T_tip) {
  const kinematics::SerialChain& arm = model.description().arm;
  const Eigen::Isometry3d X_B_tip = kinematics::ForwardKinematics(arm, q);
  const Matrix6Xd J_tip = kinematics::Jacobian(arm, q);
  CaseKinematics k;
  const Eigen::Vector3d r_L = X_B_tip.linear() * p_L_tip;
  const Eigen::Vector3d r_T = X_B_tip.linear() * p_T_tip;
  k.p_BL = X_B_tip.translation() + r_L;
  k.p_BT = X_B_tip.translation() + r_T;
  k.Jv_L = ShiftJacobian(J_tip, r_L).topRows<3>();
  k.Jv_T = ShiftJacobian(J_tip, r_T).topRows<3>();
  return k;
}

void CheckQ(const dynamics::RobotModel& model, const LoadCase& c) {
  if (c.q.size() != model.num_joints()) {
    throw std::invalid_argument("load case " + c.case_id + ": q has " + std::to_string(c.q.size()) +
                                " entries, the robot has " + std::to_string(model.num_joints()) +
                                " joints");
  }
  if (!c.q.allFinite()) throw std::invalid_argument("load case " + c.case_id + ": non-finite q");
}

}  // namespace

CaseKinematics EvaluateCaseKinematics(const dynamics::RobotModel& model, const LoadCase& c) {
  CheckQ(model, c);
  const Eigen::Vector3d tcp = (c.p_load_tip && c.p_target_tip) ? Eigen::Vector3d::Zero()
                                                               : TcpInTip(model);
  return EvaluateAt(model, c.q, c.p_load_tip.value_or(tcp), c.p_target_tip.value_or(tcp));
}

Matrix3Xd DisplacementPerCompliance(const CaseKinematics& k, const Eigen::Vector3d& force) {
  const Eigen::RowVectorXd tau = force.transpose() * k.Jv_L;  // τ = J_L,vᵀ F [N·m]
  return k.Jv_T * tau.asDiagonal();
}

Eigen::Vector3d PredictDisplacement(const dynamics::RobotModel& model, const LoadCase& c,
                                    const Eigen::VectorXd& kq) {
  const CaseKinematics k = EvaluateCaseKinematics(model, c);
  return DisplacementPerCompliance(k, c.force) * kq.cwiseInverse();
}

Eigen::Vector3d SolveStaticDeflection(const dynamics::RobotModel& model, const LoadCase& c,
                                      const Eigen::VectorXd& kq) {
  CheckQ(model, c);
  const Eigen::Vector3d tcp = TcpInTip(model);
  const Eigen::Vector3d p_L = c.p_load_tip.value_or(tcp);
  const Eigen::Vector3d p_T = c.p_target_tip.value_or(tcp);
  const CaseKinematics k0 = EvaluateAt(model, c.q, p_L, p_T);
  // Fixed point of Δq = K⁻¹ J_L(q + Δq)ᵀ F: a contraction with factor
  // ~|K⁻¹ ∂(J_Lᵀ F)/∂q| ≈ |F|·reach/k ≈ 1e-4 for the loads of a tracker test,
  // so each step gains about four digits.
  Eigen::VectorXd dq = Eigen::VectorXd::Zero(c.q.size());
  for (int it = 0; it < 100; ++it) {
    const CaseKinematics k = EvaluateAt(model, c.q + dq, p_L, p_T);
    const Eigen::VectorXd next = (k.Jv_L.transpose() * c.force).cwiseQuotient(kq);
    const double change = (next - dq).lpNorm<Eigen::Infinity>();
    dq = next;
    if (change <= 1e-15 + 1e-13 * dq.lpNorm<Eigen::Infinity>()) {
      return EvaluateAt(model, c.q + dq, p_L, p_T).p_BT - k0.p_BT;
    }
  }
  throw NumericalError("SolveStaticDeflection: no equilibrium found for case " + c.case_id +
                           " (load far beyond the linear range?)");
}

}  // namespace robomach::identification
