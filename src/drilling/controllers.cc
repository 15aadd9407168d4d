#include "robomach/drilling/controllers.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/LU>
#include <Eigen/SVD>

namespace robomach::drilling {
namespace {

void CheckSizes(int n, std::initializer_list<const Eigen::VectorXd*> vs, const char* what) {
  for (const Eigen::VectorXd* v : vs) {
    if (v->size() != n) throw std::invalid_argument(std::string(what) + ": gain vectors differ in size");
    if ((v->array() < 0.0).any() || !v->allFinite()) {
      throw std::invalid_argument(std::string(what) + ": gains and limits must be finite and >= 0");
    }
  }
}

}  // namespace

PidController::PidController(PidGains gains, Eigen::VectorXd torque_limit, double period)
    : JointController(period), gains_(std::move(gains)), limit_(std::move(torque_limit)) {
  const int n = static_cast<int>(gains_.kp.size());
  CheckSizes(n, {&gains_.kp, &gains_.ki, &gains_.kd, &limit_}, "PID");
  if (!(period > 0.0)) throw std::invalid_argument("PID: control period must be > 0");
  if (!(gains_.derivative_filter_time_constant >= 0.0)) {
    throw std::invalid_argument("PID: filter time constant must be >= 0");
  }
  tau_hold_ = integral_ = e_prev_ = ed_ = u_ = Eigen::VectorXd::Zero(n);
}

void PidController::Reset(const Eigen::VectorXd& /*q0*/, const Eigen::VectorXd& tau_m0) {
  e_prev_.setZero();
  ed_.setZero();
  first_ = true;
  tau_hold_.setZero();
  integral_.setZero();
  for (int j = 0; j < tau_m0.size(); ++j) {
    // Bumpless start: the integrator holds the equilibrium torque (PID); a
    // PD keeps it as a constant feed-forward.
    if (gains_.ki(j) > 0.0) integral_(j) = tau_m0(j) / gains_.ki(j);
    else tau_hold_(j) = tau_m0(j);
  }
}

void PidController::Step(const Eigen::VectorXd& q_d, const Eigen::VectorXd& /*qd_d*/,
                         const Eigen::VectorXd& /*qdd_d*/, const Eigen::VectorXd& q,
                         const Eigen::VectorXd& q_motor, Eigen::VectorXd* tau_m) {
  const double a = gains_.derivative_filter_time_constant > 0.0
                       ? period_ / (period_ + gains_.derivative_filter_time_constant)
                       : 1.0;
  for (int j = 0; j < q.size(); ++j) {
    const double e = q_d(j) - q(j);
    const double em = q_d(j) - q_motor(j);  // motor-side error, for the rate
    const double ed_raw = first_ ? 0.0 : (em - e_prev_(j)) / period_;
    ed_(j) += a * (ed_raw - ed_(j));
    const double ed = ed_(j);
    e_prev_(j) = em;
    const double i_next = integral_(j) + e * period_;
    double u = tau_hold_(j) + gains_.kp(j) * e + gains_.ki(j) * i_next + gains_.kd(j) * ed;
    const double lim = limit_(j);
    if (u > lim || u < -lim) {
      // Conditional integration: keep the integral unless the error pulls
      // the output back from the limit.
      const bool pulls_back = (u > lim && e < 0.0) || (u < -lim && e > 0.0);
      if (pulls_back) integral_(j) = i_next;
      u = std::clamp(tau_hold_(j) + gains_.kp(j) * e + gains_.ki(j) * integral_(j) + gains_.kd(j) * ed,
                     -lim, lim);
    } else {
      integral_(j) = i_next;
    }
    (*tau_m)(j) = u;
  }
  first_ = false;
}

std::vector<std::pair<std::string, Eigen::VectorXd>> PidController::gains() const {
  Eigen::VectorXd tf =
      Eigen::VectorXd::Constant(gains_.kp.size(), gains_.derivative_filter_time_constant);
  if (!gains_.ki.any()) {
    return {{"kp_Nm_per_rad", gains_.kp}, {"kd_Nms_per_rad", gains_.kd},
            {"derivative_filter_time_constant_s", tf}};
  }
  return {{"kp_Nm_per_rad", gains_.kp},
          {"ki_Nm_per_rad_s", gains_.ki},
          {"kd_Nms_per_rad", gains_.kd},
          {"derivative_filter_time_constant_s", tf}};
}

PdTdcController::PdTdcController(PdTdcGains gains, Eigen::VectorXd torque_limit, double period)
    : JointController(period), gains_(std::move(gains)), limit_(std::move(torque_limit)) {
  const int n = static_cast<int>(gains_.kp.size());
  CheckSizes(n, {&gains_.kp, &gains_.kd, &gains_.mbar, &limit_}, "PD-TDC");
  if (!(period > 0.0)) throw std::invalid_argument("PD-TDC: control period must be > 0");
  if (!(gains_.accel_filter_time_constant >= 0.0)) {
    throw std::invalid_argument("PD-TDC: filter time constant must be >= 0");
  }
  tau_prev_ = q1_ = q2_ = e_prev_ = qdd_est_ = u_ = Eigen::VectorXd::Zero(n);
}

void PdTdcController::Reset(const Eigen::VectorXd& q0, const Eigen::VectorXd& tau_m0) {
  tau_prev_ = tau_m0;
  q1_ = q2_ = q0;  // at rest before the start
  e_prev_.setZero();
  qdd_est_.setZero();
  steps_ = 0;
}

void PdTdcController::Step(const Eigen::VectorXd& q_d, const Eigen::VectorXd& qd_d,
                           const Eigen::VectorXd& qdd_d, const Eigen::VectorXd& q,
                           const Eigen::VectorXd& q_motor, Eigen::VectorXd* tau_m) {
  (void)qd_d;
  const double L = period_;
  const double a = gains_.accel_filter_time_constant > 0.0
                       ? L / (L + gains_.accel_filter_time_constant)
                       : 1.0;
  for (int j = 0; j < q.size(); ++j) {
    if (steps_ == 0) q1_(j) = q2_(j) = q_motor(j);  // at rest before the start
    const double e = q_d(j) - q(j);
    const double em = q_d(j) - q_motor(j);
    const double ed = steps_ == 0 ? 0.0 : (em - e_prev_(j)) / L;
    e_prev_(j) = em;
    // q''(t - L) from the second backward difference (centred at t - L).
    const double qdd_raw = (q_motor(j) - 2.0 * q1_(j) + q2_(j)) / (L * L);
    qdd_est_(j) += a * (qdd_raw - qdd_est_(j));
    const double u = gains_.mbar(j) * (qdd_d(j) + gains_.kd(j) * ed + gains_.kp(j) * e) +
                     tau_prev_(j) - gains_.mbar(j) * qdd_est_(j);
    const double sat = std::clamp(u, -limit_(j), limit_(j));
    (*tau_m)(j) = sat;
    tau_prev_(j) = sat;
    q2_(j) = q1_(j);
    q1_(j) = q_motor(j);
  }
  ++steps_;
}

std::vector<std::pair<std::string, Eigen::VectorXd>> PdTdcController::gains() const {
  Eigen::VectorXd tf = Eigen::VectorXd::Constant(gains_.kp.size(), gains_.accel_filter_time_constant);
  return {{"kp_per_s2", gains_.kp},
          {"kd_per_s", gains_.kd},
          {"mbar_Nms2_per_rad", gains_.mbar},
          {"accel_filter_time_constant_s", tf}};
}

double TdeStabilityMeasure(const Eigen::MatrixXd& M_eff, const Eigen::VectorXd& mbar) {
  const int n = static_cast<int>(mbar.size());
  const Eigen::MatrixXd A =
      Eigen::MatrixXd::Identity(n, n) - M_eff.partialPivLu().solve(Eigen::MatrixXd(mbar.asDiagonal()));
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  return svd.singularValues()(0);
}

}  // namespace robomach::drilling
