#pragma once

// The trimmed region of a CAD face (formats.md §5): the part of a NURBS
// patch's parameter rectangle inside the face's trimming wires (outer wire
// and holes). Built by io/cad_face from a STEP or IGES face; the polishing
// module only asks "is (u, v) on the face?" and "where is the boundary?", so
// it does not depend on the CAD kernel.

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace robomach::polishing {

struct FaceTrim {
  /// True if the parameter point (u, v) of the patch lies on the face
  /// (inside the outer wire and outside every hole; the boundary counts as on).
  std::function<bool(double u, double v)> contains;
  /// The face's boundary edges (all wires) as 3-D polylines [m], chords at
  /// most `boundary_chord` long and within `boundary_sag` of the edge curve.
  std::vector<std::vector<Eigen::Vector3d>> boundary;
  double boundary_chord{0.0};  // [m]
  /// The trimming wires in the patch's parameter plane (u, v): one closed
  /// polygon per wire (the last point is not repeated), the outer wire and
  /// the holes, each edge sampled as its 3-D polyline above. Seams and
  /// degenerate edges of closed surfaces are included here: this is the
  /// boundary of the face's parameter domain.
  std::vector<std::vector<Eigen::Vector2d>> wires_uv;
  /// The material edges of those wires as open polylines in (u, v): every
  /// edge but seams and degenerate edges. The margin is measured from these
  /// only (as for the 3-D `boundary`); empty: from the whole wires.
  std::vector<std::vector<Eigen::Vector2d>> edges_uv;
  double area{0.0};            // area of the face [m^2] (from the CAD kernel)
  int num_wires{0};            // 1 + number of holes
  std::string source;          // "file.step, face 3" for messages
};

}  // namespace robomach::polishing
