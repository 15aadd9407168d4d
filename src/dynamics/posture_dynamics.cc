#include "robomach/dynamics/posture_dynamics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "dynamics/internal/rigid_chain.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {

// One evaluator's reusable state. RigidChain reads the segments of a private
// copy of the chain: KDL::Joint::pose() caches its last result in mutable
// members, so two threads must never touch the same KDL::Chain object, and
// a RobotModel is shared across threads.
struct PostureEvaluator::Workspace {
  explicit Workspace(const KDL::Chain& shared_chain) : rigid(KDL::Chain(shared_chain)) {}
  internal::RigidChain rigid;
  Eigen::SelfAdjointEigenSolver<Matrix6d> reduced6;  // A = K^{-1/2} M K^{-1/2}
  Eigen::GeneralizedSelfAdjointEigenSolver<Matrix6d> general6;
  Eigen::SelfAdjointEigenSolver<Matrix6d> gram6;     // JᵀJ, eigenvalues only
  Eigen::LDLT<Eigen::MatrixXd> ldlt;                 // K, general path of H(0)
  Eigen::MatrixXd k_inv_bt;                          // K⁻¹ Bᵀ (N × 3)
  Eigen::VectorXd eigenvalues;                       // λ ascending
  Eigen::MatrixXd eigenvectors;                      // M-normalised φ
  Eigen::VectorXd c_phi;                             // C φ

  // The stages of Evaluate that use this state (members, not free helpers:
  // Workspace is private to PostureEvaluator).
  void Assemble(const RobotModel& model, const Eigen::VectorXd& q, int n, int N, PostureDynamics* out);
  void JacobianCondition(int n, PostureDynamics* out);
  void StaticCompliance(const PostureOptions& options, int N, bool k_diagonal, PostureDynamics* out);
  void SolveEigenproblem(const AssembledSystem& sys, int N, bool k_diagonal);
  void UndampedModes(const PostureOptions& options, int N, PostureDynamics* out);
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

// True if K is diagonal with finite positive entries (joint stiffness only,
// or effects whose springs act on single coordinates).
bool IsPositiveDiagonal(const Eigen::MatrixXd& K) {
  const Eigen::Index N = K.rows();
  for (Eigen::Index c = 0; c < N; ++c) {
    for (Eigen::Index r = 0; r < N; ++r) {
      const double v = K(r, c);
      if (r == c ? !(v > 0.0 && v < INFINITY) : v != 0.0) return false;
    }
  }
  return true;
}

[[noreturn]] void ThrowNotPositiveDefinite() {
  throw NumericalError("modal analysis failed: the assembled mass matrix is not positive "
                           "definite (check link and effect inertias)");
}

}  // namespace

PostureDynamics PostureEvaluator::Evaluate(const Eigen::VectorXd& q, const PostureOptions& options) {
  PostureDynamics out;
  Evaluate(q, options, &out);
  return out;
}

// The assembled system of posture q into out->system, with X_BT and J_BT:
// the rigid chain's M_q, the joint stiffness, the effects' contributions and
// the damping matrix (n joints, N DOFs).
void PostureEvaluator::Workspace::Assemble(const RobotModel& model, const Eigen::VectorXd& q, int n, int N,
                                           PostureDynamics* out_ptr) {
  PostureDynamics& out = *out_ptr;
  AssembledSystem& sys = out.system;
  sys.num_joints = n;
  sys.M.setZero(N, N);
  sys.K.setZero(N, N);
  sys.C_extra.setZero(N, N);
  sys.B.setZero(3, N);
  sys.V_T.setZero(6, N);
  out.J_BT.resize(6, n);
  // Pose, J_BT and M_q in one pass (dynamics/internal/rigid_chain.h).
  rigid.Compute(q.data(), &out.X_BT, out.J_BT, sys.M.topLeftCorner(n, n));
  sys.K.topLeftCorner(n, n).diagonal() = model.joint_stiffness();
  sys.B.leftCols(n) = out.J_BT.topRows<3>();
  sys.V_T.leftCols(n) = out.J_BT;
  const EffectContext ctx{model, q, out.X_BT, out.J_BT};
  for (const BoundEffect& be : model.effects()) {
    be.effect->Contribute(ctx, be.values, be.first_extra_dof, &sys);
  }
  sys.C.resize(N, N);
  sys.C.noalias() = model.alpha() * sys.K + model.beta() * sys.M + sys.C_extra;
  out.proportional_damping = sys.C_extra.isZero(0.0);
}

// out->jacobian_condition and near_singular from the n joints' J_BT.
void PostureEvaluator::Workspace::JacobianCondition(int n, PostureDynamics* out_ptr) {
  PostureDynamics& out = *out_ptr;
  // cond(J) = sqrt(λmax/λmin) of JᵀJ (n × n). Squaring loses the digits
  // below eps·λmax, so condition numbers up to ≈ 1e7 are resolved, which is
  // all the 1e5 threshold needs; beyond, the value is only "very large".
  // (Three times cheaper than a Jacobi SVD of a 6×6 matrix.)
  double lmin = 0.0, lmax = 0.0;
  if (n == 6) {
    const Matrix6d JtJ = out.J_BT.transpose() * out.J_BT;
    gram6.compute(JtJ, Eigen::EigenvaluesOnly);
    lmin = gram6.eigenvalues()(0);
    lmax = gram6.eigenvalues()(5);
  } else {
    const Eigen::VectorXd gram =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(out.J_BT.transpose() * out.J_BT, Eigen::EigenvaluesOnly)
            .eigenvalues();
    lmin = gram(0);
    lmax = gram(n - 1);
  }
  out.jacobian_condition = lmin > 0.0 ? std::sqrt(lmax / lmin) : INFINITY;
  if (!std::isfinite(out.jacobian_condition)) out.jacobian_condition = INFINITY;
  out.near_singular = !(out.jacobian_condition <= kNearSingularCondition);
}

// Static compliance H(0) = B K⁻¹ Bᵀ into out->static_compliance (NaN when
// not asked for). K is SPD for positive joint stiffness.
void PostureEvaluator::Workspace::StaticCompliance(const PostureOptions& options, int N, bool k_diagonal,
                                                   PostureDynamics* out_ptr) {
  PostureDynamics& out = *out_ptr;
  const AssembledSystem& sys = out.system;
  if (!options.static_compliance) {
    out.static_compliance.setConstant(NAN);
  } else if (k_diagonal) {
    Eigen::Matrix3d H0 = Eigen::Matrix3d::Zero();
    for (int j = 0; j < N; ++j) H0.noalias() += sys.B.col(j) * (sys.B.col(j).transpose() / sys.K(j, j));
    out.static_compliance = H0;
  } else {
    ldlt.compute(sys.K);
    k_inv_bt = sys.B.transpose();
    ldlt.solveInPlace(k_inv_bt);
    out.static_compliance.noalias() = sys.B * k_inv_bt;
  }
}

// K φ = λ M φ with M-normalised eigenvectors, ascending λ, into eigenvalues
// and eigenvectors. @throws NumericalError if M is not positive definite.
void PostureEvaluator::Workspace::SolveEigenproblem(const AssembledSystem& sys, int N, bool k_diagonal) {
  eigenvalues.resize(N);
  eigenvectors.resize(N, N);
  if (N == 6 && k_diagonal) {
    // Reduced through diag K to one standard symmetric problem (header).
    // Eigen's iterative solver, not computeDirect (closed-form 3×3 only and
    // inaccurate beyond). μ ascending, so λ = 1/μ descending: mode k is μ's 5 − k.
    const Vector6d k_diag = sys.K.diagonal();
    const Vector6d d = k_diag.cwiseSqrt().cwiseInverse();
    const Matrix6d M6 = sys.M;
    reduced6.compute(d.asDiagonal() * M6 * d.asDiagonal(), Eigen::ComputeEigenvectors);
    if (reduced6.info() != Eigen::Success || !(reduced6.eigenvalues()(0) > 0.0)) {
      ThrowNotPositiveDefinite();
    }
    for (int k = 0; k < 6; ++k) {
      // 1/μ and K^{-1/2}u/√μ carry the absolute error eps·μ_max of the
      // smallest μ, i.e. eps·(ω_max/ω_min)² relative for the highest mode
      // (≈ 1e-13 on the KR210). The Rayleigh quotient λ = vᵀKv / vᵀMv and the
      // M-normalisation of v = K^{-1/2}u restore full precision: λ's error is
      // quadratic in u's, which is ≈ eps·μ_max/gap.
      const Vector6d v = d.cwiseProduct(reduced6.eigenvectors().col(5 - k));
      const double vMv = v.dot(M6 * v);
      eigenvalues(k) = v.cwiseAbs2().dot(k_diag) / vMv;
      eigenvectors.col(k) = v / std::sqrt(vMv);
    }
  } else if (N == 6) {
    general6.compute(Matrix6d(sys.K), Matrix6d(sys.M), Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
    if (general6.info() != Eigen::Success) ThrowNotPositiveDefinite();
    eigenvalues = general6.eigenvalues();
    eigenvectors = general6.eigenvectors();
  } else {
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(sys.K, sys.M,
                                                                  Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
    if (ges.info() != Eigen::Success) ThrowNotPositiveDefinite();
    eigenvalues = ges.eigenvalues();
    eigenvectors = ges.eigenvectors();
  }
}

// out->modes from the solved eigenproblem: frequency, φ, p_T with its sign
// normalised, and (as asked) modal mass, shape and the proportional
// damping ratio.
void PostureEvaluator::Workspace::UndampedModes(const PostureOptions& options, int N, PostureDynamics* out_ptr) {
  PostureDynamics& out = *out_ptr;
  const AssembledSystem& sys = out.system;
  out.modes.resize(N);
  c_phi.resize(N);
  for (int k = 0; k < N; ++k) {
    Mode& m = out.modes[k];
    const double lambda = std::max(eigenvalues(k), 0.0);
    const double omega = std::sqrt(lambda);
    m.freq_hz = RadPerSecToHz(omega);
    m.phi = eigenvectors.col(k);  // φᵀ M φ = 1
    m.p_T.noalias() = sys.B * m.phi;
    NormaliseSign(&m);
    if (options.modal_masses) {
      const double p2 = m.p_T.squaredNorm();
      m.modal_mass_kg = p2 > 0.0 ? 1.0 / p2 : INFINITY;
      m.shape_T = p2 > 0.0 ? Eigen::Vector3d(m.p_T / std::sqrt(p2)) : Eigen::Vector3d::Zero();
    } else {
      m.modal_mass_kg = NAN;
      m.shape_T.setConstant(NAN);
    }
    if (options.damping_ratios) {
      // Proportional damping: φᵀ C φ = alpha ω² + beta = 2 ζ ω exactly.
      c_phi.noalias() = sys.C * m.phi;
      m.damping_ratio = omega > 0.0 ? m.phi.dot(c_phi) / (2.0 * omega) : 0.0;
    } else {
      m.damping_ratio = NAN;
    }
  }
}

namespace {

// M_X, K_X, C_X into out (NaN unless asked for, six joints and not near
// singular).
void CartesianMatrices(const PostureOptions& options, int n, PostureDynamics* out_ptr) {
  PostureDynamics& out = *out_ptr;
  const AssembledSystem& sys = out.system;
  out.M_X.setConstant(NAN);
  out.K_X.setConstant(NAN);
  out.C_X.setConstant(NAN);
  if (options.cartesian && n == 6 && !out.near_singular) {
    // Congruence with J⁻¹: M_X = J⁻ᵀ M_q J⁻¹ [Khatib 1987], K_X = J⁻ᵀ K_q J⁻¹.
    const Matrix6d J = out.J_BT;
    const Matrix6d Jinv = J.partialPivLu().inverse();
    // Fixed-size blocks: no heap temporaries in the products.
    out.M_X = Jinv.transpose() * sys.M.topLeftCorner<6, 6>() * Jinv;
    out.K_X = Jinv.transpose() * sys.K.topLeftCorner<6, 6>() * Jinv;
    out.C_X = Jinv.transpose() * sys.C.topLeftCorner<6, 6>() * Jinv;
  }
}

// The damping ratios of out->modes from the complex poles, which it
// computes into out->complex_modes.
void DampingFromComplexPoles(PostureDynamics* out_ptr) {
  PostureDynamics& out = *out_ptr;
  out.complex_modes = ComputeComplexModes(out.system);
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

}  // namespace

void PostureEvaluator::Evaluate(const Eigen::VectorXd& q, const PostureOptions& options,
                                PostureDynamics* out_ptr) {
  PostureDynamics& out = *out_ptr;
  const RobotModel& model = *model_;
  kinematics::CheckJointVector(model.chain(), q);
  const int n = model.num_joints();
  const int N = model.num_dofs();
  Workspace& w = *ws_;

  out.options = options;
  out.q = q;
  w.Assemble(model, q, n, N, &out);
  const bool k_diagonal = IsPositiveDiagonal(out.system.K);

  out.jacobian_condition = NAN;
  out.near_singular = false;
  if (options.jacobian_condition || options.cartesian) w.JacobianCondition(n, &out);
  CartesianMatrices(options, n, &out);
  w.StaticCompliance(options, N, k_diagonal, &out);

  out.complex_modes.poles.resize(0);
  out.complex_modes.residues.clear();
  if (!options.modes) {
    out.modes.clear();
    return;
  }
  w.SolveEigenproblem(out.system, N, k_diagonal);
  w.UndampedModes(options, N, &out);
  if (options.damping_ratios && !out.proportional_damping) {
    // Non-proportional damping: the damping ratio of each mode is that of
    // the complex pole nearest to its undamped frequency.
    DampingFromComplexPoles(&out);
  }
}

// Nothing to check (see the header); not called by Evaluate, the maps'
// per-posture inner loop.
void PostureOptions::Validate() const {}

PostureDynamics EvaluatePosture(std::shared_ptr<const RobotModel> model, const Eigen::VectorXd& q,
                                const PostureOptions& options) {
  PostureEvaluator e(std::move(model));
  return e.Evaluate(q, options);
}

}  // namespace robomach::dynamics
