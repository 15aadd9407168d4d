#include "robomach/io/cad_face.h"

#include <algorithm>
#include <vector>
#include <iterator>
#include <unordered_map>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <memory>
#include <sstream>

// LeakSanitizer's interface, where the build has it (GCC says so with
// __SANITIZE_ADDRESS__, clang before 17 only through __has_feature).
#if defined(__SANITIZE_ADDRESS__)
#define ROBOMACH_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(leak_sanitizer)
#define ROBOMACH_LSAN 1
#endif
#endif
#ifndef ROBOMACH_LSAN
#define ROBOMACH_LSAN 0
#endif
#if ROBOMACH_LSAN
#include <sanitizer/lsan_interface.h>
#endif

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <Bnd_Box.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepGProp.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <GCPnts_UniformAbscissa.hxx>
#include <GProp_GProps.hxx>
#include <Geom2d_Curve.hxx>
#include <GeomConvert.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_Surface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_GlobalSection.hxx>
#include <IGESData_IGESModel.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TCollection_HAsciiString.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_Static.hxx>
#include <XSControl_WorkSession.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <Precision.hxx>
#include <STEPControl_Controller.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Pnt2d.hxx>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/polishing/surface_grid.h"

namespace robomach::io {
namespace {

constexpr double kMmToM = 1e-3;
constexpr double kBoundaryChordMm = 0.25;  // boundary polyline chords (sag < 1 um on r >= 8 mm)
// On faces larger than 1 m the chords grow with the face (diagonal / 4000),
// so that the outline, the region's offsets and their round joins stay
// bounded in points: the 45 m faces of OCCT's hammer.iges read as mm had
// 150 000 points per edge at 0.25 mm, and the planner ran out of memory.
constexpr double kMaxChordsPerDiagonal = 4000.0;

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string Extension(const std::string& path) { return Lower(std::filesystem::path(path).extension().string()); }

bool IsIges(const std::string& path) {
  const std::string e = Extension(path);
  return e == ".iges" || e == ".igs";
}

// OpenCASCADE prints its reader's complaints on stdout by default, which
// would mix with a summary written to stdout: keep it quiet, we report.
std::string OcctWhat(const Standard_Failure& e) {
  const char* s = e.GetMessageString();
  return std::string(e.DynamicType()->Name()) + (s && *s ? std::string(": ") + s : std::string());
}

struct ReadResult {
  TopoDS_Shape shape;
  std::string unit;  // declared length unit of the file, "" if unknown
};

// A STEP file's instances reference each other without cycles. One that
// reaches itself through its references (an ORIENTED_EDGE that is its own
// edge element) sends OpenCASCADE into endless recursion already while it
// reads the file (its entity check calls StepShape_OrientedEdge::EdgeStart
// without end: a stack overflow; issue #22, found by fuzz_cad_face). So the
// DATA section is scanned first: each instance `#n = ...;` and the `#m`
// references in it (outside strings and comments), then an iterative
// depth-first search, O(instances + references). Returns the instance on a
// cycle and its line, or {0, 0}.
std::pair<long, int> FirstStepReferenceCycle(const std::string& text) {
  std::unordered_map<long, std::vector<long>> refs;
  std::unordered_map<long, int> line_of;
  const size_t data = text.find("DATA;");
  if (data == std::string::npos) return {0, 0};
  int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(data), '\n'));
  long current = 0;  // the instance being read, 0 between instances
  bool in_string = false, in_comment = false;
  auto number_at = [&](size_t& i) {
    long v = 0;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])) && v < 1000000000L) v = 10 * v + (text[i++] - '0');
    return v;
  };
  for (size_t i = data + 5; i < text.size();) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      // A line that starts an instance (`#n =`) starts one even after an
      // unbalanced quote or comment of a damaged file: resynchronise there,
      // as OpenCASCADE's reader does.
      size_t j = i + 1;
      while (j < text.size() && (text[j] == ' ' || text[j] == '\t' || text[j] == '\r')) ++j;
      if (j + 1 < text.size() && text[j] == '#' && std::isdigit(static_cast<unsigned char>(text[j + 1]))) {
        size_t k = j + 1;
        while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
        while (k < text.size() && (text[k] == ' ' || text[k] == '\t')) ++k;
        if (k < text.size() && text[k] == '=') {
          in_string = in_comment = false;
          current = 0;
          i = j;
          continue;
        }
      }
    }
    if (in_comment) {
      if (c == '*' && i + 1 < text.size() && text[i + 1] == '/') in_comment = false, ++i;
      ++i;
      continue;
    }
    if (in_string) {
      if (c == '\'') in_string = false;  // '' (an escaped quote) ends and reopens: same result
      ++i;
      continue;
    }
    if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      in_comment = true;
      i += 2;
      continue;
    }
    if (c == '\'') {
      in_string = true;
      ++i;
      continue;
    }
    if (c == '#') {
      ++i;
      const long id = number_at(i);
      if (current == 0) {
        current = id;
        line_of[id] = line;
        refs[id];
      } else {
        refs[current].push_back(id);
      }
      continue;
    }
    // To the end of the file, not to the first ENDSEC: OpenCASCADE's parser
    // reads instances after a stray one too.
    if (c == ';') current = 0;
    ++i;
  }
  std::unordered_map<long, char> state;  // absent unseen, 1 on the path, 2 done
  std::vector<std::pair<long, size_t>> path;
  for (const auto& [start, _] : refs) {
    if (state.count(start)) continue;
    state[start] = 1;
    path.emplace_back(start, 0);
    while (!path.empty()) {
      auto& [v, next] = path.back();
      const std::vector<long>& out = refs[v];
      if (next == out.size()) {
        state[v] = 2;
        path.pop_back();
        continue;
      }
      const long w = out[next++];
      if (!refs.count(w)) continue;  // a reference to no instance: OpenCASCADE's check reports it
      const auto st = state.find(w);
      if (st == state.end()) {
        state[w] = 1;
        path.emplace_back(w, 0);
      } else if (st->second == 1) {
        return {w, line_of[w]};
      }
    }
  }
  return {0, 0};
}

ReadResult ReadShape(const std::string& path) {
  SetUpOpenCascadeExchange();
  const bool iges = IsIges(path);
  const char* kind = iges ? "IGES" : "STEP";
  try {
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    IFSelect_ReturnStatus status;
    ReadResult out;
    if (iges) {
      IGESControl_Reader r;
      status = r.ReadFile(path.c_str());
      if (status == IFSelect_RetDone) {
        r.TransferRoots();
        out.shape = r.OneShape();
        if (!r.IGESModel().IsNull()) {
          const Handle(TCollection_HAsciiString) u = r.IGESModel()->GlobalSection().UnitName();
          if (!u.IsNull()) out.unit = u->ToCString();
        }
      }
    } else {
      {
        std::ifstream in(path, std::ios::binary);
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (const auto [id, line] = FirstStepReferenceCycle(text); id > 0) {
          throw InputError({path, line, 0}, "not a readable STEP file: instance #" + std::to_string(id) +
                                                " refers to itself through its references (a cycle; OpenCASCADE "
                                                "would recurse without end)");
        }
      }
      STEPControl_Reader r;
      status = r.ReadFile(path.c_str());
      if (status == IFSelect_RetDone) {
        // Entities that failed to load (a damaged record, a reference to a
        // missing entity) are refused before the translation: OpenCASCADE's
        // translator dereferences their null references (a SEGV in
        // StepToTopoDS_TranslateVertex; issue #22, found by fuzz_cad_face).
        const Interface_CheckIterator checks = r.WS()->ModelCheckList(false);
        if (!checks.IsEmpty(true)) {
          int failed = 0;
          std::string first;
          for (checks.Start(); checks.More(); checks.Next()) {
            const Handle(Interface_Check)& c = checks.Value();
            if (c.IsNull() || !c->HasFailed()) continue;
            if (failed++ == 0) {
              first = "entity " + std::to_string(checks.Number()) + " in file order";
              if (c->NbFails() > 0 && !c->Fail(1).IsNull()) first += ": " + std::string(c->Fail(1)->ToCString());
            }
          }
          throw InputError({path, 0, 0}, "not a readable STEP file: " + std::to_string(failed) +
                                             " damaged entit" + (failed == 1 ? "y" : "ies") + " (OpenCASCADE's check; first, " +
                                             first + ")");
        }
        r.TransferRoots();
        out.shape = r.OneShape();
        TColStd_SequenceOfAsciiString len, ang, solid;
        r.FileUnits(len, ang, solid);
        if (len.Length() > 0) out.unit = len.Value(1).ToCString();
      }
    }
    if (status != IFSelect_RetDone) {
      throw InputError({path, 0, 0}, std::string("not a readable ") + kind + " file (OpenCASCADE's " + kind +
                                         " reader failed: " + (status == IFSelect_RetVoid ? "no entities" : "syntax or structure error") + ")");
    }
    return out;
  } catch (const Standard_Failure& e) {
    throw InputError({path, 0, 0}, std::string("not a readable ") + kind + " file (OpenCASCADE: " + OcctWhat(e) + ")");
  }
}

TopTools_IndexedMapOfShape Faces(const TopoDS_Shape& shape) {
  TopTools_IndexedMapOfShape faces;
  if (!shape.IsNull()) TopExp::MapShapes(shape, TopAbs_FACE, faces);
  return faces;
}

double FaceArea(const TopoDS_Face& f) {
  GProp_GProps props;
  BRepGProp::SurfaceProperties(f, props);
  return props.Mass();
}

std::vector<double> FlatKnots(const TColStd_Array1OfReal& k) {
  std::vector<double> out;
  for (int i = k.Lower(); i <= k.Upper(); ++i) out.push_back(k(i));
  return out;
}

bool ClampedKnots(const Geom_BSplineSurface& bs) {
  const int p = bs.UDegree(), q = bs.VDegree();
  return bs.UMultiplicity(1) == p + 1 && bs.UMultiplicity(bs.NbUKnots()) == p + 1 &&
         bs.VMultiplicity(1) == q + 1 && bs.VMultiplicity(bs.NbVKnots()) == q + 1;
}

}  // namespace

bool IsCadFile(const std::string& path) {
  const std::string e = Extension(path);
  return e == ".step" || e == ".stp" || e == ".iges" || e == ".igs";
}

int CountCadFaces(const std::string& path) { return Faces(ReadShape(path).shape).Extent(); }

namespace {

std::string SizeText(const Eigen::Vector3d& s) {
  return FormatNumber(s.x(), 3) + " x " + FormatNumber(s.y(), 3) + " x " + FormatNumber(s.z(), 3) + " mm";
}

CadPartInfo PartInfo(const ReadResult& rr, int num_faces, const CadReadOptions& options) {
  CadPartInfo info;
  info.num_faces = num_faces;
  info.file_unit = rr.unit;
  info.unit_scale = options.unit_scale;
  Bnd_Box box;
  BRepBndLib::Add(rr.shape, box, Standard_False);  // without triangulation: the poles' box (may be a little loose)
  if (!box.IsVoid()) {
    double x0, y0, z0, x1, y1, z1;
    box.Get(x0, y0, z0, x1, y1, z1);
    info.bbox_size_mm = options.unit_scale * Eigen::Vector3d(x1 - x0, y1 - y0, z1 - z0);
  }
  const double big = info.bbox_size_mm.maxCoeff();
  const std::string says = rr.unit.empty() ? "the file's unit" : "the file says " + rr.unit;
  const std::string scaled = options.unit_scale != 1.0 ? " (after --cad-unit-scale " + FormatNumber(options.unit_scale, 3) + ")" : "";
  if (big > 0 && big < 1.0) {
    info.unit_warning = says + "; the part is " + SizeText(info.bbox_size_mm) + scaled + ", a part under 1 mm is probably "
                        "in metres (or inches); --cad-unit-scale 1000 (metres) or 25.4 (inches) to override";
  } else if (big > 1e4) {
    info.unit_warning = says + "; the part is " + SizeText(info.bbox_size_mm) + scaled + ", a part over 10 m is probably "
                        "in another unit (um, or 1/1000 of what it says); --cad-unit-scale 0.001 to override";
  }
  return info;
}

std::string SurfaceType(const TopoDS_Face& f) {
  switch (BRepAdaptor_Surface(f, Standard_False).GetType()) {
    case GeomAbs_Plane: return "plane";
    case GeomAbs_Cylinder: return "cylinder";
    case GeomAbs_Cone: return "cone";
    case GeomAbs_Sphere: return "sphere";
    case GeomAbs_Torus: return "torus";
    case GeomAbs_BezierSurface: return "bezier";
    case GeomAbs_BSplineSurface: return "bspline";
    case GeomAbs_SurfaceOfRevolution: return "revolution";
    case GeomAbs_SurfaceOfExtrusion: return "extrusion";
    case GeomAbs_OffsetSurface: return "offset";
    default: return "other";
  }
}

// Face `index` (1-based) of `faces` as a trimmed NURBS patch in metres.
polishing::NurbsSurface ConvertFace(const std::string& path, const TopTools_IndexedMapOfShape& faces, int index,
                                    double unit_scale) {
  const std::string where = std::filesystem::path(path).filename().string() + ", face ";
  const double to_m = kMmToM * unit_scale;  // file lengths (as OpenCASCADE gives them, mm) to metres
  try {
    const TopoDS_Face original = TopoDS::Face(faces(index));
    const std::string source = where + std::to_string(index);
    auto fail = [&](const std::string& m) { return InputError({path, 0, 0}, "face " + std::to_string(index) + ": " + m); };

    // Exact NURBS of the underlying surface (and of the pcurves), in the
    // parametrisation the trimming wires refer to.
    BRepBuilderAPI_NurbsConvert convert(original, Standard_True);
    if (!convert.IsDone()) throw fail("OpenCASCADE cannot convert its surface to NURBS");
    TopoDS_Face nf = TopoDS::Face(convert.Shape());
    const Handle(Geom_Surface) gs = BRep_Tool::Surface(nf);
    if (gs.IsNull()) throw fail("the face has no surface");
    Handle(Geom_BSplineSurface) bs = Handle(Geom_BSplineSurface)::DownCast(gs);
    if (bs.IsNull()) bs = GeomConvert::SurfaceToBSplineSurface(gs);
    if (bs.IsNull()) throw fail("OpenCASCADE cannot convert its surface to NURBS");
    bs = Handle(Geom_BSplineSurface)::DownCast(bs->Copy());
    // A periodic patch as a clamped one, cut to the face's parameter box
    // (Segment keeps the parametrisation and clamps the ends, so the
    // trimming pcurves still apply).
    if (bs->IsUPeriodic()) bs->SetUNotPeriodic();
    if (bs->IsVPeriodic()) bs->SetVNotPeriodic();
    {
      double u0, u1, v0, v1, su0, su1, sv0, sv1;
      BRepTools::UVBounds(nf, u0, u1, v0, v1);
      bs->Bounds(su0, su1, sv0, sv1);
      u0 = std::max(u0, su0), u1 = std::min(u1, su1), v0 = std::max(v0, sv0), v1 = std::min(v1, sv1);
      if (u1 - u0 > Precision::PConfusion() && v1 - v0 > Precision::PConfusion() &&
          (u0 > su0 || u1 < su1 || v0 > sv0 || v1 < sv1 || !ClampedKnots(*bs))) {
        bs->Segment(u0, u1, v0, v1);
      }
    }

    const bool reversed = nf.Orientation() == TopAbs_REVERSED;
    const int nu = bs->NbUPoles(), nv = bs->NbVPoles();
    std::vector<double> ku = FlatKnots(bs->UKnotSequence()), kv = FlatKnots(bs->VKnotSequence());
    std::vector<std::vector<Eigen::Vector3d>> P(nu, std::vector<Eigen::Vector3d>(nv));
    std::vector<std::vector<double>> W(nu, std::vector<double>(nv, 1.0));
    for (int i = 1; i <= nu; ++i)
      for (int j = 1; j <= nv; ++j) {
        const gp_Pnt p = bs->Pole(i, j);
        const int ii = reversed ? nu - i : i - 1;
        P[ii][j - 1] = to_m * Eigen::Vector3d(p.X(), p.Y(), p.Z());
        W[ii][j - 1] = bs->Weight(i, j);
      }
    // Reversed face: u' = u_lo + u_hi - u keeps the knot range and makes
    // S_u' x S_v the face's outward normal.
    const double u_sum = ku.front() + ku.back();
    if (reversed) {
      std::reverse(ku.begin(), ku.end());
      for (double& k : ku) k = u_sum - k;
    }
    polishing::NurbsSurface patch = [&] {
      try {
        return polishing::NurbsSurface::Create(bs->UDegree(), bs->VDegree(), ku, kv, P, W);
      } catch (const std::invalid_argument& e) {
        throw fail(std::string("its NURBS is not usable: ") + e.what());
      }
    }();

    auto trim = std::make_shared<polishing::FaceTrim>();
    trim->source = source;
    trim->area = FaceArea(original) * to_m * to_m;
    auto classifier = std::make_shared<BRepTopAdaptor_FClass2d>(nf, Precision::PConfusion());
    trim->contains = [classifier, reversed, u_sum](double u, double v) {
      const TopAbs_State s = classifier->Perform(gp_Pnt2d(reversed ? u_sum - u : u, v), Standard_False);
      return s == TopAbs_IN || s == TopAbs_ON;
    };
    for (TopExp_Explorer w(nf, TopAbs_WIRE); w.More(); w.Next()) ++trim->num_wires;
    // Chords of 0.25 mm, longer on faces over 1 m (bounded point count).
    double chord_mm = kBoundaryChordMm;
    {
      Bnd_Box fb;
      BRepBndLib::Add(original, fb, Standard_False);
      if (!fb.IsVoid()) chord_mm = std::max(chord_mm, unit_scale * std::sqrt(fb.SquareExtent()) / kMaxChordsPerDiagonal);
    }
    const double chord_file = chord_mm / unit_scale;  // in the lengths OpenCASCADE gives
    trim->boundary_chord = kMmToM * chord_mm;
    for (TopExp_Explorer e(nf, TopAbs_EDGE); e.More(); e.Next()) {
      const TopoDS_Edge edge = TopoDS::Edge(e.Current());
      // A degenerate edge (a pole) and the seam of a closed surface are not
      // boundaries of the material.
      if (BRep_Tool::Degenerated(edge) || BRep_Tool::IsClosed(edge, nf)) continue;
      BRepAdaptor_Curve c(edge);
      std::vector<Eigen::Vector3d> line;
      GCPnts_UniformAbscissa ua(c, chord_file);
      if (ua.IsDone() && ua.NbPoints() >= 2) {
        for (int k = 1; k <= ua.NbPoints(); ++k) {
          const gp_Pnt p = c.Value(ua.Parameter(k));
          line.push_back(to_m * Eigen::Vector3d(p.X(), p.Y(), p.Z()));
        }
      }
      const gp_Pnt a = c.Value(c.FirstParameter()), b = c.Value(c.LastParameter());
      const Eigen::Vector3d pa = to_m * Eigen::Vector3d(a.X(), a.Y(), a.Z());
      const Eigen::Vector3d pb = to_m * Eigen::Vector3d(b.X(), b.Y(), b.Z());
      if (line.empty()) line = {pa, pb};
      if ((line.front() - pa).norm() > 1e-9) line.insert(line.begin(), pa);
      if ((line.back() - pb).norm() > 1e-9) line.push_back(pb);
      trim->boundary.push_back(std::move(line));
    }
    // The wires in the parameter plane, edge by edge in the wire's order and
    // sense, through the pcurves (sampled at the 3-D chord spacing).
    for (TopExp_Explorer w(nf, TopAbs_WIRE); w.More(); w.Next()) {
      std::vector<Eigen::Vector2d> loop;
      for (BRepTools_WireExplorer we(TopoDS::Wire(w.Current()), nf); we.More(); we.Next()) {
        const TopoDS_Edge& edge = we.Current();
        double f = 0.0, l = 0.0;
        const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(edge, nf, f, l);
        if (pc.IsNull()) throw fail("an edge of the face has no curve in the surface's parameter plane");
        std::vector<double> params;
        if (!BRep_Tool::Degenerated(edge)) {
          BRepAdaptor_Curve c(edge);
          GCPnts_UniformAbscissa ua(c, chord_file);
          if (ua.IsDone()) {
            for (int k = 1; k <= ua.NbPoints(); ++k) params.push_back(ua.Parameter(k));
          }
        }
        if (params.size() < 2) params = {f, 0.5 * (f + l), l};
        params.front() = f;
        params.back() = l;
        if (edge.Orientation() == TopAbs_REVERSED) std::reverse(params.begin(), params.end());
        std::vector<Eigen::Vector2d> line;
        for (size_t k = 0; k < params.size(); ++k) {
          const gp_Pnt2d q = pc->Value(params[k]);
          line.emplace_back(reversed ? u_sum - q.X() : q.X(), q.Y());
        }
        loop.insert(loop.end(), line.begin(), line.end() - 1);  // the edge's end is the next edge's start
        if (!BRep_Tool::Degenerated(edge) && !BRep_Tool::IsClosed(edge, nf)) trim->edges_uv.push_back(std::move(line));
      }
      if (loop.size() >= 3) trim->wires_uv.push_back(std::move(loop));
    }
    return patch.WithTrim(std::move(trim));
  } catch (const Standard_Failure& e) {
    throw InputError({path, 0, 0}, "face " + std::to_string(index) + ": OpenCASCADE failed: " + OcctWhat(e));
  }
}

// True if a point of the face's outer wire lies inside its patch's
// parameter box (by more than 1e-6 of the box): the wires cut the patch.
bool TrimmedInside(const polishing::NurbsSurface& s) {
  if (!s.trim()) return false;
  const double tu = 1e-6 * (s.u_max() - s.u_min()), tv = 1e-6 * (s.v_max() - s.v_min());
  for (const auto& wire : s.trim()->wires_uv)
    for (const Eigen::Vector2d& p : wire) {
      const bool on_u = std::abs(p.x() - s.u_min()) <= tu || std::abs(p.x() - s.u_max()) <= tu;
      const bool on_v = std::abs(p.y() - s.v_min()) <= tv || std::abs(p.y() - s.v_max()) <= tv;
      if (!on_u && !on_v) return true;
    }
  return false;
}

int LargestFace(const TopTools_IndexedMapOfShape& faces) {
  int index = 1;
  double best = -1.0;
  for (int i = 1; i <= faces.Extent(); ++i) {
    const double a = FaceArea(TopoDS::Face(faces(i)));
    if (a > best) best = a, index = i;
  }
  return index;
}

// CadReadOptions::Validate, worded as the polishing tools have always said
// it (their option, the file).
void CheckScale(const std::string& path, const CadReadOptions& options) {
  try {
    options.Validate();
  } catch (const OptionError&) {
    throw std::invalid_argument("--cad-unit-scale: expected a number > 0, got " + FormatNumber(options.unit_scale, 3) +
                                " (for " + path + ")");
  }
}

}  // namespace

void CadReadOptions::Validate() const {
  if (unit_scale > 0.0 && std::isfinite(unit_scale)) return;
  std::ostringstream s;
  s << "unit_scale: expected a finite value > 0, got " << unit_scale;
  throw OptionError("unit_scale", s.str());
}

polishing::NurbsSurface ReadCadFace(const std::string& path, int face, const CadReadOptions& options, CadPartInfo* info) {
  CheckScale(path, options);
  const ReadResult rr = ReadShape(path);
  const TopTools_IndexedMapOfShape faces = Faces(rr.shape);
  const int n = faces.Extent();
  if (n == 0) throw InputError({path, 0, 0}, "the file holds no faces (no surface to polish)");
  const std::string kind = IsIges(path) ? "IGES" : "STEP";
  if (face < 0 || face > n) {
    throw InputError({path, 0, 0}, "--face " + std::to_string(face) + ": the " + kind + " file has " +
                                       std::to_string(n) + " face" + (n == 1 ? "" : "s") + " (1.." +
                                       std::to_string(n) + ")");
  }
  if (info) *info = PartInfo(rr, n, options);
  int index = face;
  if (index == 0) {  // formats.md §5: by default the largest by area
    try {
      index = LargestFace(faces);
    } catch (const Standard_Failure& e) {
      throw InputError({path, 0, 0}, "finding the largest face: OpenCASCADE failed: " + OcctWhat(e));
    }
  }
  return ConvertFace(path, faces, index, options.unit_scale);
}

std::vector<CadFaceRow> ListCadFaces(const std::string& path, const FaceCheck& check, const CadReadOptions& options,
                                     CadPartInfo* info, const std::function<void(int, int)>& progress) {
  CheckScale(path, options);
  const ReadResult rr = ReadShape(path);
  const TopTools_IndexedMapOfShape faces = Faces(rr.shape);
  const int n = faces.Extent();
  if (n == 0) throw InputError({path, 0, 0}, "the file holds no faces (no surface to polish)");
  if (info) *info = PartInfo(rr, n, options);
  std::vector<CadFaceRow> rows;
  for (int i = 1; i <= n; ++i) {
    CadFaceRow row;
    row.face = i;
    const TopoDS_Face f = TopoDS::Face(faces(i));
    try {
      row.surface_type = SurfaceType(f);
      row.area_mm2 = FaceArea(f) * options.unit_scale * options.unit_scale;
      int wires = 0;
      for (TopExp_Explorer w(f, TopAbs_WIRE); w.More(); w.Next()) ++wires;
      row.holes = std::max(0, wires - 1);
    } catch (const Standard_Failure& e) {
      row.reason = "OpenCASCADE failed: " + OcctWhat(e);
      rows.push_back(row);
      if (progress) progress(i, n);
      continue;
    }
    try {
      const polishing::NurbsSurface s = ConvertFace(path, faces, i, options.unit_scale);
      const polishing::SurfaceSize size = polishing::MeasureSurface(s);
      row.u_size_mm = 1e3 * size.length_u;
      row.v_size_mm = 1e3 * size.length_v;
      row.trimmed = row.holes > 0 || TrimmedInside(s);
      if (check) {
        const auto [ok, reason] = check(s);
        row.polishable = ok;
        row.reason = reason;
      } else {
        row.polishable = true;
      }
    } catch (const InputError& e) {
      row.reason = e.what();
    } catch (const std::invalid_argument& e) {  // the surface's measures: a degenerate or non-finite face
      row.reason = e.what();
    } catch (const std::domain_error& e) {
      row.reason = e.what();
    } catch (const NumericalError& e) {
      row.reason = e.what();
    } catch (const Standard_Failure& e) {
      row.reason = std::string("OpenCASCADE: ") + e.GetMessageString();
    }
    // Anything else (a bug, memory) propagates: it says nothing about the face.
    rows.push_back(row);
    if (progress) progress(i, n);
  }
  return rows;
}

void WriteStepFace(const polishing::NurbsSurface& s, const std::string& path, const std::string& comment) {
  SetUpOpenCascadeExchange();
  const int nu = s.num_u(), nv = s.num_v();
  TColgp_Array2OfPnt poles(1, nu, 1, nv);
  TColStd_Array2OfReal weights(1, nu, 1, nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Eigen::Vector3d p = s.control_point(i, j) / kMmToM;
      poles(i + 1, j + 1) = gp_Pnt(p.x(), p.y(), p.z());
      weights(i + 1, j + 1) = s.weight(i, j);
    }
  auto compress = [](const std::vector<double>& flat, std::vector<double>* k, std::vector<int>* m) {
    for (double x : flat) {
      if (!k->empty() && x == k->back()) ++m->back();
      else k->push_back(x), m->push_back(1);
    }
  };
  std::vector<double> ku, kv;
  std::vector<int> mu, mv;
  compress(s.knots_u(), &ku, &mu);
  compress(s.knots_v(), &kv, &mv);
  TColStd_Array1OfReal aku(1, static_cast<int>(ku.size())), akv(1, static_cast<int>(kv.size()));
  TColStd_Array1OfInteger amu(1, static_cast<int>(mu.size())), amv(1, static_cast<int>(mv.size()));
  for (size_t i = 0; i < ku.size(); ++i) aku(static_cast<int>(i) + 1) = ku[i], amu(static_cast<int>(i) + 1) = mu[i];
  for (size_t i = 0; i < kv.size(); ++i) akv(static_cast<int>(i) + 1) = kv[i], amv(static_cast<int>(i) + 1) = mv[i];
  const std::string tmp = path + ".tmp";
  try {
    Handle(Geom_BSplineSurface) bs =
        new Geom_BSplineSurface(poles, weights, aku, akv, amu, amv, s.degree_u(), s.degree_v());
    BRepBuilderAPI_MakeFace mk(bs, Precision::Confusion());
    if (!mk.IsDone()) throw OutputError(path + ": OpenCASCADE cannot make a face of the patch");
    Interface_Static::SetCVal("write.step.unit", "MM");
    STEPControl_Writer w;
    if (w.Transfer(mk.Face(), STEPControl_AsIs) != IFSelect_RetDone || w.Write(tmp.c_str()) != IFSelect_RetDone) {
      std::remove(tmp.c_str());
      throw OutputError(path + ": OpenCASCADE's STEP writer failed");
    }
  } catch (const Standard_Failure& e) {
    std::remove(tmp.c_str());
    throw OutputError(path + ": OpenCASCADE failed: " + OcctWhat(e));
  }
  // The comment after the first line (ISO 10303-21 allows /* */ comments).
  std::ifstream in(tmp);
  std::stringstream body;
  body << in.rdbuf();
  in.close();
  std::string text = body.str();
  const size_t eol = text.find('\n');
  std::string c = comment;
  for (size_t k; (k = c.find("*/")) != std::string::npos;) c.replace(k, 2, "* /");
  if (eol != std::string::npos && !c.empty()) text.insert(eol + 1, "/*\n" + c + (c.back() == '\n' ? "" : "\n") + "*/\n");
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    if (!out) {
      std::remove(tmp.c_str());
      throw OutputError(path + ": cannot write " + tmp);
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw OutputError(path + ": cannot rename " + tmp + " into place: " + ec.message());
  }
}

// The controllers' set-up keeps about 3 KB that no pointer LeakSanitizer
// can see still refers to (the same for one read or a thousand; every stack
// of it goes through STEPControl_Controller::Init, seen with
// fast_unwind_on_malloc=0). Under LeakSanitizer it runs with the leak check
// off, so that a leak check (scripts/check-sanitizers.sh, tests/fuzz)
// reports robomach's leaks only.
void SetUpOpenCascadeExchange() {
  static const bool done = [] {
    const Handle(Message_Messenger)& m = Message::DefaultMessenger();
    m->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
#if ROBOMACH_LSAN
    __lsan_disable();
#endif
    STEPControl_Controller::Init();
    IGESControl_Controller::Init();
#if ROBOMACH_LSAN
    __lsan_enable();
#endif
    return true;
  }();
  (void)done;
}


std::string CadFaceListCsv(const std::vector<CadFaceRow>& rows) {
  auto short6 = [](double x) {
    std::ostringstream o;
    o.precision(6);
    o << x;
    return o.str();
  };
  auto field = [](const std::string& x) {
    if (x.find_first_of(",\"\n") == std::string::npos) return x;
    std::string q = "\"";
    for (char c : x) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
    return q + "\"";
  };
  std::ostringstream csv;
  csv << "face,surface_type,area_mm2,u_size_mm,v_size_mm,trimmed,holes,polishable,reason\n";
  for (const auto& r : rows) {
    csv << r.face << ',' << r.surface_type << ',' << short6(r.area_mm2) << ',' << short6(r.u_size_mm) << ','
        << short6(r.v_size_mm) << ',' << (r.trimmed ? 1 : 0) << ',' << r.holes << ',' << (r.polishable ? 1 : 0) << ','
        << field(r.reason) << '\n';
  }
  return csv.str();
}

}  // namespace robomach::io
