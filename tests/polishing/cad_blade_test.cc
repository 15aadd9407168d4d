// The STEP copy of the demo blade (config/polishing/blade.step) against its
// YAML copy (needs robomach::io for the YAML; cad_face_test.cc does not).
#include <algorithm>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "robomach/io/cad_face.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::io {
namespace {

std::string SourcePath(const std::string& rel) { return std::string(ROBOMACH_SOURCE_DIR) + "/" + rel; }

// The STEP copy of the demo blade holds the YAML patch exactly: same
// degrees, knots, weights, control points (STEP stores mm with 15 digits).
TEST(CadFace, BladeStepHoldsTheYamlPatch) {
  const polishing::NurbsSurface yaml = ReadNurbsYaml(SourcePath("config/polishing/blade.yaml"));
  const polishing::NurbsSurface step = ReadCadFace(SourcePath("config/polishing/blade.step"), 1);
  ASSERT_EQ(CountCadFaces(SourcePath("config/polishing/blade.step")), 1);
  ASSERT_EQ(step.degree_u(), yaml.degree_u());
  ASSERT_EQ(step.degree_v(), yaml.degree_v());
  ASSERT_EQ(step.num_u(), yaml.num_u());
  ASSERT_EQ(step.num_v(), yaml.num_v());
  EXPECT_EQ(step.knots_u(), yaml.knots_u());
  EXPECT_EQ(step.knots_v(), yaml.knots_v());
  for (int i = 0; i < yaml.num_u(); ++i)
    for (int j = 0; j < yaml.num_v(); ++j) {
      EXPECT_LT((step.control_point(i, j) - yaml.control_point(i, j)).norm(), 1e-12) << i << "," << j;
      EXPECT_NEAR(step.weight(i, j), yaml.weight(i, j), 1e-14);
    }
  ASSERT_NE(step.trim(), nullptr);
  EXPECT_EQ(step.trim()->num_wires, 1);
}

// Acceptance (issue 11): the STEP copy of the demo surface gives the same
// removal map as its YAML copy, within the sampling. The same cycloid path
// (planned on the YAML patch) is simulated on both. The region differs only
// in how the 5 mm margin is measured (iso-line arc length on the YAML patch,
// 3-D distance to the boundary edges on the CAD face): only points within
// one sample spacing of the margin line may differ.
TEST(CadFace, BladeStepGivesTheYamlRemovalMap) {
  const polishing::NurbsSurface yaml = ReadNurbsYaml(SourcePath("config/polishing/blade.yaml"));
  const polishing::NurbsSurface step = ReadCadFace(SourcePath("config/polishing/blade.step"), 0);
  const polishing::PolishingProcess process = ReadPolishingProcess(SourcePath("config/polishing/belt_2N.yaml"));
  const double h = 0.5e-3;
  const auto gy = polishing::SampleGrid::Build(yaml, h, process.margin, false);
  const auto gs = polishing::SampleGrid::Build(step, h, process.margin, false);
  ASSERT_EQ(gy.size(), gs.size());
  const polishing::PlannedPath path = polishing::PlanPath(yaml, gy, polishing::PathParameters{}, process);
  const polishing::RemovalSimulator sy(yaml, process, gy.points(), gy.normals(), 0.0015);
  const polishing::RemovalSimulator ss(step, process, gs.points(), gs.normals(), 0.0015);
  const std::vector<double> ry = sy.Simulate(path.rows), rs = ss.Simulate(path.rows);
  double max_ry = 0.0, max_diff = 0.0;
  int both = 0, only_one = 0, only_one_far = 0;
  for (int k = 0; k < gy.size(); ++k) {
    EXPECT_LT((gy.points()[k] - gs.points()[k]).norm(), 1e-12);
    max_ry = std::max(max_ry, ry[k]);
    max_diff = std::max(max_diff, std::abs(ry[k] - rs[k]));
    if (gy.in_region()[k] && gs.in_region()[k]) ++both;
    if (gy.in_region()[k] != gs.in_region()[k]) {
      ++only_one;
      // Its straight distance to the face's boundary edges.
      double edge = 1e300;
      for (const auto& line : step.trim()->boundary)
        for (size_t q = 1; q < line.size(); ++q) {
          const Eigen::Vector3d ab = line[q] - line[q - 1];
          const double f = std::clamp((gy.points()[k] - line[q - 1]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
          edge = std::min(edge, (line[q - 1] + f * ab - gy.points()[k]).norm());
        }
      if (std::abs(edge - process.margin) > 2 * h) ++only_one_far;
    }
  }
  EXPECT_LT(max_diff, 1e-9 * max_ry);  // same patch, same path: same removal everywhere
  EXPECT_EQ(only_one_far, 0);
  EXPECT_LT(only_one, 0.02 * both) << both;
  // And the statistics over each region agree to well within a percent.
  const auto sty = polishing::ComputeRemovalStats(ry, gy.areas(), gy.in_region());
  const auto sts = polishing::ComputeRemovalStats(rs, gs.areas(), gs.in_region());
  EXPECT_NEAR(sts.mean / sty.mean, 1.0, 0.005);
  EXPECT_NEAR(sts.cv, sty.cv, 0.01 * sty.cv + 1e-3);
  std::cout << "blade YAML vs STEP: " << both << " common points, " << only_one << " in one region only; mean "
            << sty.mean * 1e6 << " / " << sts.mean * 1e6 << " um, cv " << sty.cv << " / " << sts.cv << "\n";
}

}  // namespace
}  // namespace robomach::io
