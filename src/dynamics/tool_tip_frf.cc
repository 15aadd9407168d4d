#include "robomach/dynamics/tool_tip_frf.h"

#include <complex>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "dynamics/internal/modal_sum.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"

namespace robomach::dynamics {

using cd = std::complex<double>;

std::vector<Eigen::Matrix3cd> ReceptanceDirect(const AssembledSystem& sys,
                                               const Eigen::VectorXd& freq_hz) {
  const int N = static_cast<int>(sys.M.rows());
  std::vector<Eigen::Matrix3cd> H(freq_hz.size());
  Eigen::MatrixXcd D(N, N);
  const Eigen::MatrixXcd Bt = sys.B.transpose().cast<cd>();
  Eigen::PartialPivLU<Eigen::MatrixXcd> lu(N);
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    if (!std::isfinite(freq_hz(i))) throw std::invalid_argument("non-finite frequency line");
    const double w = HzToRadPerSec(freq_hz(i));
    D.real() = sys.K - w * w * sys.M;
    D.imag() = w * sys.C;
    lu.compute(D);
    H[i] = sys.B.cast<cd>() * lu.solve(Bt);
  }
  return H;
}

void ReceptanceModal(const PostureDynamics& d, const Eigen::VectorXd& freq_hz, std::vector<Eigen::Matrix3cd>* H) {
  if (d.modes.empty()) throw std::invalid_argument("ReceptanceModal: the posture has no modes");
  if (!d.proportional_damping) {
    throw std::invalid_argument(
        "ReceptanceModal: damping is not proportional; use ReceptanceComplexModal");
  }
  if (!d.options.damping_ratios) {
    throw std::invalid_argument(
        "ReceptanceModal: the posture was evaluated without damping ratios (PostureOptions::damping_ratios)");
  }
  const int nm = static_cast<int>(d.modes.size());
  // Per mode: ω_k², 2 ζ_k ω_k and the six distinct entries of p pᵀ. Fixed
  // buffers for up to 32 modes (no allocation), a vector beyond.
  constexpr int kFixed = 32;
  double w2_fixed[kFixed], c_fixed[kFixed], P_fixed[6 * kFixed];
  std::vector<double> heap;
  double *w2 = w2_fixed, *c = c_fixed, *P = P_fixed;
  if (nm > kFixed) {
    heap.resize(8 * static_cast<size_t>(nm));
    w2 = heap.data();
    c = w2 + nm;
    P = c + nm;
  }
  internal::PackModes(d.modes, w2, c, P);
  H->resize(freq_hz.size());
  static_assert(sizeof(Eigen::Matrix3cd) == 9 * sizeof(cd), "Matrix3cd is nine packed complex numbers");
  internal::RealModalSum(nm, w2, c, P, freq_hz.data(), freq_hz.size(), reinterpret_cast<cd*>(H->data()));
}

std::vector<Eigen::Matrix3cd> ReceptanceModal(const PostureDynamics& d, const Eigen::VectorXd& freq_hz) {
  std::vector<Eigen::Matrix3cd> H;
  ReceptanceModal(d, freq_hz, &H);
  return H;
}

namespace {

// Poles and residues from a state matrix A, input matrix Bin (2N×3) and
// output matrix Cout (3×2N): H(s) = Cout (sI − A)⁻¹ Bin = Σ R_k / (s − λ_k).
ComplexModalModel FromStateSpace(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Bin, const Eigen::MatrixXd& Cout) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(A);
  if (es.info() != Eigen::Success) throw NumericalError("complex modal analysis failed");
  const Eigen::MatrixXcd V = es.eigenvectors();
  const Eigen::MatrixXcd W = V.inverse();
  ComplexModalModel out;
  out.poles = es.eigenvalues();
  const Eigen::MatrixXcd left = Cout.cast<cd>() * V;   // 3 × 2N
  const Eigen::MatrixXcd right = W * Bin.cast<cd>();   // 2N × 3
  for (Eigen::Index k = 0; k < V.cols(); ++k) out.residues.push_back(left.col(k) * right.row(k));
  return out;
}

}  // namespace

ComplexModalModel ComputeComplexModes(const AssembledSystem& sys) {
  const int N = static_cast<int>(sys.M.rows());
  // Balanced first-order form. In mass-normalised undamped modal
  // coordinates η (Φᵀ M Φ = I, Φᵀ K Φ = Ω²) with u = Ω η the state
  // [u; η'] obeys
  //   u' = Ω η',   η'' = −Ω u − C̃ η' + B̃ᵀ F,   x_T = B̃ Ω⁻¹ u,
  // C̃ = Φᵀ C Φ, B̃ = B Φ. Its state matrix [0 Ω; −Ω −C̃] is skew plus a small
  // damping term, so nearly normal and its eigenvectors nearly orthogonal:
  // the residues keep full precision when the modes span decades, where the
  // plain form [0 I; −M⁻¹K −M⁻¹C] lost 1e-8 relative (flange on springs).
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(sys.K, sys.M,
                                                                Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (ges.info() == Eigen::Success && ges.eigenvalues().minCoeff() > 0.0) {
    const Eigen::MatrixXd& Phi = ges.eigenvectors();
    const Eigen::VectorXd omega = ges.eigenvalues().cwiseSqrt();
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * N, 2 * N);
    A.topRightCorner(N, N) = omega.asDiagonal();
    A.bottomLeftCorner(N, N) = -Eigen::MatrixXd(omega.asDiagonal());
    A.bottomRightCorner(N, N) = -Phi.transpose() * sys.C * Phi;
    const Eigen::MatrixXd Bt = sys.B * Phi;  // 3 × N
    Eigen::MatrixXd Bin = Eigen::MatrixXd::Zero(2 * N, 3);
    Bin.bottomRows(N) = Bt.transpose();
    Eigen::MatrixXd Cout = Eigen::MatrixXd::Zero(3, 2 * N);
    Cout.leftCols(N) = Bt * omega.cwiseInverse().asDiagonal();
    return FromStateSpace(A, Bin, Cout);
  }
  // A rigid-body mode (K singular) or an indefinite M: the plain form.
  const Eigen::PartialPivLU<Eigen::MatrixXd> Mlu(sys.M);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * N, 2 * N);
  A.topRightCorner(N, N).setIdentity();
  A.bottomLeftCorner(N, N) = -Mlu.solve(sys.K);
  A.bottomRightCorner(N, N) = -Mlu.solve(sys.C);
  Eigen::MatrixXd Bin = Eigen::MatrixXd::Zero(2 * N, 3);
  Bin.bottomRows(N) = Mlu.solve(Eigen::MatrixXd(sys.B.transpose()));
  Eigen::MatrixXd Cout = Eigen::MatrixXd::Zero(3, 2 * N);
  Cout.leftCols(N) = sys.B;
  return FromStateSpace(A, Bin, Cout);
}

std::vector<Eigen::Matrix3cd> ReceptanceComplexModal(const ComplexModalModel& m,
                                                     const Eigen::VectorXd& freq_hz) {
  // R / (iω − λ) = R conj(d) / |d|², d = −Re λ + i (ω − Im λ): one real
  // division per line and pole instead of nine complex ones.
  std::vector<Eigen::Matrix3cd> H(freq_hz.size());
  const Eigen::Index np = m.poles.size();
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    const double w = HzToRadPerSec(freq_hz(i));
    Eigen::Matrix3d re = Eigen::Matrix3d::Zero(), im = Eigen::Matrix3d::Zero();
    for (Eigen::Index k = 0; k < np; ++k) {
      const double dr = -m.poles(k).real(), di = w - m.poles(k).imag();
      const double inv = 1.0 / (dr * dr + di * di);
      const double gr = dr * inv, gi = -di * inv;  // 1/d
      const Eigen::Matrix3cd& R = m.residues[k];
      re.noalias() += gr * R.real() - gi * R.imag();
      im.noalias() += gr * R.imag() + gi * R.real();
    }
    H[i].real() = re;
    H[i].imag() = im;
  }
  return H;
}

std::vector<Eigen::Matrix3cd> Receptance(const PostureDynamics& d, const Eigen::VectorXd& freq_hz) {
  if (d.proportional_damping && !d.modes.empty()) return ReceptanceModal(d, freq_hz);
  if (d.complex_modes.poles.size() > 0) return ReceptanceComplexModal(d.complex_modes, freq_hz);
  return ReceptanceComplexModal(ComputeComplexModes(d.system), freq_hz);
}

ReceptanceEvaluator::ReceptanceEvaluator(const PostureDynamics& d) {
  real_modes_ = d.proportional_damping && !d.modes.empty();
  if (real_modes_) {
    const int nm = static_cast<int>(d.modes.size());
    w2_.resize(nm);
    c_.resize(nm);
    p_.resize(3, nm);
    for (int k = 0; k < nm; ++k) {
      const double w = HzToRadPerSec(d.modes[k].freq_hz);
      w2_(k) = w * w;
      c_(k) = 2.0 * d.modes[k].damping_ratio * w;
      p_.col(k) = d.modes[k].p_T;
    }
    return;
  }
  ComplexModalModel m = d.complex_modes.poles.size() > 0 ? d.complex_modes : ComputeComplexModes(d.system);
  poles_ = std::move(m.poles);
  residues_ = std::move(m.residues);
}

Eigen::VectorXcd ReceptanceEvaluator::Entry(const Eigen::VectorXd& freq_hz, int r, int e) const {
  if (r < 0 || r > 2 || e < 0 || e > 2) throw std::invalid_argument("ReceptanceEvaluator: direction index out of 0..2");
  Eigen::VectorXcd h(freq_hz.size());
  if (real_modes_) {
    const Eigen::VectorXd P = (p_.row(r).array() * p_.row(e).array()).transpose();
    for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
      const double w = HzToRadPerSec(freq_hz(i)), w_sq = w * w;
      double re = 0.0, im = 0.0;
      for (Eigen::Index k = 0; k < P.size(); ++k) {
        const double a = w2_(k) - w_sq, b = c_(k) * w;
        const double s = P(k) / (a * a + b * b);
        re += a * s;
        im -= b * s;
      }
      h(i) = cd(re, im);
    }
    return h;
  }
  Eigen::VectorXcd R(poles_.size());
  for (Eigen::Index k = 0; k < poles_.size(); ++k) R(k) = residues_[k](r, e);
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    const double w = HzToRadPerSec(freq_hz(i));
    cd s = 0.0;
    for (Eigen::Index k = 0; k < poles_.size(); ++k) {
      // R / (iω − λ) = R conj(d) / |d|², d = −Re λ + i (ω − Im λ).
      const double dr = -poles_(k).real(), di = w - poles_(k).imag();
      s += R(k) * cd(dr, -di) / (dr * dr + di * di);
    }
    h(i) = s;
  }
  return h;
}

std::complex<double> ReceptanceEvaluator::Entry(double freq_hz, int r, int e) const {
  Eigen::VectorXd f(1);
  f(0) = freq_hz;
  return Entry(f, r, e)(0);
}

}  // namespace robomach::dynamics
