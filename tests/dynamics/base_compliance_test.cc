// The base_compliance effect: the whole robot on a compliant foundation.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <kdl/chaindynparam.hpp>

#include "dynamics/internal/composite_inertia.h"
#include "effect_test_support.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {
namespace {

using robomach::testing::ExpectValidSystem;
using robomach::testing::Kr210;
using robomach::testing::Kr210With;
using robomach::testing::RandomPosture;

// The composite-rigid-body route that the effect uses for the base coupling
// gives, for the joints, KDL's M_q (ChainDynParam::JntToMass, also CRBA but
// with KDL's own recursion in local frames). Both sum the same inertias;
// rounding ≈ 1e-14 of max|M_q| ≈ 1e3 kg·m², so 1e-10 relative.
TEST(BaseCompliance, CompositeInertiaJointBlockEqualsKdlMassMatrix) {
  const auto model = Kr210();
  KDL::ChainDynParam dyn(model->chain().kdl(), KDL::Vector::Zero());
  std::mt19937 rng(21);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    KDL::JntArray jq(6);
    jq.data = q;
    KDL::JntSpaceInertiaMatrix H(6);
    dyn.JntToMass(jq, H);
    const auto ci = internal::ComputeCompositeInertia(model->chain().kdl(), q);
    const Eigen::MatrixXd M = internal::CompositeRigidBodyMassMatrix(ci);
    EXPECT_LE((M - H.data).cwiseAbs().maxCoeff(), 1e-10 * H.data.cwiseAbs().maxCoeff());
  }
}

// Second method for the whole 12×12 M: the kinetic energy of every link, the
// end effector and the foundation mass, all carried by the base displacement
// (u_b, θ_b) about B's origin, from finite-differenced poses (tolerance
// argument as in spindle_interface_test.cc: 1e-7 of √(M_ii M_jj)).
TEST(BaseCompliance, MassMatrixEqualsKineticEnergyOfBodies) {
  const auto model = Kr210With({{"base_compliance", {}}});
  ASSERT_EQ(model->num_dofs(), 12);
  auto base = [](const Eigen::VectorXd& z) {
    return testing::SpringDisplacement(Eigen::Vector3d::Zero(), z.segment<3>(6), z.segment<3>(9));
  };
  std::vector<testing::PosedBody> bodies = testing::LinkBodies(*model, base);
  const RobotModel* m = model.get();
  kinematics::Inertial ee;
  for (const auto& b : m->end_effector_bodies()) ee = kinematics::CombineInertials(ee, b.inertial);
  bodies.push_back({ee, [m, base](const Eigen::VectorXd& z) {
                      return Eigen::Isometry3d(base(z) * testing::TipPose(*m, z));
                    }});
  kinematics::Inertial foundation;
  foundation.mass = m->parameters().Get("base_compliance.foundation_mass_kg");
  foundation.inertia_com =
      m->parameters().Get("base_compliance.foundation_inertia_kgm2") * Eigen::Matrix3d::Identity();
  bodies.push_back({foundation, base});
  std::mt19937 rng(22);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd z = Eigen::VectorXd::Zero(12);
    z.head(6) = RandomPosture(*model, rng);
    const PostureDynamics pd = EvaluatePosture(model, z.head(6));
    ExpectValidSystem(pd.system);
    EXPECT_LE(testing::MaxScaledDifference(pd.system.M, testing::MassFromKineticEnergy(bodies, z, 1e-5)),
              1e-7);
  }
}

// Static superposition: the foundation springs are in series with the
// joints, H(0) = J_v K_q⁻¹ J_vᵀ + G K_b⁻¹ Gᵀ with G = [I  −[p_T]×] (a base
// rotation θ about B's origin moves the tip by θ × p_T), derived by hand.
// Rounding: cond(K) ≈ 1e9/2e5 ≈ 5e3 in these units, ≈ 1e-12 of |H|; 1e-9.
TEST(BaseCompliance, StaticComplianceIsJointPlusFoundationSeries) {
  const auto rigid = Kr210();
  const auto model = Kr210With({{"base_compliance", {}}});
  const Eigen::VectorXd kb = (Eigen::VectorXd(6) << 5e8, 5e8, 1e9, 5e7, 5e7, 5e7).finished();
  std::mt19937 rng(23);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = RandomPosture(*model, rng);
    const PostureDynamics p0 = EvaluatePosture(rigid, q);
    const PostureDynamics p1 = EvaluatePosture(model, q);
    const Eigen::Vector3d p = p1.X_BT.translation();
    Eigen::Matrix<double, 3, 6> G;
    G << 1, 0, 0, 0, p.z(), -p.y(),
         0, 1, 0, -p.z(), 0, p.x(),
         0, 0, 1, p.y(), -p.x(), 0;
    const Eigen::Matrix3d expected =
        p0.static_compliance + G * kb.cwiseInverse().asDiagonal() * G.transpose();
    EXPECT_LE((p1.static_compliance - expected).norm(), 1e-9 * expected.norm());
    // With the defaults the foundation adds a few per cent, not more.
    const double share = (p1.static_compliance.trace() - p0.static_compliance.trace()) /
                         p0.static_compliance.trace();
    EXPECT_GT(share, 0.005);
    EXPECT_LT(share, 0.2);
  }
}

// Stiff limit: all foundation stiffnesses ×10 and ×100; the robot's six modes
// converge to the rigid-base ones with the shift falling ≈ tenfold (0.15
// allows for the second-order term), and so does the FRF below 300 Hz.
TEST(BaseCompliance, ConvergesToTheRigidBaseWhenStiff) {
  auto scaled = [](double s) {
    return Kr210With({{"base_compliance",
                       {{"lateral_stiffness_N_per_m", 5e8 * s}, {"vertical_stiffness_N_per_m", 1e9 * s},
                        {"rocking_stiffness_Nm_per_rad", 5e7 * s},
                        {"torsional_stiffness_Nm_per_rad", 5e7 * s}}}});
  };
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.3, -1.2, 1.4, 0.5, 0.9, -0.4).finished();
  const PostureDynamics p0 = EvaluatePosture(Kr210(), q);
  const PostureDynamics p10 = EvaluatePosture(scaled(10.0), q);
  const PostureDynamics p100 = EvaluatePosture(scaled(100.0), q);
  for (int k = 0; k < 6; ++k) {
    const double d10 = p0.modes[k].freq_hz - p10.modes[k].freq_hz;
    const double d100 = p0.modes[k].freq_hz - p100.modes[k].freq_hz;
    EXPECT_GE(d10, -1e-9 * p0.modes[k].freq_hz);
    EXPECT_LE(std::abs(d100), 0.15 * std::abs(d10) + 1e-9 * p0.modes[k].freq_hz) << "mode " << k;
  }
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(60, 5.0, 300.0);
  const auto H0 = ReceptanceDirect(p0.system, f);
  const auto H10 = ReceptanceDirect(p10.system, f);
  const auto H100 = ReceptanceDirect(p100.system, f);
  double e10 = 0.0, e100 = 0.0;
  for (int i = 0; i < f.size(); ++i) {
    e10 = std::max(e10, (H10[i] - H0[i]).norm() / H0[i].norm());
    e100 = std::max(e100, (H100[i] - H0[i]).norm() / H0[i].norm());
  }
  EXPECT_LT(e100, 0.15 * e10);
}

}  // namespace
}  // namespace robomach::dynamics
