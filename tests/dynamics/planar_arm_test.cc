// A planar two-link arm built from a modified-DH table against the textbook
// closed-form inertia matrix [Spong, Hutchinson & Vidyasagar 2006, §7.4.1]:
//   M11 = m1 lc1² + m2 (l1² + lc2² + 2 l1 lc2 cos q2) + I1 + I2
//   M12 = m2 (lc2² + l1 lc2 cos q2) + I2
//   M22 = m2 lc2² + I2
// with I_i the links' moments about their COM about the joint axes (z).
#include <gtest/gtest.h>

#include "robomach/common/units.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/kinematics/modified_dh.h"

namespace robomach::dynamics {
namespace {

constexpr double l1 = 0.8, l2 = 0.6, lc1 = 0.35, lc2 = 0.25;  // [m]
constexpr double m1 = 12.0, m2 = 7.0;                          // [kg]
constexpr double I1 = 0.9, I2 = 0.4;                           // [kg·m²] about z at the COM

RobotDescription PlanarArm() {
  auto link = [](const std::string& name, double a_prev, double m, double lc, double Izz) {
    kinematics::ModifiedDhRow r;
    r.joint_name = name;
    r.a_prev = a_prev;
    r.inertial.mass = m;
    r.inertial.com = Eigen::Vector3d(lc, 0.0, 0.0);
    // A slender link: Ixx small, Iyy = Izz (triangle inequality holds).
    r.inertial.inertia_com = Eigen::Vector3d(0.1 * Izz, Izz, Izz).asDiagonal();
    return r;
  };
  Eigen::Isometry3d X_nT = Eigen::Isometry3d::Identity();
  X_nT.translation() = Eigen::Vector3d(l2, 0.0, 0.0);
  RobotDescription d;
  d.arm = kinematics::BuildModifiedDhChain({link("j1", 0.0, m1, lc1, I1), link("j2", l1, m2, lc2, I2)},
                                           Eigen::Isometry3d::Identity(), X_nT);
  d.joint_stiffness = Eigen::Vector2d(2e5, 8e4);
  d.alpha = 1e-4;
  d.beta = 2.0;
  return d;
}

TEST(PlanarArm, MassMatrixMatchesClosedForm) {
  const RobotDescription d = PlanarArm();
  const auto model = RobotModel::Build(d);
  for (double q2 : {-2.5, -1.0, 0.0, 0.4, 1.3, 3.0}) {
    const Eigen::Vector2d q(0.7, q2);
    const PostureDynamics pd = EvaluatePosture(model, q);
    const double c2 = std::cos(q2);
    Eigen::Matrix2d M;
    M(0, 0) = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2 * l1 * lc2 * c2) + I1 + I2;
    M(0, 1) = M(1, 0) = m2 * (lc2 * lc2 + l1 * lc2 * c2) + I2;
    M(1, 1) = m2 * lc2 * lc2 + I2;
    // Closed form in double precision: rounding ≈ 1e-15 of M11 ≈ 10 kg·m².
    EXPECT_LE((pd.M_q() - M).cwiseAbs().maxCoeff(), 1e-12) << "q2 = " << q2;
  }
}

// The tip-mass effect on the same arm: ΔM = m J_vᵀ J_v with the planar
// Jacobian J_v = [−l1 s1 − l2 s12, −l2 s12; l1 c1 + l2 c12, l2 c12; 0, 0].
TEST(PlanarArm, TipMassAddsClosedFormInertia) {
  RobotDescription d = PlanarArm();
  const auto bare = RobotModel::Build(d);
  d.effects.push_back({"tip_mass", {{"mass_kg", 1.5}}});
  const auto loaded = RobotModel::Build(d);
  const Eigen::Vector2d q(0.3, 1.1);
  const double s1 = std::sin(q(0)), c1 = std::cos(q(0));
  const double s12 = std::sin(q(0) + q(1)), c12 = std::cos(q(0) + q(1));
  Eigen::Matrix<double, 2, 2> Jv;
  Jv << -l1 * s1 - l2 * s12, -l2 * s12, l1 * c1 + l2 * c12, l2 * c12;
  const Eigen::Matrix2d expected = EvaluatePosture(bare, q).M_q() + 1.5 * Jv.transpose() * Jv;
  EXPECT_LE((EvaluatePosture(loaded, q).M_q() - expected).cwiseAbs().maxCoeff(), 1e-12);
}

// A two-joint arm is not square: no Cartesian 6×6 matrices, but modes,
// static compliance and FRF are well defined.
TEST(PlanarArm, NonSquareJacobianHasNoCartesianMatricesButModes) {
  const auto model = RobotModel::Build(PlanarArm());
  const PostureDynamics pd = EvaluatePosture(model, Eigen::Vector2d(0.2, 0.9));
  EXPECT_FALSE(pd.M_X.allFinite());
  ASSERT_EQ(pd.modes.size(), 2u);
  EXPECT_GT(pd.modes[0].freq_hz, 0.0);
  EXPECT_TRUE(pd.static_compliance.allFinite());
}

}  // namespace
}  // namespace robomach::dynamics
