// ISO 230-2 figures against a hand-computed example.
#include "robomach/machine/iso230.h"

#include <gtest/gtest.h>

namespace robomach::machine {
namespace {

// Two targets, three runs each way, deviations in µm (as integers, so the
// arithmetic is exact in binary):
//   target 10: up 1, 2, 3  (mean 2, s 1);  down -1, -2, -3 (mean -2, s 1)
//   target 20: up 4, 4, 4  (mean 4, s 0);  down  0,  2,  4 (mean  2, s 2)
// By hand (ISO 230-2:2014 definitions):
//   B1 = 4, B2 = 2  -> B = 4, B_mean = 3;  x̄1 = 0, x̄2 = 3 -> M = 3
//   R1↑ = 4, R1↓ = 4, R1 = max(2+2+4, 4, 4) = 8;  R2↑ = 0, R2↓ = 8, R2 = max(0+4+2, 0, 8) = 8
//   R↑ = 4, R↓ = 8, R = 8
//   E↑ = 4 - 2 = 2;  E↓ = 2 - (-2) = 4;  E = max(2,-2,4,2) - min(2,-2,4,2) = 6
//   A↑ = max(2+2, 4+0) - min(2-2, 4-0) = 4
//   A↓ = max(-2+2, 2+4) - min(-2-2, 2-4) = 10
//   A  = max(4, 0, 4, 6) - min(0, -4, 4, -2) = 10
std::vector<Iso230Approach> HandExample() {
  std::vector<Iso230Approach> a;
  auto add = [&](double target, bool up, std::initializer_list<double> devs) {
    int run = 1;
    for (double d : devs) a.push_back({target, run++, up, d});
  };
  add(20, true, {4, 4, 4});
  add(10, true, {1, 2, 3});
  add(10, false, {-1, -2, -3});
  add(20, false, {0, 2, 4});
  return a;
}

TEST(Iso230, HandComputedExampleReproducedExactly) {
  const Iso230Result r = EvaluateIso230(HandExample());
  ASSERT_EQ(r.targets.size(), 2u);
  EXPECT_EQ(r.targets[0].target, 10);
  EXPECT_EQ(r.targets[0].mean_up, 2);
  EXPECT_EQ(r.targets[0].mean_down, -2);
  EXPECT_EQ(r.targets[0].s_up, 1);
  EXPECT_EQ(r.targets[0].s_down, 1);
  EXPECT_EQ(r.targets[0].reversal, 4);
  EXPECT_EQ(r.targets[0].R, 8);
  EXPECT_EQ(r.targets[1].s_down, 2);
  EXPECT_EQ(r.targets[1].R, 8);
  EXPECT_EQ(r.targets[1].mean, 3);
  EXPECT_EQ(r.A, 10);
  EXPECT_EQ(r.A_up, 4);
  EXPECT_EQ(r.A_down, 10);
  EXPECT_EQ(r.E, 6);
  EXPECT_EQ(r.E_up, 2);
  EXPECT_EQ(r.E_down, 4);
  EXPECT_EQ(r.M, 3);
  EXPECT_EQ(r.R, 8);
  EXPECT_EQ(r.R_up, 4);
  EXPECT_EQ(r.R_down, 8);
  EXPECT_EQ(r.B, 4);
  EXPECT_EQ(r.B_mean, 3);
}

// Unit plausibility: the hand example's deviations are in µm. Given as mm
// (÷1000) beside targets of 10 and 20 mm they are plausible; left in µm
// under an _mm header the largest |mean| + 2 s (target 20 down: 2 + 2·2 = 6
// by hand) is 30 % of the targets' magnitude (20 mm) and flagged; the same
// runs with the targets in µm too (20000) pass the relative limit but not
// the absolute 1 mm one.
TEST(Iso230, DeviationsInMicrometresUnderMmAreFlagged) {
  std::vector<Iso230Approach> mm = HandExample(), um_targets = HandExample();
  for (auto& a : mm) a.deviation *= 1e-3;
  for (auto& a : um_targets) a.target *= 1e3;
  EXPECT_TRUE(Iso230UnitFindings("X", EvaluateIso230(mm), false).empty());
  const auto f = Iso230UnitFindings("X", EvaluateIso230(HandExample()), false);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NE(f[0].find("deviations up to 6 mm are 30 % of the targets' magnitude (20 mm"), std::string::npos) << f[0];
  EXPECT_NE(f[0].find("in um"), std::string::npos);
  const auto g = Iso230UnitFindings("X", EvaluateIso230(um_targets), false);
  ASSERT_EQ(g.size(), 1u);
  EXPECT_NE(g[0].find("more than the 1 mm"), std::string::npos) << g[0];
  // Rotary: 6 "deg" is arcsec typed as deg; 6 arcsec (0.00167 deg) is not.
  std::vector<Iso230Approach> arcsec = HandExample();
  for (auto& a : arcsec) a.deviation /= 3600.0;
  EXPECT_EQ(Iso230UnitFindings("C", EvaluateIso230(HandExample()), true).size(), 1u);
  EXPECT_TRUE(Iso230UnitFindings("C", EvaluateIso230(arcsec), true).empty());
}

TEST(Iso230, ShiftingEveryDeviationLeavesSpreadFiguresUnchanged) {
  // Invariant: adding a constant to all deviations changes no figure except
  // the per-target means (all figures are differences or spreads).
  auto a = HandExample();
  for (auto& x : a) x.deviation += 7.0;
  const Iso230Result r = EvaluateIso230(a);
  EXPECT_EQ(r.A, 10);
  EXPECT_EQ(r.E, 6);
  EXPECT_EQ(r.M, 3);
  EXPECT_EQ(r.B, 4);
}

TEST(Iso230, RejectsMissingDirectionAndDuplicates) {
  auto a = HandExample();
  a.resize(6);  // target 10 down has only... up 20 (3), up 10 (3): no down at all
  EXPECT_THROW(EvaluateIso230(a), std::invalid_argument);
  auto b = HandExample();
  b.push_back(b.front());
  EXPECT_THROW(EvaluateIso230(b), std::invalid_argument);
}

TEST(Iso230, WrapsRotaryDeviations) {
  EXPECT_EQ(WrapDeviationDeg(359.999), 359.999 - 360.0);
  EXPECT_EQ(WrapDeviationDeg(180.0), 180.0);
  EXPECT_EQ(WrapDeviationDeg(-180.0), 180.0);
  EXPECT_EQ(WrapDeviationDeg(-0.5), -0.5);
}

}  // namespace
}  // namespace robomach::machine
