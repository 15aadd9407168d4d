#include "robomach/io/cad_face.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Builder.hxx>
#include <IGESControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::io {
namespace {

std::string TmpPath(const std::string& name) {
  std::filesystem::create_directories(std::string(ROBOMACH_TEST_TMP_DIR) + "/cad_face");
  return std::string(ROBOMACH_TEST_TMP_DIR) + "/cad_face/" + name;
}

// A plate Lx x Ly [mm] in z = 0 with a circular hole of radius r at (cx, cy),
// made with OpenCASCADE's own builders (not robomach's code) and written
// with its STEP writer in mm.
TopoDS_Face PlateWithHole(double Lx, double Ly, double cx, double cy, double r) {
  const gp_Pln plane(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1));
  const gp_Pnt a(0, 0, 0), b(Lx, 0, 0), c(Lx, Ly, 0), d(0, Ly, 0);
  BRepBuilderAPI_MakeWire outer(BRepBuilderAPI_MakeEdge(a, b), BRepBuilderAPI_MakeEdge(b, c),
                                BRepBuilderAPI_MakeEdge(c, d), BRepBuilderAPI_MakeEdge(d, a));
  BRepBuilderAPI_MakeFace face(plane, outer.Wire());
  if (r > 0) {
    const gp_Circ circle(gp_Ax2(gp_Pnt(cx, cy, 0), gp_Dir(0, 0, 1)), r);
    TopoDS_Wire hole = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle)).Wire();
    hole.Reverse();  // inner wires run clockwise seen from the normal
    face.Add(hole);
  }
  return face.Face();
}

void WriteStep(const TopoDS_Shape& shape, const std::string& path) {
  SetUpOpenCascadeExchange();  // as the reader does (messages off, controllers set up once)
  STEPControl_Writer w;
  ASSERT_EQ(w.Transfer(shape, STEPControl_AsIs), IFSelect_RetDone);
  ASSERT_EQ(w.Write(path.c_str()), IFSelect_RetDone);
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// A trimmed face with a hole, built by OpenCASCADE: a 100 x 60 mm plate with
// a 10 mm radius hole at (50, 30), margin 5 mm. The polished region is
// analytically 5 <= x <= 95, 5 <= y <= 55, |(x, y) - (50, 30)| >= 15.
TEST(CadFace, PlateWithHoleRegionMatchesAnalytic) {
  const std::string file = TmpPath("plate_hole.step");
  WriteStep(PlateWithHole(100, 60, 50, 30, 10), file);
  const polishing::NurbsSurface s = ReadCadFace(file, 1);
  ASSERT_NE(s.trim(), nullptr);
  EXPECT_EQ(s.trim()->num_wires, 2);
  EXPECT_NEAR(s.trim()->area, (6000.0 - kPi * 100.0) * 1e-6, 1e-6 * 6000e-6);  // OCCT's own face area
  auto on_face = [&](double x_mm, double y_mm) {
    double u = 0.5 * (s.u_min() + s.u_max()), v = 0.5 * (s.v_min() + s.v_max());
    EXPECT_LT(polishing::ProjectToSurface(s, Eigen::Vector3d(x_mm, y_mm, 0) * 1e-3, &u, &v), 1e-9);
    return s.OnFace(u, v);
  };
  EXPECT_FALSE(on_face(50, 30));    // hole centre
  EXPECT_FALSE(on_face(59.9, 30));  // in the hole
  EXPECT_TRUE(on_face(60.1, 30));   // just outside it
  EXPECT_TRUE(on_face(1, 1));
  // The wires in the parameter plane (for the guide lines): the outer
  // rectangle and the hole, every point of them on the edge it samples.
  ASSERT_EQ(s.trim()->wires_uv.size(), 2u);
  size_t points = 0;
  for (const auto& wire : s.trim()->wires_uv) {
    ASSERT_GE(wire.size(), 8u);
    for (const Eigen::Vector2d& uv : wire) {
      const Eigen::Vector3d p = s.Point(uv.x(), uv.y()) * 1e3;  // mm
      const double d_edge = std::min({std::abs(p.x()), std::abs(p.x() - 100), std::abs(p.y()), std::abs(p.y() - 60)});
      const double d_hole = std::abs(std::hypot(p.x() - 50, p.y() - 30) - 10);
      EXPECT_LT(std::min(d_edge, d_hole), 1e-6) << p.transpose();
      ++points;
    }
  }
  EXPECT_GT(points, (320 + 2 * kPi * 10) / 0.25 * 0.9);  // 0.25 mm chords
  const double margin = 5e-3, h = 0.25e-3;
  const auto g = polishing::SampleGrid::Build(s, h, margin, false);
  // Every sample point against the analytic rule, except within 2 um of the
  // region's boundary (the hole is a polyline of 0.25 mm chords, sag 0.8 um).
  int wrong = 0, in = 0;
  double area = 0.0;
  for (int k = 0; k < g.size(); ++k) {
    const Eigen::Vector3d p = g.points()[k] * 1e3;  // mm
    ASSERT_NEAR(p.z(), 0.0, 1e-9);
    const double dc = std::hypot(p.x() - 50, p.y() - 30) - 15;
    const double de = std::min({p.x() - 5, 95 - p.x(), p.y() - 5, 55 - p.y()});
    const double d = std::min(dc, de);  // > 0 inside the analytic region
    if (g.in_region()[k]) ++in, area += g.areas()[k];
    if (std::abs(d) < 2e-3) continue;
    if ((d > 0) != static_cast<bool>(g.in_region()[k])) ++wrong;
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(in, 50000);
  // Area: the sampled region's area weights against 4500 - pi 15^2 mm^2;
  // each grid cell cut by the region boundary (length 374 mm) is counted
  // whole or not at all, so |error| <= 374 mm x h / 2 = 47 mm^2 (1.2 %).
  const double exact = 4500.0 - kPi * 225.0;
  EXPECT_NEAR(area * 1e6, exact, 374.0 * 0.25 / 2) << "exact " << exact;
  std::cout << "plate with hole: region area " << area * 1e6 << " mm^2 sampled, " << exact << " analytic\n";
}

// Face numbering: 1-based in the file's order; 0 picks the largest; a face
// number beyond the file's is an error naming the file and the face count.
TEST(CadFace, FaceNumbersAndMissingFace) {
  const std::string file = TmpPath("two_plates.step");
  TopoDS_Compound both;
  BRep_Builder b;
  b.MakeCompound(both);
  b.Add(both, PlateWithHole(20, 20, 0, 0, 0));   // small plate first
  b.Add(both, PlateWithHole(100, 60, 50, 30, 10));
  WriteStep(both, file);
  ASSERT_EQ(CountCadFaces(file), 2);
  EXPECT_NEAR(ReadCadFace(file, 1).trim()->area, 400e-6, 1e-9);
  EXPECT_NEAR(ReadCadFace(file, 2).trim()->area, (6000.0 - kPi * 100) * 1e-6, 1e-9);
  EXPECT_NEAR(ReadCadFace(file, 0).trim()->area, (6000.0 - kPi * 100) * 1e-6, 1e-9);
  EXPECT_THAT(ErrorOf([&] { ReadCadFace(file, 3); }),
              ::testing::HasSubstr("two_plates.step: --face 3: the STEP file has 2 faces (1..2)"));
}

// IGES: the same plate with a hole through OpenCASCADE's IGES writer
// (trimmed surface entities) reads back with its hole.
TEST(CadFace, IgesPlateWithHole) {
  const std::string file = TmpPath("plate_hole.igs");
  SetUpOpenCascadeExchange();
  IGESControl_Writer w("MM", 0);
  ASSERT_TRUE(w.AddShape(PlateWithHole(100, 60, 50, 30, 10)));
  w.ComputeModel();
  ASSERT_TRUE(w.Write(file.c_str()));
  ASSERT_EQ(CountCadFaces(file), 1);
  const polishing::NurbsSurface s = ReadCadFace(file, 1);
  EXPECT_EQ(s.trim()->num_wires, 2);
  EXPECT_NEAR(s.trim()->area, (6000.0 - kPi * 100.0) * 1e-6, 1e-4 * 6000e-6);
  const auto g = polishing::SampleGrid::Build(s, 0.5e-3, 5e-3, false);
  // SampleGrid::region_area (what the tools' summaries report) against
  // the analytic area, within the cells cut by the boundary.
  EXPECT_NEAR(g.region_area() * 1e6, 4500.0 - kPi * 225.0, 374.0 * 0.5 / 2);
}

// Faces of solids made by OpenCASCADE: half of a box's faces are REVERSED
// in the shell, and a cylinder's side is a periodic surface with a seam.
// Every face's normal S_u x S_v must point out of the solid; the cylinder
// side's region (margin from its two circles, not from the seam) is the band
// 5 <= z <= 45 mm, area 2 pi 30 x 40 mm^2.
TEST(CadFace, SolidFacesPointOutwardsAndSeamsAreNoBoundary) {
  const std::string box = TmpPath("box.step"), cyl = TmpPath("cylinder.step");
  WriteStep(BRepPrimAPI_MakeBox(100, 60, 20).Shape(), box);
  WriteStep(BRepPrimAPI_MakeCylinder(30, 50).Shape(), cyl);
  for (const auto& [file, centre] : {std::pair{box, Eigen::Vector3d(0.05, 0.03, 0.01)},
                                     std::pair{cyl, Eigen::Vector3d(0.0, 0.0, 0.025)}}) {
    const int n = CountCadFaces(file);
    ASSERT_EQ(n, file == box ? 6 : 3);
    for (int i = 1; i <= n; ++i) {
      const polishing::NurbsSurface s = ReadCadFace(file, i);
      const double u = 0.5 * (s.u_min() + s.u_max()), v = 0.5 * (s.v_min() + s.v_max());
      ASSERT_TRUE(s.OnFace(u, v)) << file << " face " << i;
      const polishing::SurfaceDerivatives d = s.Evaluate(u, v);
      Eigen::Vector3d out = d.S - centre;
      const Eigen::Vector3d n_face = polishing::UnitNormal(d);
      if (file == cyl && std::abs(n_face.z()) < 0.5) out.z() = 0.0;  // the side: radial
      EXPECT_GT(n_face.dot(out.normalized()), 0.999) << file << " face " << i;
    }
  }
  const polishing::NurbsSurface side = ReadCadFace(cyl, 0);  // the largest face
  EXPECT_NEAR(side.trim()->area, 2 * kPi * 30 * 50 * 1e-6, 1e-6 * 2 * kPi * 30 * 50 * 1e-6);
  EXPECT_EQ(side.trim()->boundary.size(), 2u);  // the two circles; the seam is no boundary
  const auto g = polishing::SampleGrid::Build(side, 0.5e-3, 5e-3, false);
  double area = 0.0;
  for (int k = 0; k < g.size(); ++k) {
    if (!g.in_region()[k]) continue;
    area += g.areas()[k];
    EXPECT_GE(g.points()[k].z(), 5e-3 - 1e-6);
    EXPECT_LE(g.points()[k].z(), 45e-3 + 1e-6);
  }
  // Boundary: two circles of 188 mm, each cut cell counted whole or not.
  EXPECT_NEAR(area * 1e6, 2 * kPi * 30 * 40, 2 * 188.5 * 0.5 / 2);
}

// Planning on a curved trimmed face made by OpenCASCADE's boolean cut (not
// by robomach): a quarter cylinder R 60 mm, 80 mm high, with a radial hole of
// radius 10 mm drilled at 45 deg, z = 40 mm. The rows in contact must lie on
// the cylinder, inside the quarter and outside the drilled hole (distance
// from the drill's axis >= 10 mm), for the cycloid on offsets and the
// zig-zag; the default cycloid covers the region.
TEST(CadFace, PathsOnACurvedFaceWithADrilledHole) {
  const std::string file = TmpPath("quarter_cylinder_hole.step");
  const TopoDS_Shape quarter = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 60, 80, kPi / 2).Shape();
  const gp_Dir radial(std::cos(kPi / 4), std::sin(kPi / 4), 0);
  const TopoDS_Shape drill = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 40), radial), 10, 100).Shape();
  BRepAlgoAPI_Cut cut(quarter, drill);
  ASSERT_TRUE(cut.IsDone());
  WriteStep(cut.Shape(), file);
  const polishing::NurbsSurface face = ReadCadFace(file, 0);  // the largest: the drilled cylindrical side
  ASSERT_NE(face.trim(), nullptr);
  ASSERT_EQ(face.trim()->num_wires, 2);
  polishing::PolishingProcess proc;
  proc.margin = 3e-3;
  const auto grid = polishing::SampleGrid::Build(face, 0.5e-3, proc.margin, false);
  const Eigen::Vector3d axis_point(0, 0, 0.040), axis(radial.X(), radial.Y(), 0);
  for (const auto pattern : {polishing::Pattern::kCycloid, polishing::Pattern::kParallel}) {
    polishing::PathParameters p;
    p.pattern = pattern;
    if (pattern == polishing::Pattern::kParallel) p.offset = 0.004;
    const polishing::PlannedPath path = polishing::PlanPath(face, grid, p, proc);
    int in_contact = 0;
    for (size_t i = 0; i < path.rows.size(); ++i) {
      const Eigen::Vector3d x = path.rows[i].p;
      if (path.rows[i].force == 0.0) continue;
      ++in_contact;
      ASSERT_NEAR(std::hypot(x.x(), x.y()), 0.060, 1e-6) << i;
      ASSERT_TRUE(x.x() >= -1e-7 && x.y() >= -1e-7 && x.z() >= -1e-7 && x.z() <= 0.080 + 1e-7) << i;
      const Eigen::Vector3d q = x - axis_point;
      ASSERT_GE((q - q.dot(axis) * axis).norm(), 0.010 - 2e-6) << "row " << i << " in the hole";
      ASSERT_TRUE(face.OnFace(path.rows[i].u, path.rows[i].v)) << i;
    }
    EXPECT_GT(in_contact, 1000);
    if (pattern == polishing::Pattern::kCycloid) {
      const polishing::RemovalSimulator sim(face, proc, grid.points(), grid.normals(), 1.5e-3);
      const auto st = polishing::ComputeRemovalStats(sim.Simulate(path.rows), grid.areas(), grid.in_region());
      EXPECT_GE(st.coverage, 0.99);
      std::cout << "drilled quarter cylinder: default cycloid cv " << st.cv << ", coverage " << st.coverage
                << ", lifts " << path.lifts << "\n";
    }
  }
}

// A whole cylinder (R 30 mm, 60 mm high) drilled radially at 90 deg: the
// side face has a seam at 0 deg, which is no edge of the material. The
// margin is kept from the two circles and the hole only, so the zig-zag
// polishes across the seam line: coverage as anywhere else.
TEST(CadFace, SeamTakesNoMarginOnADrilledCylinder) {
  const std::string file = TmpPath("cylinder_hole.step");
  const TopoDS_Shape cyl = BRepPrimAPI_MakeCylinder(30, 60).Shape();
  const TopoDS_Shape drill = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 30), gp_Dir(0, 1, 0)), 8, 50).Shape();
  BRepAlgoAPI_Cut cut(cyl, drill);
  ASSERT_TRUE(cut.IsDone());
  WriteStep(cut.Shape(), file);
  const polishing::NurbsSurface face = ReadCadFace(file, 0);
  ASSERT_NE(face.trim(), nullptr);
  polishing::PolishingProcess proc;
  proc.margin = 3e-3;
  const auto grid = polishing::SampleGrid::Build(face, 0.5e-3, proc.margin, false);
  polishing::PathParameters p;
  p.pattern = polishing::Pattern::kParallel;
  p.offset = 0.003;
  const polishing::PlannedPath path = polishing::PlanPath(face, grid, p, proc);
  for (const auto& r : path.rows) {
    if (r.force != 0.0) ASSERT_TRUE(face.OnFace(r.u, r.v));
  }
  const polishing::RemovalSimulator sim(face, proc, grid.points(), grid.normals(), 1.5e-3);
  const std::vector<double> h = sim.Simulate(path.rows);
  const auto st = polishing::ComputeRemovalStats(h, grid.areas(), grid.in_region());
  EXPECT_GE(st.coverage, 0.99);
  // At the seam (angle within 2 mm of 0 deg) the removal is that of the rest.
  double seam = 0.0, seam_area = 0.0;
  for (int k = 0; k < grid.size(); ++k) {
    const Eigen::Vector3d q = grid.points()[k];
    if (!grid.in_region()[k] || std::abs(q.z() - 0.030) > 0.015) continue;
    if (std::abs(std::atan2(q.y(), q.x())) * 0.030 < 0.002) seam += h[k] * grid.areas()[k], seam_area += grid.areas()[k];
  }
  ASSERT_GT(seam_area, 0.0);
  EXPECT_GT(seam / seam_area, 0.8 * st.mean) << "mean at the seam " << seam / seam_area << ", overall " << st.mean;
}

// A face bound that refers to an entity the file does not have: OpenCASCADE
// loads the file with a check failure, and its translator then crashed on
// the null reference (SEGV; issue #22, found by fuzz_cad_face, input kept in
// tests/fuzz/corpus/cad_face). Refused as damaged before the translation
// (entity 17 is the ADVANCED_FACE; its second parameter, the face bounds).
TEST(CadFace, UnresolvedReferenceIsRefusedBeforeTranslation) {
  std::ifstream in(ROBOMACH_SOURCE_DIR "/tests/data/polishing/plate_hole.step");
  std::string step((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "#17 = ADVANCED_FACE('',(#18,#89)";
  ASSERT_NE(step.find(from), std::string::npos);
  step.replace(step.find(from), from.size(), "#17 = ADVANCED_FACE('',(#18,#999)");
  const std::string path = TmpPath("unresolved.step");
  std::ofstream(path) << step;
  const std::string e = ErrorOf([&] { ReadCadFace(path, 0); });
  EXPECT_THAT(e, ::testing::HasSubstr("unresolved.step: not a readable STEP file: 1 damaged entity"));
  EXPECT_THAT(e, ::testing::HasSubstr("first, entity 17 in file order: Parameter n0.2 (face_bound)"));
}

// A reference cycle: OpenCASCADE's reader recursed without end on an
// ORIENTED_EDGE that is its own edge element (a stack overflow while it
// checked the file; issue #22, found by fuzz_cad_face, input kept in
// tests/fuzz/corpus/cad_face). Two cycles made from plate_hole.step: the
// edge on itself, and a longer one through a vertex (#22 -> #23 -> #20 ->
// #21 -> #22); both refused with the line of an instance on the cycle. The
// file as it is (no cycle) still reads.
TEST(CadFace, ReferenceCycleIsRefusedBeforeReading) {
  std::ifstream in(ROBOMACH_SOURCE_DIR "/tests/data/polishing/plate_hole.step");
  const std::string step((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto with = [&](const std::string& from, const std::string& to, const std::string& name) {
    std::string text = step;
    EXPECT_NE(text.find(from), std::string::npos) << from;
    text.replace(text.find(from), from.size(), to);
    const std::string path = TmpPath(name);
    std::ofstream(path) << text;
    return ErrorOf([&] { ReadCadFace(path, 0); });
  };
  EXPECT_THAT(with("#20 = ORIENTED_EDGE('',*,*,#21,.T.);", "#20 = ORIENTED_EDGE('',*,*,#20,.T.);", "self.step"),
              ::testing::HasSubstr("self.step:32: not a readable STEP file: instance #20 refers to itself"));
  const std::string e = with("#23 = CARTESIAN_POINT('',", "#23 = CARTESIAN_POINT(#20,", "loop.step");
  EXPECT_THAT(e, ::testing::HasSubstr("loop.step:"));
  EXPECT_THAT(e, ::testing::HasSubstr("refers to itself through its references"));
  EXPECT_NO_THROW(ReadCadFace(ROBOMACH_SOURCE_DIR "/tests/data/polishing/plate_hole.step", 0));
}

TEST(CadFace, CorruptAndEmptyFiles) {
  const std::string bad = TmpPath("corrupt.step");
  {
    std::ofstream out(bad);
    out << "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nDATA;\n#1 = B_SPLINE_SURFACE_WITH_KNOTS('',3,3,((#2,\n";
  }
  EXPECT_THAT(ErrorOf([&] { ReadCadFace(bad, 1); }), ::testing::HasSubstr("corrupt.step: "));
  const std::string text = TmpPath("notes.igs");
  {
    std::ofstream out(text);
    out << "this is not an IGES file\n";
  }
  EXPECT_THAT(ErrorOf([&] { ReadCadFace(text, 1); }), ::testing::HasSubstr("notes.igs: "));
}

}  // namespace
}  // namespace robomach::io
