#include "robomach/drilling/drilling_sim.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <nlopt.hpp>

#include "robomach/common/option_checks.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "robomach/drilling/controller_kinds.h"

namespace robomach::drilling {
namespace {

constexpr double kDivergedError = DegToRad(10.0);  // |e| beyond this: the run has failed
constexpr double kDivergedCost = 1e6;

Eigen::Vector3d Unit(HoleAxis a) {
  switch (a) {
    case HoleAxis::kTipX: return Eigen::Vector3d::UnitX();
    case HoleAxis::kTipY: return Eigen::Vector3d::UnitY();
    case HoleAxis::kTipZ: return Eigen::Vector3d::UnitZ();
  }
  return Eigen::Vector3d::UnitZ();
}

// The tip-frame axis after `a` (x -> y -> z -> x): normal to the hole axis.
Eigen::Vector3d Next(HoleAxis a) {
  switch (a) {
    case HoleAxis::kTipX: return Eigen::Vector3d::UnitY();
    case HoleAxis::kTipY: return Eigen::Vector3d::UnitZ();
    case HoleAxis::kTipZ: return Eigen::Vector3d::UnitX();
  }
  return Eigen::Vector3d::UnitX();
}

// Orientation error of R against R_d as a rotation vector in B (small angles).
Eigen::Vector3d RotationError(const Eigen::Matrix3d& R_d, const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R_d * R.transpose());
  return aa.angle() * aa.axis();
}

}  // namespace

double TuningCost(const SimSeries& s, double period) {
  double J = 0.0;
  for (size_t k = 0; k < s.t.size(); ++k) J += s.t[k] * s.e.col(k).cwiseAbs().sum() * period;
  return J;
}

DrillingScenario::DrillingScenario(FlexibleJointRobot* robot, DrillGeometry drill,
                                   DrillingMaterial material, DrillingProcess process)
    : robot_(robot), drill_(drill), material_(material), process_(std::move(process)) {
  CheckValid(drill_);
  CheckValid(material_);
  const int n = robot_->num_joints();
  const Eigen::VectorXd& q0 = process_.initial_posture;
  if (q0.size() != n) {
    throw std::invalid_argument("initial_posture_deg has " + std::to_string(q0.size()) +
                                " angles, the robot has " + std::to_string(n) + " joints");
  }
  if (!(process_.control_period > 0.0 && process_.duration >= process_.control_period)) {
    throw std::invalid_argument("simulation: expected 0 < control_period_s <= duration_s");
  }
  axis_tip_ = Unit(process_.hole_axis);
  x_drill_tip_ = Next(process_.hole_axis);
  drill_axis_tip_ = Eigen::AngleAxisd(process_.initial_tilt, x_drill_tip_) * axis_tip_;
  const Eigen::Isometry3d X0 = robot_->TipPose(q0);
  hole_axis_B_ = X0.linear() * axis_tip_;

  // Can the tip move along the hole axis while keeping its orientation?
  Matrix6Xd J = robot_->TipJacobian(q0);
  Vector6d twist;
  twist << hole_axis_B_, Eigen::Vector3d::Zero();
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(J);
  const Eigen::VectorXd qdot = cod.solve(twist);
  const double residual = (J * qdot - twist).norm();
  if (!(residual < 1e-6)) {
    std::ostringstream s;
    s << "the robot cannot feed along the hole axis at the initial posture: moving the tip along "
      << "the hole axis (" << hole_axis_B_.transpose().format(Eigen::IOFormat(4, 0, ", ", ", "))
      << " in the base frame) with a fixed tool orientation leaves a residual of " << residual
      << " of the unit twist (the joints cannot produce that motion; choose another hole_axis or posture)";
    throw std::invalid_argument(s.str());
  }

  // Desired joint path: tip along the hole axis at the feed speed, fixed
  // orientation; resolved rates plus two Newton corrections per sample.
  const double L = process_.control_period;
  const int N = static_cast<int>(std::floor(process_.duration / L + 1e-9)) + 1;
  const double v = process_.feed_speed();
  q_d_.resize(n, N);
  q_d_.col(0) = q0;
  Eigen::VectorXd q = q0;
  for (int k = 1; k < N; ++k) {
    const Eigen::Vector3d p_target = X0.translation() + v * (k * L) * hole_axis_B_;
    for (int it = 0; it < 2; ++it) {
      const Eigen::Isometry3d X = robot_->TipPose(q);
      Vector6d err;
      err << p_target - X.translation(), RotationError(X0.linear(), X.linear());
      J = robot_->TipJacobian(q);
      q += Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(J).solve(err);
    }
    q_d_.col(k) = q;
  }
  qd_d_ = Eigen::MatrixXd::Zero(n, N);
  qdd_d_ = Eigen::MatrixXd::Zero(n, N);
  for (int k = 1; k < N; ++k) {
    qd_d_.col(k) = k + 1 < N ? (q_d_.col(k + 1) - q_d_.col(k - 1)) / (2 * L)
                             : (q_d_.col(k) - q_d_.col(k - 1)) / L;
  }
  for (int k = 1; k < N; ++k) qdd_d_.col(k) = (qd_d_.col(k) - qd_d_.col(k - 1)) / L;

  const Eigen::MatrixXd M = robot_->MassMatrix(q0);
  const Eigen::VectorXd& gear = robot_->gear_ratio();
  M_eff_ = gear.cwiseInverse().asDiagonal() *
           (M + Eigen::MatrixXd((gear.array().square() * robot_->rotor_inertia().array()).matrix().asDiagonal()));
  robot_->EquilibriumAt(q0, Eigen::VectorXd::Zero(n), &tau_hold_);
  modes_hz_ = robot_->PlantModesHz(q0);
  omega_max_ = robot_->HighestFreeModeRadS(q0);
  const double R = drill_.radius(), rc = drill_.chisel_half_length(), wt = drill_.web_half_thickness();
  const double d_full =
      (std::sqrt(R * R - wt * wt) - std::sqrt(rc * rc - wt * wt)) / std::tan(drill_.half_point_angle());
  t_full_ = d_full / v;
}

void SimOptions::Validate() const {
  for (Eigen::Index j = 0; j < motor_torque_limit.size(); ++j) {
    CheckOptionAtLeast("motor_torque_limit", motor_torque_limit(j), 0.0);
    CheckOptionFinite("motor_torque_limit", motor_torque_limit(j));
  }
  CheckOptionAbove("max_omega_h", max_omega_h, 0.0);
  CheckOptionRange("max_omega_h", max_omega_h, 0.0, 2.8);
}

SimResult DrillingScenario::Run(JointController& controller, const SimOptions& options) {
  options.Validate();
  const int n = robot_->num_joints();
  const int N = num_samples();
  const double L = process_.control_period;
  if (options.motor_torque_limit.size() != n) {
    throw std::invalid_argument("motor torque limits: expected one per joint");
  }
  SimResult out;
  out.controller = controller.name();
  out.gains = controller.gains();
  out.substeps = SubstepsFor(omega_max_, L, options.max_omega_h);
  const double h = L / out.substeps;
  SimSeries& s = out.series;
  if (options.record) {
    s.t.reserve(N);
    s.q.resize(n, N);
    s.e.resize(n, N);
    s.tau_m.resize(n, N);
    s.thrust.reserve(N);
    s.torque.reserve(N);
    s.offset.reserve(N);
  }
  const Eigen::VectorXd& q0 = process_.initial_posture;
  FlexibleJointState x = robot_->EquilibriumAt(q0, Eigen::VectorXd::Zero(n), nullptr);
  // The motor side starts wound up by the gravity load: reset the controller
  // with the link angle; its motor-side differences start from theta/n.
  controller.Reset(q0, tau_hold_);
  Rk4Integrator rk4(n);
  Eigen::VectorXd tau_m = tau_hold_, tau_ext(n), e(n), q_motor(n);
  Vector6d wrench;
  out.max_abs_error = Eigen::VectorXd::Zero(n);
  out.max_abs_error_last_10pc = Eigen::VectorXd::Zero(n);
  const int k_last10 = static_cast<int>(std::floor(0.9 * (N - 1)));
  int last_outside = -1;
  double cost = 0.0, th_min = 1e300, th_max = -1e300, th_sum = 0.0;
  int th_count = 0;
  const double v = process_.feed_speed();
  long next_progress = 0;
  for (int k = 0; k < N; ++k) {
    const double t = k * L;
    e = q_d_.col(k) - x.q;
    q_motor = x.theta.cwiseQuotient(robot_->gear_ratio());
    controller.Step(q_d_.col(k), qd_d_.col(k), qdd_d_.col(k), x.q, q_motor, &tau_m);
    // Drilling load at the current posture.
    const Eigen::Isometry3d X = robot_->TipPose(x.q);
    const Eigen::Vector3d a = X.linear() * drill_axis_tip_;
    const Eigen::Vector3d xd = (X.linear() * x_drill_tip_ - a * a.dot(X.linear() * x_drill_tip_)).normalized();
    const Eigen::Vector3d yd = a.cross(xd);
    const double tilt = std::acos(std::clamp(a.dot(hole_axis_B_), -1.0, 1.0));
    const DrillState ds{.feed_per_rev = process_.feed_per_rev,
                        .penetration = v * t,
                        .tilt = tilt,
                        .spindle_angle = std::fmod(process_.spindle_speed_rad_s * t, 2.0 * kPi)};
    const DrillForces F = ComputeDrillForces(drill_, material_, ds);
    wrench << -F.thrust * a + F.radial.x() * xd + F.radial.y() * yd, -F.torque * a;
    tau_ext = robot_->TipJacobian(x.q).transpose() * wrench;

    const double abs_max = e.cwiseAbs().maxCoeff();
    if (!x.q.allFinite() || !(abs_max < kDivergedError)) {
      out.diverged = true;
      break;
    }
    out.max_abs_error = out.max_abs_error.cwiseMax(e.cwiseAbs());
    if (k >= k_last10) out.max_abs_error_last_10pc = out.max_abs_error_last_10pc.cwiseMax(e.cwiseAbs());
    if (abs_max > process_.error_band) last_outside = k;
    cost += t * e.cwiseAbs().sum() * L;
    if (t >= t_full_) {
      th_min = std::min(th_min, F.thrust);
      th_max = std::max(th_max, F.thrust);
      th_sum += F.thrust;
      ++th_count;
    }
    if (options.record) {
      s.t.push_back(t);
      s.q.col(k) = x.q;
      s.e.col(k) = e;
      s.tau_m.col(k) = tau_m;
      s.thrust.push_back(F.thrust);
      s.torque.push_back(F.torque);
      s.offset.push_back(tilt);
    }
    for (int i = 0; i < out.substeps; ++i) rk4.Step(*robot_, tau_m, tau_ext, h, &x);
    if (options.progress && k >= next_progress) {
      options.progress(k, N);
      next_progress = k + std::max(1, N / 100);
    }
  }
  if (options.progress) options.progress(N, N);
  if (out.diverged) {
    if (options.record) {
      const int m = static_cast<int>(s.t.size());
      s.q.conservativeResize(n, m);
      s.e.conservativeResize(n, m);
      s.tau_m.conservativeResize(n, m);
    }
    out.cost = kDivergedCost;
    out.settling_time = NAN;
    return out;
  }
  out.cost = cost;
  out.settling_time = last_outside < 0 ? 0.0 : (last_outside == N - 1 ? NAN : last_outside * L);
  if (th_count > 0) {
    out.thrust = {th_min, th_max, th_sum / th_count, true};
  }
  return out;
}

std::unique_ptr<JointController> MakeController(const ControllerParameters& p,
                                                const DrillingScenario& sc,
                                                const Eigen::VectorXd& limit) {
  return FindControllerKind(p.kind).Make(p, sc.effective_inertia().diagonal(), sc.process().control_period, limit);
}

ControllerParameters DefaultParameters(const std::string& kind) { return FindControllerKind(kind).defaults(); }

TuneResult TuneController(const ControllerParameters& start, DrillingScenario& scenario,
                          const SimOptions& options, int max_evaluations) {
  options.Validate();
  ControllerParameters p = start;
  const ControllerKind& kind = FindControllerKind(p.kind);
  const bool third = !kind.third_parameter().empty();
  const int dim = third ? 3 : 2;
  // Bounds: w from a slow 2 rad/s to 1/4 of the control rate (the sampled
  // loop needs w L well below 1); zeta 0.2..3; the third parameter's from
  // its ControllerKind (pid: r 1..100; pd-tdc: alpha 0.01..1.95).
  const double wmax = 0.25 / scenario.process().control_period;
  std::vector<double> lo = {std::log(2.0), std::log(0.2)}, hi = {std::log(wmax), std::log(3.0)};
  if (third) {
    lo.push_back(std::log(kind.third_bounds().first));
    hi.push_back(std::log(kind.third_bounds().second));
  }
  std::vector<double> x = {std::log(p.omega), std::log(p.zeta)};
  if (third) x.push_back(std::log(p.third));
  for (int i = 0; i < dim; ++i) x[i] = std::clamp(x[i], lo[i], hi[i]);

  SimOptions run = options;
  run.record = false;
  run.progress = nullptr;
  // Tuning only ranks gains: RK4 at omega_max h <= 0.2 (amplitude error
  // 4e-7 and phase error 3e-6 rad per step in the highest mode) is ample
  // for that and 3x faster; the reported run uses options.max_omega_h.
  run.max_omega_h = std::max(options.max_omega_h, 0.2);
  struct Ctx {
    ControllerParameters base;
    DrillingScenario* sc;
    SimOptions* run;
    int evals{0};
    double first_cost{NAN};  // the start's (as BOBYQA places it): the test of kNotImproved
  } ctx{p, &scenario, &run};
  auto f = [](const std::vector<double>& xv, std::vector<double>&, void* data) -> double {
    Ctx* c = static_cast<Ctx*>(data);
    ControllerParameters q = c->base;
    q.omega = std::exp(xv[0]);
    q.zeta = std::exp(xv[1]);
    if (xv.size() > 2) q.third = std::exp(xv[2]);
    auto ctl = MakeController(q, *c->sc, c->run->motor_torque_limit);
    const double cost = c->sc->Run(*ctl, *c->run).cost;
    if (++c->evals == 1) c->first_cost = cost;
    return cost;
  };
  nlopt::opt opt(nlopt::LN_BOBYQA, dim);
  opt.set_lower_bounds(lo);
  opt.set_upper_bounds(hi);
  opt.set_min_objective(f, &ctx);
  opt.set_maxeval(max_evaluations);
  opt.set_xtol_rel(1e-3);
  std::vector<double> step(dim, 0.3);
  opt.set_initial_step(step);
  double fx = 0.0;
  TuneResult out;
  bool stopped_early = false;  // at max_evaluations or on round-off, not on the tolerance
  try {
    const nlopt::result r = opt.optimize(x, fx);
    stopped_early = r == nlopt::MAXEVAL_REACHED;
    out.message = stopped_early ? "max_evaluations" : "converged";
  } catch (const nlopt::roundoff_limited&) {
    stopped_early = true;
    out.message = "roundoff_limited";
    fx = f(x, step, &ctx);
  }
  p.omega = std::exp(x[0]);
  p.zeta = std::exp(x[1]);
  if (third) p.third = std::exp(x[2]);
  out.parameters = p;
  out.cost = fx;
  out.evaluations = ctx.evals;
  // Every run diverged (each costs kDivergedCost): no usable gains.
  out.status = !(fx < kDivergedCost)      ? SolverStatus::kFailed
               : !(fx < ctx.first_cost)   ? SolverStatus::kNotImproved
               : stopped_early            ? SolverStatus::kNotConverged
                                          : SolverStatus::kConverged;
  return out;
}

ControllerParameters ParametersFromGains(const std::string& kind, const std::vector<double>& v) {
  ControllerParameters p = DefaultParameters(kind);
  auto positive = [](double x) { return x > 0.0 && std::isfinite(x); };
  if (v.size() < 2 || v.size() > 4 || !positive(v[0]) || !positive(v[1]) || (v.size() >= 3 && !positive(v[2])) ||
      (v.size() == 4 && !(v[3] >= 0.0 && std::isfinite(v[3])))) {
    throw std::invalid_argument("expected 2 to 4 numbers after " + kind +
                                "=: omega_rad_s and zeta > 0, the third parameter > 0, the filter time constant "
                                ">= 0 [s]");
  }
  p.omega = v[0];
  p.zeta = v[1];
  if (v.size() >= 3) p.third = v[2];
  if (v.size() == 4) p.filter_time_constant = v[3];
  return p;
}

}  // namespace robomach::drilling
