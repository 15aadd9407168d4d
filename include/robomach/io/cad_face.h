#pragma once

// One face of a STEP (.step, .stp) or IGES (.iges, .igs) file as a polishing
// surface (formats.md §5), read with OpenCASCADE: the face's underlying
// surface converted to an exact NURBS patch (BRepBuilderAPI_NurbsConvert; a
// B-spline face is kept as it is) in metres, with the face's trimming wires
// (outer boundary and holes) as its FaceTrim.

#include <string>

#include "robomach/polishing/nurbs_surface.h"

namespace robomach::io {

/// True for the extensions ReadCadFace reads (case-insensitive).
bool IsCadFile(const std::string& path);

/// Face `face` of the file: 1-based, in the order OpenCASCADE's explorer
/// visits the unique faces of the shape read from the file (for a STEP file
/// the order of the ADVANCED_FACEs in its shells); 0 picks the largest face
/// by area. Lengths are converted to mm by the reader and then to metres.
/// A face whose orientation is REVERSED in the file gets its u direction
/// reversed, so that S_u x S_v is the face's outward (material) normal.
/// @throws InputError naming the file (and face): unreadable or corrupt
/// file, no faces, face number out of range, a surface that cannot be
/// converted to NURBS.
polishing::NurbsSurface ReadCadFace(const std::string& path, int face);

/// Number of faces in the file (numbering as above).
int CountCadFaces(const std::string& path);

/// Writes `surface` (its untrimmed patch, lengths in mm) as a STEP AP214 file
/// with one B-spline face; `comment` (lines) goes into a comment after the
/// header line. Written to a temporary file and renamed into place.
/// @throws OutputError if the file cannot be written.
void WriteStepFace(const polishing::NurbsSurface& surface, const std::string& path, const std::string& comment);

}  // namespace robomach::io
