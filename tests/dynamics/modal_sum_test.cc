// The vectorised modal FRF (dynamics/internal/modal_sum.h, ReceptanceModal)
// and the real-arithmetic complex-mode sum against the formulas they
// replaced, kept here as the references, and against a closed form.
#include <complex>
#include <random>

#include <gtest/gtest.h>

#include "dynamics/internal/modal_sum.h"
#include "effect_test_support.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "test_models.h"

namespace robomach::dynamics {
namespace {

using cd = std::complex<double>;
using robomach::testing::Kr210;
using robomach::testing::RandomPosture;

// ReceptanceModal before issue #23: one line at a time, modes inner, the six
// distinct entries of p pᵀ accumulated in real arithmetic.
std::vector<Eigen::Matrix3cd> OldReceptanceModal(const PostureDynamics& d, const Eigen::VectorXd& freq_hz) {
  const int nm = static_cast<int>(d.modes.size());
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
    Eigen::Matrix<double, 6, 1> re = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Matrix<double, 6, 1> im = Eigen::Matrix<double, 6, 1>::Zero();
    for (int k = 0; k < nm; ++k) {
      const double a = w2(k) - w_sq, b = c(k) * w;
      const double inv = 1.0 / (a * a + b * b);
      re.noalias() += (a * inv) * P.col(k);
      im.noalias() -= (b * inv) * P.col(k);
    }
    const int idx[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col) H[i](r, col) = cd(re(idx[r][col]), im(idx[r][col]));
    }
  }
  return H;
}

// ReceptanceComplexModal before issue #23: a complex matrix divided per pole.
std::vector<Eigen::Matrix3cd> OldReceptanceComplexModal(const ComplexModalModel& m, const Eigen::VectorXd& freq_hz) {
  std::vector<Eigen::Matrix3cd> H(freq_hz.size());
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    const cd iw(0.0, HzToRadPerSec(freq_hz(i)));
    Eigen::Matrix3cd h = Eigen::Matrix3cd::Zero();
    for (int k = 0; k < m.poles.size(); ++k) h += m.residues[k] / (iw - m.poles(k));
    H[i] = h;
  }
  return H;
}

// Largest ‖H_i − R_i‖ / ‖R_i‖ (Frobenius) over the lines: per line, not per
// entry, because an off-diagonal entry can be a cancelling sum near zero.
double MaxRelDiff(const std::vector<Eigen::Matrix3cd>& H, const std::vector<Eigen::Matrix3cd>& R) {
  EXPECT_EQ(H.size(), R.size());
  double worst = 0.0;
  for (size_t i = 0; i < R.size(); ++i) worst = std::max(worst, (H[i] - R[i]).norm() / R[i].norm());
  return worst;
}

Eigen::VectorXd P1() {
  Eigen::VectorXd q(6);
  q << 0.0, -1.5707963, 1.5707963, 0.0, 0.7853982, 0.0;
  return q;
}

// Tolerance 1e-12 (issue #23). The new kernel does the same operations in
// the same order per line; on AVX2 the compiler may fuse a multiply and an
// add (one rounding less per term), so the sums differ by a few ulp per
// mode: with 6 modes and terms of comparable size ≈ 1e-15 relative. The
// lowest line (0 Hz) and line counts that are not multiples of the SIMD
// width (the scalar tail) are included.
TEST(ModalSum, EqualsOldFormulaOnEveryKernel) {
  const auto model = Kr210();
  std::mt19937 rng(2302);
  std::vector<Eigen::VectorXd> qs = {P1()};
  for (int i = 0; i < 4; ++i) qs.push_back(RandomPosture(*model, rng));
  for (const Eigen::Index lines : {Eigen::Index(2000), Eigen::Index(1), Eigen::Index(3), Eigen::Index(7)}) {
    const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(lines, 0.0, 1000.0 * lines / 2000.0 + 3.0);
    for (const Eigen::VectorXd& q : qs) {
      const PostureDynamics d = EvaluatePosture(model, q);
      const auto ref = OldReceptanceModal(d, f);
      EXPECT_LE(MaxRelDiff(ReceptanceModal(d, f), ref), 1e-12) << lines << " lines";
      // Each kernel explicitly.
      const int nm = static_cast<int>(d.modes.size());
      std::vector<double> w2(nm), c(nm), P(6 * nm);
      internal::PackModes(d.modes, w2.data(), c.data(), P.data());
      for (auto level : {internal::SimdLevel::kBest, internal::SimdLevel::kBaseline, internal::SimdLevel::kScalar}) {
        std::vector<Eigen::Matrix3cd> H(f.size(), Eigen::Matrix3cd::Constant(cd(NAN, NAN)));
        internal::RealModalSum(nm, w2.data(), c.data(), P.data(), f.data(), f.size(),
                               reinterpret_cast<cd*>(H.data()), level);
        EXPECT_LE(MaxRelDiff(H, ref), 1e-12) << lines << " lines, level " << static_cast<int>(level);
      }
    }
  }
}

// Into a reused vector: the same values, whatever it held.
TEST(ModalSum, ReusedBufferGivesTheSameValues) {
  const PostureDynamics d = EvaluatePosture(Kr210(), P1());
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0);
  std::vector<Eigen::Matrix3cd> H(5000, Eigen::Matrix3cd::Constant(cd(7.0, 7.0)));
  ReceptanceModal(d, f, &H);
  const auto fresh = ReceptanceModal(d, f);
  ASSERT_EQ(H.size(), fresh.size());
  for (size_t i = 0; i < H.size(); ++i) EXPECT_EQ(H[i], fresh[i]);
}

// A one-joint arm (the pendulum of test_models.h, Rayleigh damping): the
// receptance is the 1-DOF closed form B Bᵀ / (k − m ω² + i c ω) with m = M_q,
// k the joint stiffness, c = alpha k + beta m, B = J_v. One complex division
// against a modal sum of one term: both a few ulp, and the mode comes from
// the general N-DOF eigensolver (1e-15 relative): 1e-12.
TEST(ModalSum, OneDofEqualsClosedForm) {
  RobotDescription desc = testing::Pendulum(4.0, 0.35);
  desc.alpha = 2e-4;
  desc.beta = 3.0;
  const auto model = RobotModel::Build(desc);
  for (double q0 : {-1.2, 0.4}) {
    const PostureDynamics d = EvaluatePosture(model, Eigen::VectorXd::Constant(1, q0));
    ASSERT_EQ(d.modes.size(), 1u);
    const double m = d.system.M(0, 0), k = model->joint_stiffness()(0);
    const double c = desc.alpha * k + desc.beta * m;
    const Eigen::Vector3d B = d.J_BT.col(0).head<3>();
    const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2001, 0.0, 5.0 * d.modes[0].freq_hz);
    const auto H = ReceptanceModal(d, f);
    for (Eigen::Index i = 0; i < f.size(); ++i) {
      const double w = HzToRadPerSec(f(i));
      const cd g = 1.0 / cd(k - m * w * w, c * w);
      const Eigen::Matrix3cd expected = (B * B.transpose()).cast<cd>() * g;
      EXPECT_LE((H[i] - expected).norm(), 1e-12 * expected.norm()) << f(i) << " Hz";
    }
  }
}

// The complex-mode sum in real arithmetic against the complex divisions it
// replaced (non-proportional damping: joint_damping). Per term 1/d in real
// arithmetic vs. std::complex division: a few ulp; 1e-12.
TEST(ModalSum, ComplexModesEqualOldFormula) {
  const auto model = testing::Kr210With({{"joint_damping", {}}});
  std::mt19937 rng(2303);
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.0, 1000.0);
  for (int trial = 0; trial < 3; ++trial) {
    const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
    ASSERT_FALSE(d.proportional_damping);
    ASSERT_GT(d.complex_modes.poles.size(), 0);
    EXPECT_LE(MaxRelDiff(ReceptanceComplexModal(d.complex_modes, f),
                         OldReceptanceComplexModal(d.complex_modes, f)),
              1e-12);
  }
}

// A posture evaluated without damping ratios cannot give a modal FRF.
TEST(ModalSum, RefusesPostureWithoutDampingRatios) {
  PostureOptions o;
  o.damping_ratios = false;
  const PostureDynamics d = EvaluatePosture(Kr210(), P1(), o);
  EXPECT_THROW(ReceptanceModal(d, Eigen::VectorXd::LinSpaced(10, 1.0, 100.0)), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::dynamics
