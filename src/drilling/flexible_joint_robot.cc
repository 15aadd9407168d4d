// Spong's reduced elastic-joint model (seed 003 eq. 1) on a KDL chain.
//
// - [Spong 1987] M. W. Spong, Modeling and control of elastic joint robots,
//   ASME J. Dyn. Syst. Meas. Control 109(4), 310-319.
// - [Featherstone 2008] R. Featherstone, Rigid Body Dynamics Algorithms,
//   Springer: spatial vectors (ch. 2), recursive Newton-Euler (ch. 5.3),
//   composite-rigid-body algorithm (ch. 6.2).
#include "robomach/drilling/flexible_joint_robot.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "robomach/common/units.h"

namespace robomach::drilling {

struct FlexibleJointRobot::Kdl {
  KDL::Chain chain;
  KDL::ChainDynParam dyn;
  KDL::ChainFkSolverPos_recursive fk;
  KDL::ChainJntToJacSolver jac;
  KDL::JntArray q_kin;          // for TipPose / TipJacobian
  KDL::Frame X;
  KDL::Jacobian J;
  KDL::JntArray q, qd, c, g;
  KDL::JntSpaceInertiaMatrix M;
  Kdl(const KDL::Chain& ch, int n)
      : chain(ch),
        dyn(chain, KDL::Vector(0.0, 0.0, -kStandardGravity)),
        fk(chain),
        jac(chain),
        q_kin(n),
        J(n),
        q(n), qd(n), c(n), g(n), M(n) {}
};

// The chain's rigid-body dynamics for Derivative(), which the integrator calls
// four times per RK4 step (~10^5 times per simulated second): M(q) by the
// composite-rigid-body algorithm and C(q, q') q' + G(q) by recursive
// Newton-Euler [Featherstone 2008], both from ONE pass over the segment poses
// (KDL's ChainDynParam and ChainIdSolver_RNE each redo it) and with every
// spatial quantity in the base frame, so the composite inertias are plain
// sums and no spatial transform is needed in the O(n²) part. Spatial motion
// vectors are (w, v_O), force vectors (n_O, f), both about the base origin
// O. Per segment the KDL data are used as they are: the segment's pose from
// Segment::pose(q) (KDL's own joint conventions) and its joint's unit twist,
// which is constant in the segment's tip frame.
struct FlexibleJointRobot::Bodies {
  struct Body {
    bool moves{false};          // a non-fixed joint
    int joint{-1};              // its index in q
    Eigen::Vector3d s_w, s_v;   // unit joint twist in the tip frame, about the tip origin
    double m{0.0};
    Eigen::Vector3d c;          // centre of mass, tip frame
    Eigen::Matrix3d I_com;      // inertia about the centre of mass, tip frame
    double joint_inertia{0.0};  // KDL Joint::getInertia() (added to M's diagonal, as KDL does)
    // Per evaluation, base frame:
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    Eigen::Vector3d S_w, S_v;   // joint twist about O
    double Ic_m{0.0};           // composite inertia of this body and all after it
    Eigen::Vector3d Ic_h;       // ... first moment m c about O
    Eigen::Matrix3d Ic_I;       // ... rotational inertia about O
    Eigen::Vector3d v_w, v_v, a_w, a_v, f_n, f_f;
  };
  std::vector<Body> b;
  const KDL::Chain* chain;
  Eigen::Vector3d a_base_v;     // -g: gravity as an upward base acceleration

  explicit Bodies(const KDL::Chain& ch) : chain(&ch), a_base_v(0.0, 0.0, kStandardGravity) {
    b.resize(ch.getNrOfSegments());
    int j = 0;
    for (size_t i = 0; i < b.size(); ++i) {
      const KDL::Segment& seg = ch.getSegment(i);
      Body& B = b[i];
      B.moves = seg.getJoint().getType() != KDL::Joint::Fixed;
      if (B.moves) {
        B.joint = j++;
        B.joint_inertia = seg.getJoint().getInertia();
        const KDL::Frame X0 = seg.pose(0.0);
        const KDL::Twist S = X0.M.Inverse(seg.twist(0.0, 1.0));
        B.s_w = Eigen::Vector3d(S.rot.x(), S.rot.y(), S.rot.z());
        B.s_v = Eigen::Vector3d(S.vel.x(), S.vel.y(), S.vel.z());
      }
      const KDL::RigidBodyInertia& in = seg.getInertia();
      B.m = in.getMass();
      const KDL::Vector c = in.getCOG();
      B.c = Eigen::Vector3d(c.x(), c.y(), c.z());
      const KDL::RotationalInertia I = in.getRotationalInertia();  // about the tip origin
      Eigen::Matrix3d Io;
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) Io(r, k) = I.data[3 * r + k];
      // Parallel axis: I_o = I_com + m (|c|² 1 - c c^T).
      B.I_com = Io - B.m * (B.c.squaredNorm() * Eigen::Matrix3d::Identity() - B.c * B.c.transpose());
    }
  }

  // M(q) and C(q, q') q' + G(q) into M and h (sizes n x n and n, allocated).
  void Compute(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, Eigen::MatrixXd* M,
               Eigen::VectorXd* h) {
    // Forward pass: poses, joint twists, inertias about O, velocities and
    // velocity-product accelerations (q'' = 0).
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    Eigen::Vector3d v_w = Eigen::Vector3d::Zero(), v_v = Eigen::Vector3d::Zero();
    Eigen::Vector3d a_w = Eigen::Vector3d::Zero(), a_v = a_base_v;
    const int nb = static_cast<int>(b.size());
    for (int i = 0; i < nb; ++i) {
      Body& B = b[i];
      const KDL::Frame X = chain->getSegment(i).pose(B.moves ? q(B.joint) : 0.0);
      Eigen::Matrix3d Rx;
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) Rx(r, k) = X.M(r, k);
      p += R * Eigen::Vector3d(X.p.x(), X.p.y(), X.p.z());
      R = R * Rx;
      B.R = R;
      B.p = p;
      if (B.moves) {
        // Twist about the tip origin p, in the base frame; then about O:
        // v_O = v_p + w x (O - p) = v_p + p x w.
        B.S_w = R * B.s_w;
        B.S_v = R * B.s_v + p.cross(B.S_w);
        const double qdj = qd(B.joint);
        const Eigen::Vector3d vj_w = B.S_w * qdj, vj_v = B.S_v * qdj;
        v_w += vj_w;
        v_v += vj_v;
        // a += v x vj (spatial motion cross product).
        a_v += v_w.cross(vj_v) + v_v.cross(vj_w);
        a_w += v_w.cross(vj_w);
      }
      B.v_w = v_w;
      B.v_v = v_v;
      B.a_w = a_w;
      B.a_v = a_v;
      // Spatial inertia about O: m, h = m c_O, I_O = I_com,B + m (|c_O|² 1 - c_O c_O^T).
      const Eigen::Vector3d cO = p + R * B.c;
      B.Ic_m = B.m;
      B.Ic_h = B.m * cO;
      B.Ic_I = R * B.I_com * R.transpose() +
               B.m * (cO.squaredNorm() * Eigen::Matrix3d::Identity() - cO * cO.transpose());
      // f = I a + v x* (I v); I (w, v) = (I_O w + h x v, m v + w x h).
      const Eigen::Vector3d ia_n = B.Ic_I * a_w + B.Ic_h.cross(a_v);
      const Eigen::Vector3d ia_f = B.m * a_v + a_w.cross(B.Ic_h);
      const Eigen::Vector3d iv_n = B.Ic_I * v_w + B.Ic_h.cross(v_v);
      const Eigen::Vector3d iv_f = B.m * v_v + v_w.cross(B.Ic_h);
      // (w, v) x* (n, f) = (w x n + v x f, w x f).
      B.f_n = ia_n + v_w.cross(iv_n) + v_v.cross(iv_f);
      B.f_f = ia_f + v_w.cross(iv_f);
    }
    // Backward pass: composite inertias and forces are sums (all about O);
    // torque of joint i is S_i . f_c; M(j, i) = S_j . (Ic_i S_i), j <= i.
    for (int i = nb - 1; i >= 0; --i) {
      Body& B = b[i];
      if (i + 1 < nb) {
        const Body& C = b[i + 1];
        B.Ic_m += C.Ic_m;
        B.Ic_h += C.Ic_h;
        B.Ic_I += C.Ic_I;
        B.f_n += C.f_n;
        B.f_f += C.f_f;
      }
      if (!B.moves) continue;
      (*h)(B.joint) = B.S_w.dot(B.f_n) + B.S_v.dot(B.f_f);
      const Eigen::Vector3d F_n = B.Ic_I * B.S_w + B.Ic_h.cross(B.S_v);
      const Eigen::Vector3d F_f = B.Ic_m * B.S_v + B.S_w.cross(B.Ic_h);
      for (int k = 0; k <= i; ++k) {
        const Body& A = b[k];
        if (!A.moves) continue;
        const double Mji = A.S_w.dot(F_n) + A.S_v.dot(F_f);
        (*M)(A.joint, B.joint) = Mji;
        (*M)(B.joint, A.joint) = Mji;
      }
      (*M)(B.joint, B.joint) += B.joint_inertia;
    }
  }
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
  bodies_ = std::make_unique<Bodies>(kdl_->chain);
  M_.resize(n_, n_);
  h_.resize(n_);
  tau_.resize(n_);
  rhs_.resize(n_);
  // Storage for the n×n factor, so that the first step does not allocate.
  // Not `llt_ = Eigen::LLT<Eigen::MatrixXd>(n_)`: Eigen's size constructor
  // leaves m_info uninitialised, and the assignment then reads it (UBSan:
  // "not a valid value for type 'ComputationInfo'"). Factorising the identity
  // sizes the storage and leaves a valid state.
  llt_.compute(Eigen::MatrixXd::Identity(n_, n_));
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
  // M(q) and C(q, q') q' + G(q) (recursive Newton-Euler with q'' = 0).
  bodies_->Compute(x.q, x.qd, &M_, &h_);
  // (3): tau = K (theta/n - q) + D (theta'/n - q')
  tau_.array() = K_.array() * (x.theta.array() / gear_.array() - x.q.array()) +
                 D_.array() * (x.thetad.array() / gear_.array() - x.qd.array());
  rhs_ = tau_ + tau_ext - h_;
  llt_.compute(M_);
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
