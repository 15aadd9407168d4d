// Tool-tip FRF: modal superposition against the direct solve, static and
// symmetry invariants, complex modes, a decoupled closed form, and the
// wrist singularity.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include "robomach/common/units.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "test_models.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::Kr210;
using robomach::testing::RandomPosture;

Eigen::VectorXd Grid() { return Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0); }

double MaxRelDiff(const std::vector<Eigen::Matrix3cd>& a, const std::vector<Eigen::Matrix3cd>& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, (a[i] - b[i]).norm() / b[i].norm());
  }
  return worst;
}

// (2) and (1) of tool_tip_frf.h are algebraically identical for proportional
// damping. The modal route loses ≈ cond(M_q) eps ≈ 1e-12 in the mass
// normalisation and the LU route ≈ N eps |D||D⁻¹| near resonance
// (|D⁻¹| ≈ 1/(2ζk) with ζ ≈ 0.01): ≈ 1e-12; 1e-9 is the bound.
TEST(ToolTipFrf, ModalSuperpositionEqualsDirectSolve) {
  const auto model = Kr210();
  std::mt19937 rng(21);
  for (int trial = 0; trial < 5; ++trial) {
    const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
    EXPECT_LE(MaxRelDiff(ReceptanceModal(d, Grid()), ReceptanceDirect(d.system, Grid())), 1e-9);
  }
}

// The state-space (complex-mode) route is a third, independent formula.
TEST(ToolTipFrf, ComplexModesEqualDirectSolve) {
  const auto model = Kr210();
  std::mt19937 rng(22);
  const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
  const auto cm = ComputeComplexModes(d.system);
  EXPECT_LE(MaxRelDiff(ReceptanceComplexModal(cm, Grid()), ReceptanceDirect(d.system, Grid())), 1e-9);
  // Its poles reproduce the modal damping 2ζω = alpha ω² + beta.
  for (const Mode& m : d.modes) {
    const double w = HzToRadPerSec(m.freq_hz);
    EXPECT_NEAR(2 * m.damping_ratio * w, model->alpha() * w * w + model->beta(), 1e-9 * w);
  }
}

// The single-entry evaluator against the direct solve, on both of its
// paths: real modes (proportional damping) and complex modes (a flange on
// springs with its own modal damping, C_extra ≠ 0; modes from 10 Hz to
// kHz, cond(M) ≈ 1e5). Same 1e-9 as above: the balanced state-space form of
// ComputeComplexModes holds it (measured 5e-11; the plain [0 I; −M⁻¹K −M⁻¹C]
// form gave 3e-8 here).
TEST(ToolTipFrf, SingleEntryEvaluatorEqualsDirectSolve) {
  for (const std::string effect : {"", "flange_compliance"}) {
    io::RobotConfig cfg = robomach::testing::Kr210Config();
    if (!effect.empty()) {
      cfg.description.effects.push_back({effect, {}});
      const ParameterSet start = cfg.parameters;
      cfg.parameters = DefaultParameters(cfg.description);
      for (const auto& s : start.specs()) cfg.parameters.Set(s.name, start.Get(s.name));
    }
    const auto model = RobotModel::Build(cfg.description, cfg.parameters);
    std::mt19937 rng(23);
    const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
    EXPECT_EQ(d.proportional_damping, effect.empty());
    const ReceptanceEvaluator ev(d);
    const auto direct = ReceptanceDirect(d.system, Grid());
    for (int r = 0; r < 3; ++r) {
      for (int e = 0; e < 3; ++e) {
        const Eigen::VectorXcd h = ev.Entry(Grid(), r, e);
        double worst = 0.0;
        for (int i = 0; i < h.size(); ++i) {
          worst = std::max(worst, std::abs(h(i) - direct[i](r, e)) / direct[i].norm());
        }
        EXPECT_LE(worst, 1e-9) << effect << " H" << r << e;
      }
    }
    EXPECT_THROW(ev.Entry(Grid(), 3, 0), std::invalid_argument);
  }
}

// H(0) = J_v K_q⁻¹ J_vᵀ: the static compliance of elastic joints
// [Salisbury 1980]. Both sides are O(1e-6) m/N; relative 1e-10.
TEST(ToolTipFrf, ZeroFrequencyIsStaticCompliance) {
  const auto model = Kr210();
  std::mt19937 rng(23);
  for (int trial = 0; trial < 5; ++trial) {
    const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
    const Eigen::MatrixXd Jv = d.J_BT.topRows<3>();
    const Eigen::Matrix3d expected =
        Jv * model->joint_stiffness().cwiseInverse().asDiagonal() * Jv.transpose();
    const auto H0 = ReceptanceDirect(d.system, Eigen::VectorXd::Zero(1))[0];
    EXPECT_LE((H0.real() - expected).norm(), 1e-10 * expected.norm());
    EXPECT_LE(H0.imag().norm(), 1e-14 * expected.norm());
    EXPECT_LE((d.static_compliance - expected).norm(), 1e-10 * expected.norm());
  }
}

// Reciprocity (Maxwell-Betti): the receptance matrix is symmetric, Hxy = Hyx,
// because M, C and K are symmetric; and H(−ω) = conj H(ω) for a real system.
TEST(ToolTipFrf, ReciprocityAndConjugateSymmetry) {
  const auto model = Kr210();
  std::mt19937 rng(24);
  const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
  const auto H = ReceptanceDirect(d.system, Grid());
  const auto Hneg = ReceptanceDirect(d.system, -Grid());
  for (size_t i = 0; i < H.size(); ++i) {
    EXPECT_LE((H[i] - H[i].transpose()).norm(), 1e-12 * H[i].norm());
    EXPECT_LE((Hneg[i] - H[i].conjugate()).norm(), 1e-12 * H[i].norm());
  }
}

// Joint-space FRF equals the Cartesian (K_X − ω² M_X + iω C_X)⁻¹ block where J
// is regular. The Cartesian route inverts a matrix with cond ≈ cond(J)² ·
// cond(K_q) ≈ 1e8, so it is accurate to ≈ 1e-8; tolerance 1e-6.
TEST(ToolTipFrf, JointSpaceEqualsCartesianForm) {
  const auto model = Kr210();
  std::mt19937 rng(25);
  const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
  ASSERT_TRUE(d.M_X.allFinite());
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(50, 1.0, 400.0);
  const auto H = ReceptanceDirect(d.system, f);
  for (int i = 0; i < f.size(); ++i) {
    const double w = HzToRadPerSec(f(i));
    Eigen::Matrix<std::complex<double>, 6, 6> D;
    D.real() = d.K_X - w * w * d.M_X;
    D.imag() = w * d.C_X;
    const Eigen::Matrix3cd Hc = D.inverse().topLeftCorner<3, 3>();
    EXPECT_LE((Hc - H[i]).norm(), 1e-6 * H[i].norm()) << f(i) << " Hz";
  }
}

// A decoupled system: each diagonal entry must be the 1-DOF closed form
// 1/(k − mω² + icω) (style.md §2.14).
TEST(ToolTipFrf, DecoupledSystemMatchesSingleDofClosedForm) {
  AssembledSystem s;
  s.num_joints = 3;
  const Eigen::Vector3d m(2.0, 3.0, 5.0), k(8e6, 1.2e7, 3e7), c(150.0, 220.0, 400.0);
  s.M = m.asDiagonal();
  s.K = k.asDiagonal();
  s.C = c.asDiagonal();
  s.B = Eigen::Matrix3d::Identity();
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(200, 10.0, 1000.0);
  const auto H = ReceptanceDirect(s, f);
  for (int i = 0; i < f.size(); ++i) {
    const double w = HzToRadPerSec(f(i));
    for (int a = 0; a < 3; ++a) {
      const std::complex<double> expected = 1.0 / std::complex<double>(k(a) - m(a) * w * w, c(a) * w);
      // One complex division: ≈ 2e-14 relative; 1e-12 keeps a margin.
      EXPECT_LE(std::abs(H[i](a, a) - expected), 1e-12 * std::abs(expected));
    }
  }
}

// At the wrist singularity (q5 = 0) J loses rank: the Cartesian matrices are
// meaningless, but the joint-space FRF stays finite and equals the modal one.
TEST(ToolTipFrf, WristSingularPostureGivesFiniteFrfAndIsFlagged) {
  const auto model = Kr210();
  Eigen::VectorXd q(6);
  q << 0.0, DegToRad(-90), DegToRad(90), 0.0, 0.0, 0.0;
  const PostureDynamics d = EvaluatePosture(model, q);
  EXPECT_TRUE(d.near_singular);
  EXPECT_GT(d.jacobian_condition, kNearSingularCondition);
  EXPECT_FALSE(d.M_X.allFinite());  // not reported, instead of garbage
  const auto H = ReceptanceDirect(d.system, Grid());
  for (const auto& h : H) ASSERT_TRUE(h.allFinite());
  EXPECT_LE(MaxRelDiff(ReceptanceModal(d, Grid()), H), 1e-9);
  EXPECT_TRUE(d.static_compliance.allFinite());
}

// Modal mass and mode shape: the tool-tip receptance near an isolated mode is
// dominated by p pᵀ / (2iζω²); the modal mass is 1/|p|².
TEST(ToolTipFrf, ModalMassIsInverseSquaredTipShape) {
  const auto model = Kr210();
  std::mt19937 rng(26);
  const PostureDynamics d = EvaluatePosture(model, RandomPosture(*model, rng));
  for (const Mode& m : d.modes) {
    EXPECT_NEAR(m.modal_mass_kg * m.p_T.squaredNorm(), 1.0, 1e-12);
    EXPECT_NEAR(m.shape_T.norm(), 1.0, 1e-12);
    EXPECT_NEAR(m.phi.dot(d.system.M * m.phi), 1.0, 1e-10);
  }
}

}  // namespace
}  // namespace robomach::dynamics
