#include "robomach/dynamics/tool_tip_frf.h"

#include <complex>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

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

std::vector<Eigen::Matrix3cd> ReceptanceModal(const PostureDynamics& d,
                                              const Eigen::VectorXd& freq_hz) {
  if (d.modes.empty()) throw std::invalid_argument("ReceptanceModal: the posture has no modes");
  if (!d.proportional_damping) {
    throw std::invalid_argument(
        "ReceptanceModal: damping is not proportional; use ReceptanceComplexModal");
  }
  const int nm = static_cast<int>(d.modes.size());
  // Per mode: ω_k², 2 ζ_k ω_k and the six distinct entries of p pᵀ.
  Eigen::VectorXd w2(nm), c(nm);
  Eigen::Matrix<double, 6, Eigen::Dynamic> P(6, nm);
  for (int k = 0; k < nm; ++k) {
    const Mode& m = d.modes[k];
    const double w = HzToRadPerSec(m.freq_hz);
    w2(k) = w * w;
    c(k) = 2.0 * m.damping_ratio * w;
    const Eigen::Vector3d& p = m.p_T;
    P.col(k) << p(0) * p(0), p(1) * p(1), p(2) * p(2), p(0) * p(1), p(0) * p(2), p(1) * p(2);
  }
  std::vector<Eigen::Matrix3cd> H(freq_hz.size());
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    const double w = HzToRadPerSec(freq_hz(i));
    const double w_sq = w * w;
    // 1/(a + ib) = (a − ib)/(a² + b²), accumulated in real arithmetic.
    Eigen::Matrix<double, 6, 1> re = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Matrix<double, 6, 1> im = Eigen::Matrix<double, 6, 1>::Zero();
    for (int k = 0; k < nm; ++k) {
      const double a = w2(k) - w_sq, b = c(k) * w;
      const double inv = 1.0 / (a * a + b * b);
      re.noalias() += (a * inv) * P.col(k);
      im.noalias() -= (b * inv) * P.col(k);
    }
    Eigen::Matrix3cd& h = H[i];
    const int idx[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col) h(r, col) = cd(re(idx[r][col]), im(idx[r][col]));
    }
  }
  return H;
}

ComplexModalModel ComputeComplexModes(const AssembledSystem& sys) {
  const int N = static_cast<int>(sys.M.rows());
  const Eigen::PartialPivLU<Eigen::MatrixXd> Mlu(sys.M);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * N, 2 * N);
  A.topRightCorner(N, N).setIdentity();
  A.bottomLeftCorner(N, N) = -Mlu.solve(sys.K);
  A.bottomRightCorner(N, N) = -Mlu.solve(sys.C);
  Eigen::MatrixXd Bin = Eigen::MatrixXd::Zero(2 * N, 3);
  Bin.bottomRows(N) = Mlu.solve(Eigen::MatrixXd(sys.B.transpose()));
  Eigen::EigenSolver<Eigen::MatrixXd> es(A);
  if (es.info() != Eigen::Success) throw std::runtime_error("complex modal analysis failed");
  const Eigen::MatrixXcd V = es.eigenvectors();
  const Eigen::MatrixXcd W = V.inverse();
  ComplexModalModel out;
  out.poles = es.eigenvalues();
  const Eigen::MatrixXcd left = sys.B.cast<cd>() * V.topRows(N);  // 3 × 2N
  const Eigen::MatrixXcd right = W * Bin.cast<cd>();              // 2N × 3
  for (int k = 0; k < 2 * N; ++k) out.residues.push_back(left.col(k) * right.row(k));
  return out;
}

std::vector<Eigen::Matrix3cd> ReceptanceComplexModal(const ComplexModalModel& m,
                                                     const Eigen::VectorXd& freq_hz) {
  std::vector<Eigen::Matrix3cd> H(freq_hz.size());
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    const cd iw(0.0, HzToRadPerSec(freq_hz(i)));
    Eigen::Matrix3cd h = Eigen::Matrix3cd::Zero();
    for (int k = 0; k < m.poles.size(); ++k) h += m.residues[k] / (iw - m.poles(k));
    H[i] = h;
  }
  return H;
}

std::vector<Eigen::Matrix3cd> Receptance(const PostureDynamics& d, const Eigen::VectorXd& freq_hz) {
  if (d.proportional_damping && !d.modes.empty()) return ReceptanceModal(d, freq_hz);
  return ReceptanceComplexModal(ComputeComplexModes(d.system), freq_hz);
}

}  // namespace robomach::dynamics
