// The controller registry: every kind found by its name, its defaults of
// its own kind, its controller built with the gain laws of drilling_sim.h
// (written out here), and an unknown name refused with the known ones.
#include <gtest/gtest.h>

#include <map>

#include "robomach/drilling/controller_kinds.h"
#include "robomach/drilling/drilling_sim.h"

namespace robomach::drilling {
namespace {

std::map<std::string, Eigen::VectorXd> GainsOf(const JointController& c) {
  std::map<std::string, Eigen::VectorXd> g;
  for (const auto& [name, v] : c.gains()) g[name] = v;
  return g;
}

TEST(ControllerKinds, NamesDefaultsAndList) {
  ASSERT_EQ(ControllerKinds().size(), 3u);
  EXPECT_EQ(ControllerKindList(), "pid, pd or pd-tdc");
  for (const ControllerKind* k : ControllerKinds()) {
    EXPECT_EQ(&FindControllerKind(k->name()), k);
    EXPECT_EQ(k->defaults().kind, k->name());
    EXPECT_GT(k->defaults().omega, 0.0);
    EXPECT_EQ(DefaultParameters(k->name()).omega, k->defaults().omega);
  }
  EXPECT_EQ(FindControllerKind("pid").third_parameter(), "integral_ratio");
  EXPECT_EQ(FindControllerKind("pd").third_parameter(), "");
  EXPECT_EQ(FindControllerKind("pd-tdc").third_parameter(), "mbar_ratio");
  EXPECT_TRUE(FindControllerKind("pd-tdc").uses_time_delay_estimation());
  EXPECT_FALSE(FindControllerKind("pid").uses_time_delay_estimation());
  try {
    FindControllerKind("lqr");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown controller kind 'lqr': expected pid, pd or pd-tdc"), std::string::npos) << e.what();
  }
}

TEST(ControllerKinds, BuildWithTheGainLaws) {
  const Eigen::Vector3d m(2.0, 0.5, 0.1);  // effective inertia [kg m²]
  const Eigen::Vector3d limit = Eigen::Vector3d::Constant(100.0);
  const double w = 50.0, zeta = 0.8, L = 1e-3;
  {
    const ControllerParameters p{"pid", w, zeta, 4.0, 0.005};
    const auto g = GainsOf(*FindControllerKind("pid").Make(p, m, L, limit));
    EXPECT_TRUE(g.at("kp_Nm_per_rad").isApprox(m * w * w));
    EXPECT_TRUE(g.at("kd_Nms_per_rad").isApprox(m * 2.0 * zeta * w));
    EXPECT_TRUE(g.at("ki_Nm_per_rad_s").isApprox(m * w * w * w / 4.0));
  }
  {
    const ControllerParameters p{"pd", w, zeta, 0.0, 0.005};
    const auto c = FindControllerKind("pd").Make(p, m, L, limit);
    EXPECT_EQ(c->name(), "pd");
    const auto g = GainsOf(*c);
    EXPECT_TRUE(g.at("kp_Nm_per_rad").isApprox(m * w * w));
    EXPECT_EQ(g.count("ki_Nm_per_rad_s"), 0u);
  }
  {
    const ControllerParameters p{"pd-tdc", w, zeta, 0.5, 0.005};
    const auto c = FindControllerKind("pd-tdc").Make(p, m, L, limit);
    EXPECT_EQ(c->name(), "pd-tdc");
    const auto g = GainsOf(*c);
    EXPECT_TRUE(g.at("kp_per_s2").isApprox(Eigen::Vector3d::Constant(w * w)));
    EXPECT_TRUE(g.at("kd_per_s").isApprox(Eigen::Vector3d::Constant(2.0 * zeta * w)));
    EXPECT_TRUE(g.at("mbar_Nms2_per_rad").isApprox(0.5 * m));
  }
}

}  // namespace
}  // namespace robomach::drilling
