#pragma once

// One face of a STEP (.step, .stp) or IGES (.iges, .igs) file as a polishing
// surface (formats.md §5), read with OpenCASCADE: the face's underlying
// surface converted to an exact NURBS patch (BRepBuilderAPI_NurbsConvert; a
// B-spline face is kept as it is) in metres, with the face's trimming wires
// (outer boundary and holes) as its FaceTrim.

#include <functional>
#include <string>
#include <vector>

#include "robomach/polishing/nurbs_surface.h"

namespace robomach::io {

/// True for the extensions ReadCadFace reads (case-insensitive).
bool IsCadFile(const std::string& path);

struct CadReadOptions {
  /// Multiplies every length as read (after OpenCASCADE's conversion of the
  /// file's unit to mm): 1000 for a file that says mm but holds metres.
  double unit_scale{1.0};

  /// @throws OptionError naming the field, its value and the bound:
  /// unit_scale finite > 0 (a length scale).
  void Validate() const;
};

/// What the reader saw of the whole file (for the units plausibility check).
struct CadPartInfo {
  int num_faces{0};
  Eigen::Vector3d bbox_size_mm{0, 0, 0};  // bounding box of all faces, after unit_scale [mm]
  std::string file_unit;                  // the unit the file declares ("MM", "M", "INCH"...), "" if unknown
  double unit_scale{1.0};
  /// Non-empty when the part's largest bounding-box side is under 1 mm or
  /// over 10 m: "the file says MM; a part of 0.12 mm is probably in metres;
  /// --cad-unit-scale to override".
  std::string unit_warning;
};

/// Face `face` of the file: 1-based, in the order OpenCASCADE's explorer
/// visits the unique faces of the shape read from the file (for a STEP file
/// the order of the ADVANCED_FACEs in its shells); 0 picks the largest face
/// by area. Lengths are converted to mm by the reader and then to metres.
/// A face whose orientation is REVERSED in the file gets its u direction
/// reversed, so that S_u x S_v is the face's outward (material) normal.
/// @throws InputError naming the file (and face): unreadable or corrupt
/// file, no faces, face number out of range, a surface that cannot be
/// converted to NURBS.
/// The boundary polylines are sampled with chords of 0.25 mm, or of 1/4000
/// of the face's bounding-box diagonal on faces over 1 m (at most ~4000
/// points per wire length of one diagonal), so that large faces stay bounded.
/// `info`, if given, receives the file's unit and the part's size.
polishing::NurbsSurface ReadCadFace(const std::string& path, int face, const CadReadOptions& options = {},
                                    CadPartInfo* info = nullptr);

/// Number of faces in the file (numbering as above).
int CountCadFaces(const std::string& path);

/// One row of `polish-plan --list-faces`.
struct CadFaceRow {
  int face{0};                 // 1-based, as ReadCadFace numbers them
  std::string surface_type;    // bspline, plane, cylinder, cone, sphere, torus, revolution, extrusion, offset, other
  double area_mm2{0.0};        // area of the trimmed face
  double u_size_mm{0.0};       // mean arc length of the face's patch along u (ReadCadFace's patch)
  double v_size_mm{0.0};
  bool trimmed{false};         // the face's wires are not just its patch's boundary
  int holes{0};                // inner wires
  bool polishable{false};
  std::string reason;          // why not (or a note), "" when polishable without remark
};

/// Checks one face converted as ReadCadFace does; returns {polishable, reason}.
using FaceCheck = std::function<std::pair<bool, std::string>(const polishing::NurbsSurface&)>;

/// All faces of the file, one row each, the file read once. `check` (may be
/// empty: every face polishable) decides polishability; a face that cannot
/// be converted is listed as not polishable with the reason.
/// @throws InputError for an unreadable file or one with no faces.
/// `progress(done, total)` is called after each face.
std::vector<CadFaceRow> ListCadFaces(const std::string& path, const FaceCheck& check,
                                     const CadReadOptions& options = {}, CadPartInfo* info = nullptr,
                                     const std::function<void(int, int)>& progress = {});

/// polish-plan --list-faces' CSV (docs/formats.md §5): `face,surface_type,
/// area_mm2,u_size_mm,v_size_mm,trimmed,holes,polishable,reason`, sizes to 6
/// significant digits, the reason quoted where it needs it.
std::string CadFaceListCsv(const std::vector<CadFaceRow>& rows);

/// Writes `surface` (its untrimmed patch, lengths in mm) as a STEP AP214 file
/// with one B-spline face; `comment` (lines) goes into a comment after the
/// header line. Written to a temporary file and renamed into place.
/// @throws OutputError if the file cannot be written.
void WriteStepFace(const polishing::NurbsSurface& surface, const std::string& path, const std::string& comment);

/// Sets up OpenCASCADE's data exchange once per process, as every function
/// here does first: its messages off stdout, its STEP and IGES controllers
/// initialised (under LeakSanitizer with the leak check off: OpenCASCADE
/// keeps ~3 KB of that set-up where no pointer refers to it). For code that
/// uses OpenCASCADE's STEP/IGES classes before calling these (tests).
void SetUpOpenCascadeExchange();

}  // namespace robomach::io
