#include "robomach/stability/measured_tip_model.h"

#include <cmath>

#include <gtest/gtest.h>

#include "robomach/common/units.h"

namespace robomach::stability {
namespace {

TEST(DominantModes, KeepsTheMostCompliant) {
  TipModalModel m;
  m.omega_rad_s = Eigen::Vector3d(10.0, 20.0, 30.0);
  m.zeta = Eigen::Vector3d(0.01, 0.01, 0.01);
  m.p = Matrix3Xd::Zero(3, 3);
  m.p(0, 0) = 1.0;   // compliance 1/100
  m.p(1, 1) = 3.0;   // 9/400 — the largest
  m.p(2, 2) = 100.0; // axial only: no in-plane compliance
  const TipModalModel d = DominantModes(m, 2);
  ASSERT_EQ(d.num_modes(), 2);
  EXPECT_EQ(d.omega_rad_s(0), 10.0);
  EXPECT_EQ(d.omega_rad_s(1), 20.0);
}

}  // namespace
}  // namespace robomach::stability
