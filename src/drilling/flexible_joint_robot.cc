// Spong's reduced elastic-joint model (seed 003 eq. 1) on KDL's dynamics.
//
// - [Spong 1987] M. W. Spong, Modeling and control of elastic joint robots,
//   ASME J. Dyn. Syst. Meas. Control 109(4), 310-319.
#include "robomach/drilling/flexible_joint_robot.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "robomach/common/units.h"

namespace robomach::drilling {

struct FlexibleJointRobot::Kdl {
  KDL::Chain chain;
  KDL::ChainDynParam dyn;
  KDL::ChainIdSolver_RNE rne;   // C q' + G in one pass (q'' = 0)
  KDL::ChainFkSolverPos_recursive fk;
  KDL::ChainJntToJacSolver jac;
  KDL::JntArray q_kin;          // for TipPose / TipJacobian
  KDL::Frame X;
  KDL::Jacobian J;
  KDL::JntArray q, qd, qdd, c, g, h;
  KDL::JntSpaceInertiaMatrix M;
  KDL::Wrenches no_wrench;
  Kdl(const KDL::Chain& ch, int n)
      : chain(ch),
        dyn(chain, KDL::Vector(0.0, 0.0, -kStandardGravity)),
        rne(chain, KDL::Vector(0.0, 0.0, -kStandardGravity)),
        fk(chain),
        jac(chain),
        q_kin(n),
        J(n),
        q(n), qd(n), qdd(n), c(n), g(n), h(n), M(n),
        no_wrench(chain.getNrOfSegments(), KDL::Wrench::Zero()) {}
};

FlexibleJointRobot::FlexibleJointRobot(kinematics::SerialChain chain, std::vector<JointDrive> drives)
    : chain_(std::move(chain)), drives_(std::move(drives)), n_(chain_.num_joints()) {
  if (static_cast<int>(drives_.size()) != n_) {
    throw std::invalid_argument("flexible joints: " + std::to_string(drives_.size()) +
                                " drives for a robot with " + std::to_string(n_) + " joints");
  }
  K_.resize(n_);
  D_.resize(n_);
  Jm_.resize(n_);
  gear_.resize(n_);
  for (int j = 0; j < n_; ++j) {
    const JointDrive& d = drives_[j];
    const std::string name = chain_.joint_names()[j];
    if (!(d.stiffness > 0.0 && std::isfinite(d.stiffness))) {
      throw std::invalid_argument(name + ": stiffness must be > 0");
    }
    if (!(d.gear_ratio > 0.0 && std::isfinite(d.gear_ratio))) {
      throw std::invalid_argument(name + ": gear ratio must be > 0");
    }
    if (!(d.rotor_inertia > 0.0 && std::isfinite(d.rotor_inertia))) {
      throw std::invalid_argument(name + ": rotor inertia must be > 0");
    }
    if (!(d.damping >= 0.0 && std::isfinite(d.damping))) {
      throw std::invalid_argument(name + ": damping must be >= 0");
    }
    K_(j) = d.stiffness;
    D_(j) = d.damping;
    Jm_(j) = d.rotor_inertia;
    gear_(j) = d.gear_ratio;
  }
  kdl_ = std::make_unique<Kdl>(chain_.kdl(), n_);
  M_.resize(n_, n_);
  c_.resize(n_);
  g_.resize(n_);
  tau_.resize(n_);
  rhs_.resize(n_);
  llt_ = Eigen::LLT<Eigen::MatrixXd>(n_);
}

FlexibleJointRobot::~FlexibleJointRobot() = default;

void FlexibleJointRobot::LinkTerms(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                   Eigen::MatrixXd* M, Eigen::VectorXd* c, Eigen::VectorXd* g) {
  kinematics::CheckJointVector(chain_, q);
  kdl_->q.data = q;
  kdl_->qd.data = qd;
  if (M) {
    kdl_->dyn.JntToMass(kdl_->q, kdl_->M);
    *M = kdl_->M.data;
  }
  if (c) {
    kdl_->dyn.JntToCoriolis(kdl_->q, kdl_->qd, kdl_->c);
    *c = kdl_->c.data;
  }
  if (g) {
    kdl_->dyn.JntToGravity(kdl_->q, kdl_->g);
    *g = kdl_->g.data;
  }
}

Eigen::VectorXd FlexibleJointRobot::Gravity(const Eigen::VectorXd& q) {
  Eigen::VectorXd g(n_);
  LinkTerms(q, Eigen::VectorXd::Zero(n_), nullptr, nullptr, &g);
  return g;
}

Eigen::MatrixXd FlexibleJointRobot::MassMatrix(const Eigen::VectorXd& q) {
  Eigen::MatrixXd M(n_, n_);
  LinkTerms(q, Eigen::VectorXd::Zero(n_), &M, nullptr, nullptr);
  return M;
}

void FlexibleJointRobot::Derivative(const FlexibleJointState& x, const Eigen::VectorXd& tau_m,
                                    const Eigen::VectorXd& tau_ext, FlexibleJointState* dx) {
  // KDL works on its own JntArrays: copy without allocating.
  kdl_->q.data = x.q;
  kdl_->qd.data = x.qd;
  kdl_->dyn.JntToMass(kdl_->q, kdl_->M);
  // Recursive Newton-Euler with q'' = 0 gives C(q, q') q' + G(q) in one pass.
  kdl_->rne.CartToJnt(kdl_->q, kdl_->qd, kdl_->qdd, kdl_->no_wrench, kdl_->h);
  // (3): tau = K (theta/n - q) + D (theta'/n - q')
  tau_.array() = K_.array() * (x.theta.array() / gear_.array() - x.q.array()) +
                 D_.array() * (x.thetad.array() / gear_.array() - x.qd.array());
  rhs_ = tau_ + tau_ext - kdl_->h.data;
  llt_.compute(kdl_->M.data);
  llt_.solveInPlace(rhs_);
  dx->q = x.qd;
  dx->qd = rhs_;
  dx->theta = x.thetad;
  // (2): J_m theta'' = tau_m - tau / n
  dx->thetad.array() = (tau_m.array() - tau_.array() / gear_.array()) / Jm_.array();
}

double FlexibleJointRobot::Energy(const FlexibleJointState& x) {
  const Eigen::MatrixXd M = MassMatrix(x.q);
  double e = 0.5 * x.qd.dot(M * x.qd);
  e += 0.5 * (Jm_.array() * x.thetad.array().square()).sum();
  const Eigen::ArrayXd stretch = x.theta.array() / gear_.array() - x.q.array();
  e += 0.5 * (K_.array() * stretch.square()).sum();
  // Gravity potential from the centres of mass (forward kinematics).
  for (int s = 0; s < chain_.num_segments(); ++s) {
    const kinematics::Inertial in = chain_.segment_inertial(s);
    if (in.mass == 0.0) continue;
    const Eigen::Isometry3d X = kinematics::SegmentPose(chain_, x.q, s);
    e += in.mass * kStandardGravity * (X * in.com).z();
  }
  return e;
}

FlexibleJointState FlexibleJointRobot::EquilibriumAt(const Eigen::VectorXd& q0,
                                                     const Eigen::VectorXd& tau_ext,
                                                     Eigen::VectorXd* tau_m_hold) {
  const Eigen::VectorXd g = Gravity(q0);
  FlexibleJointState x;
  x.q = q0;
  x.qd = Eigen::VectorXd::Zero(n_);
  x.theta = gear_.array() * (q0.array() + (g - tau_ext).array() / K_.array());
  x.thetad = Eigen::VectorXd::Zero(n_);
  if (tau_m_hold) *tau_m_hold = (g - tau_ext).array() / gear_.array();
  return x;
}

Eigen::VectorXd FlexibleJointRobot::PlantModesHz(const Eigen::VectorXd& q0) {
  const Eigen::MatrixXd M = MassMatrix(q0);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(K_.asDiagonal()), M);
  Eigen::VectorXd f = es.eigenvalues().cwiseMax(0.0).cwiseSqrt() / (2.0 * kPi);
  std::sort(f.data(), f.data() + f.size());
  return f;
}

double FlexibleJointRobot::HighestFreeModeRadS(const Eigen::VectorXd& q0) {
  // Coordinates (q, theta): mass diag(M, J_m); stiffness from
  // 1/2 (theta/n - q)^T K (theta/n - q).
  const Eigen::MatrixXd M = MassMatrix(q0);
  Eigen::MatrixXd Mf = Eigen::MatrixXd::Zero(2 * n_, 2 * n_), Kf = Mf;
  Mf.topLeftCorner(n_, n_) = M;
  Mf.bottomRightCorner(n_, n_) = Jm_.asDiagonal();
  for (int j = 0; j < n_; ++j) {
    Kf(j, j) = K_(j);
    Kf(n_ + j, n_ + j) = K_(j) / (gear_(j) * gear_(j));
    Kf(j, n_ + j) = Kf(n_ + j, j) = -K_(j) / gear_(j);
  }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Kf, Mf);
  double w2 = es.eigenvalues().maxCoeff();
  // Damping adds a real pole near -D/M_jj; count it like a frequency.
  for (int j = 0; j < n_; ++j) w2 = std::max(w2, std::pow(D_(j) / M(j, j), 2));
  return std::sqrt(std::max(w2, 0.0));
}

// KDL solvers bound to this robot's own chain copy (kinematics::
// ForwardKinematics and Jacobian build new solvers per call; the simulation
// calls these once per control period). Same conventions: tip of the last
// segment, Jacobian rows [v; w] in the base frame, reference point at the tip.
Eigen::Isometry3d FlexibleJointRobot::TipPose(const Eigen::VectorXd& q) const {
  kinematics::CheckJointVector(chain_, q);
  kdl_->q_kin.data = q;
  if (kdl_->fk.JntToCart(kdl_->q_kin, kdl_->X) < 0) throw std::runtime_error("TipPose: KDL error");
  return kinematics::ToEigen(kdl_->X);
}

Matrix6Xd FlexibleJointRobot::TipJacobian(const Eigen::VectorXd& q) const {
  kinematics::CheckJointVector(chain_, q);
  kdl_->q_kin.data = q;
  if (kdl_->jac.JntToJac(kdl_->q_kin, kdl_->J) < 0) throw std::runtime_error("TipJacobian: KDL error");
  return kdl_->J.data;
}

namespace {
void Resize(FlexibleJointState* s, int n) {
  s->q.resize(n);
  s->qd.resize(n);
  s->theta.resize(n);
  s->thetad.resize(n);
}
// out = x + a * k
void Axpy(const FlexibleJointState& x, double a, const FlexibleJointState& k, FlexibleJointState* out) {
  out->q = x.q + a * k.q;
  out->qd = x.qd + a * k.qd;
  out->theta = x.theta + a * k.theta;
  out->thetad = x.thetad + a * k.thetad;
}
}  // namespace

Rk4Integrator::Rk4Integrator(int n) {
  for (auto* s : {&k1_, &k2_, &k3_, &k4_, &tmp_}) Resize(s, n);
}

void Rk4Integrator::Step(FlexibleJointRobot& robot, const Eigen::VectorXd& tau_m,
                         const Eigen::VectorXd& tau_ext, double h, FlexibleJointState* x) {
  robot.Derivative(*x, tau_m, tau_ext, &k1_);
  Axpy(*x, 0.5 * h, k1_, &tmp_);
  robot.Derivative(tmp_, tau_m, tau_ext, &k2_);
  Axpy(*x, 0.5 * h, k2_, &tmp_);
  robot.Derivative(tmp_, tau_m, tau_ext, &k3_);
  Axpy(*x, h, k3_, &tmp_);
  robot.Derivative(tmp_, tau_m, tau_ext, &k4_);
  const double w = h / 6.0;
  x->q += w * (k1_.q + 2.0 * k2_.q + 2.0 * k3_.q + k4_.q);
  x->qd += w * (k1_.qd + 2.0 * k2_.qd + 2.0 * k3_.qd + k4_.qd);
  x->theta += w * (k1_.theta + 2.0 * k2_.theta + 2.0 * k3_.theta + k4_.theta);
  x->thetad += w * (k1_.thetad + 2.0 * k2_.thetad + 2.0 * k3_.thetad + k4_.thetad);
}

int SubstepsFor(double omega_max, double period, double max_omega_h) {
  return std::max(1, static_cast<int>(std::ceil(omega_max * period / max_omega_h)));
}

}  // namespace robomach::drilling
