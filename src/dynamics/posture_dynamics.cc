#include "robomach/dynamics/posture_dynamics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "kinematics/internal/kdl_status.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {

// KDL::Joint::pose() caches its last result in mutable members, so two
// threads must never evaluate the same KDL::Chain object. Each workspace owns
// a private copy of the chain (a few hundred bytes) and binds its solvers to
// it; that is what makes a shared RobotModel safe across threads.
struct PostureEvaluator::Workspace {
  explicit Workspace(const KDL::Chain& shared_chain)
      : chain(shared_chain),
        fk(chain),
        jac(chain),
        dyn(chain, KDL::Vector::Zero()),  // gravity does not enter M_q
        q(shared_chain.getNrOfJoints()),
        J(shared_chain.getNrOfJoints()),
        H(shared_chain.getNrOfJoints()) {}
  const KDL::Chain chain;  // declared first: the solvers below keep a reference to it
  KDL::ChainFkSolverPos_recursive fk;
  KDL::ChainJntToJacSolver jac;
  KDL::ChainDynParam dyn;
  KDL::JntArray q;
  KDL::Jacobian J;
  KDL::JntSpaceInertiaMatrix H;
};

PostureEvaluator::PostureEvaluator(std::shared_ptr<const RobotModel> model)
    : model_(std::move(model)), ws_(std::make_unique<Workspace>(model_->chain().kdl())) {}

PostureEvaluator::~PostureEvaluator() = default;

namespace {

// Orders a mode's sign so that its largest tool-tip component is positive
// (a reproducible sign for tables and tests).
void NormaliseSign(Mode* m) {
  Eigen::Index i = 0;
  m->p_T.cwiseAbs().maxCoeff(&i);
  if (m->p_T(i) < 0.0) {
    m->p_T = -m->p_T;
    m->phi = -m->phi;
  }
}

// K φ = λ M φ with M-normalised eigenvectors, ascending λ. A fixed-size
// solver for the common 6-DOF case: about twice as fast as the dynamic one
// (bench/bench_posture.cc), which matters in workspace maps.
template <int Size>
bool SolveGeneralizedFixed(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M,
                           Eigen::VectorXd* values, Eigen::MatrixXd* vectors) {
  using Mat = Eigen::Matrix<double, Size, Size>;
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat> ges(Mat(K), Mat(M),
                                                    Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (ges.info() != Eigen::Success) return false;
  *values = ges.eigenvalues();
  *vectors = ges.eigenvectors();
  return true;
}

bool SolveGeneralized(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M, Eigen::VectorXd* values,
                      Eigen::MatrixXd* vectors) {
  if (K.rows() == 6) return SolveGeneralizedFixed<6>(K, M, values, vectors);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(K, M,
                                                                Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (ges.info() != Eigen::Success) return false;
  *values = ges.eigenvalues();
  *vectors = ges.eigenvectors();
  return true;
}

// Eigenvalues of JᵀJ (ascending), fixed-size for six joints.
Eigen::VectorXd GramEigenvalues(const Matrix6Xd& J) {
  if (J.cols() == 6) {
    const Matrix6d JtJ = J.transpose() * J;
    return Eigen::SelfAdjointEigenSolver<Matrix6d>(JtJ, Eigen::EigenvaluesOnly).eigenvalues();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(J.transpose() * J, Eigen::EigenvaluesOnly)
      .eigenvalues();
}

}  // namespace

PostureDynamics PostureEvaluator::Evaluate(const Eigen::VectorXd& q, const PostureOptions& options) {
  const RobotModel& model = *model_;
  const kinematics::SerialChain& chain = model.chain();
  kinematics::CheckJointVector(chain, q);
  const int n = model.num_joints();
  const int N = model.num_dofs();
  Workspace& w = *ws_;
  w.q.data = q;

  PostureDynamics out;
  out.q = q;
  KDL::Frame f;
  kinematics::internal::ThrowIfKdlFailed(w.fk.JntToCart(w.q, f), w.fk, "forward kinematics");
  out.X_BT = kinematics::ToEigen(f);
  kinematics::internal::ThrowIfKdlFailed(w.jac.JntToJac(w.q, w.J), w.jac, "Jacobian");
  out.J_BT = w.J.data;
  kinematics::internal::ThrowIfKdlFailed(w.dyn.JntToMass(w.q, w.H), w.dyn, "joint-space inertia");

  AssembledSystem& sys = out.system;
  sys.num_joints = n;
  sys.M.setZero(N, N);
  sys.K.setZero(N, N);
  sys.C_extra.setZero(N, N);
  sys.B.setZero(3, N);
  sys.V_T.setZero(6, N);
  sys.M.topLeftCorner(n, n) = w.H.data;
  sys.K.topLeftCorner(n, n).diagonal() = model.joint_stiffness();
  sys.B.leftCols(n) = out.J_BT.topRows<3>();
  sys.V_T.leftCols(n) = out.J_BT;
  const EffectContext ctx{model, q, out.X_BT, out.J_BT};
  for (const BoundEffect& be : model.effects()) {
    be.effect->Contribute(ctx, be.values, be.first_extra_dof, &sys);
  }
  sys.C = model.alpha() * sys.K + model.beta() * sys.M + sys.C_extra;
  out.proportional_damping = sys.C_extra.isZero(0.0);

  // cond(J) = sqrt(λmax/λmin) of JᵀJ (n × n). Squaring loses the digits
  // below eps·λmax, so condition numbers up to ≈ 1e7 are resolved, which is
  // all the 1e5 threshold needs; beyond, the value is only "very large".
  // (Three times cheaper than a Jacobi SVD of a 6×6 matrix.)
  const Eigen::VectorXd gram = GramEigenvalues(out.J_BT);
  const double lmin = gram(0), lmax = gram(n - 1);
  out.jacobian_condition = lmin > 0.0 ? std::sqrt(lmax / lmin) : INFINITY;
  if (!std::isfinite(out.jacobian_condition)) out.jacobian_condition = INFINITY;
  out.near_singular = !(out.jacobian_condition <= kNearSingularCondition);

  out.M_X.setConstant(NAN);
  out.K_X.setConstant(NAN);
  out.C_X.setConstant(NAN);
  if (options.cartesian && n == 6 && !out.near_singular) {
    // Congruence with J⁻¹: M_X = J⁻ᵀ M_q J⁻¹ [Khatib 1987], K_X = J⁻ᵀ K_q J⁻¹.
    const Matrix6d J = out.J_BT;
    const Matrix6d Jinv = J.partialPivLu().inverse();
    out.M_X = Jinv.transpose() * sys.M.topLeftCorner(6, 6) * Jinv;
    out.K_X = Jinv.transpose() * sys.K.topLeftCorner(6, 6) * Jinv;
    out.C_X = Jinv.transpose() * sys.C.topLeftCorner(6, 6) * Jinv;
  }

  // Static compliance H(0) = B K⁻¹ Bᵀ. K is SPD for positive joint stiffness.
  Eigen::LDLT<Eigen::MatrixXd> ldlt(sys.K);
  out.static_compliance = sys.B * ldlt.solve(sys.B.transpose());

  if (options.modes) {
    Eigen::VectorXd eigenvalues;
    Eigen::MatrixXd eigenvectors;
    if (!SolveGeneralized(sys.K, sys.M, &eigenvalues, &eigenvectors)) {
      throw NumericalError("modal analysis failed: the assembled mass matrix is not positive "
                               "definite (check link and effect inertias)");
    }
    out.modes.resize(N);
    for (int k = 0; k < N; ++k) {
      Mode& m = out.modes[k];
      const double lambda = std::max(eigenvalues(k), 0.0);
      const double omega = std::sqrt(lambda);
      m.freq_hz = RadPerSecToHz(omega);
      m.phi = eigenvectors.col(k);  // φᵀ M φ = 1 (Eigen's Ax_lBx normalisation)
      m.p_T = sys.B * m.phi;
      NormaliseSign(&m);
      const double p2 = m.p_T.squaredNorm();
      m.modal_mass_kg = p2 > 0.0 ? 1.0 / p2 : INFINITY;
      m.shape_T = p2 > 0.0 ? Eigen::Vector3d(m.p_T / std::sqrt(p2)) : Eigen::Vector3d::Zero();
      // Proportional damping: φᵀ C φ = alpha ω² + beta = 2 ζ ω exactly.
      m.damping_ratio = omega > 0.0 ? m.phi.dot(sys.C * m.phi) / (2.0 * omega) : 0.0;
    }
    if (!out.proportional_damping) {
      // Non-proportional damping: the damping ratio of each mode is that of
      // the complex pole nearest to its undamped frequency.
      out.complex_modes = ComputeComplexModes(sys);
      const ComplexModalModel& cm = out.complex_modes;
      for (Mode& m : out.modes) {
        double best = INFINITY;
        for (int k = 0; k < cm.poles.size(); ++k) {
          const std::complex<double> lam = cm.poles(k);
          if (lam.imag() <= 0.0) continue;
          const double d = std::abs(std::abs(lam) - HzToRadPerSec(m.freq_hz));
          if (d < best) {
            best = d;
            m.damping_ratio = -lam.real() / std::abs(lam);
          }
        }
      }
    }
  }
  return out;
}

PostureDynamics EvaluatePosture(std::shared_ptr<const RobotModel> model, const Eigen::VectorXd& q,
                                const PostureOptions& options) {
  PostureEvaluator e(std::move(model));
  return e.Evaluate(q, options);
}

}  // namespace robomach::dynamics
