// Cusps of the CAD faces: corners where two edges of a face leave a vertex in the same
// direction, with the face between them (a zero angle; a plane cutting a quarter cylinder
// meets the cylinder's straight edge tangentially, as in FreeCAD's I22 inductor models).
//
// Why it matters: a mesh that follows the CAD puts the two curved element edges at that vertex
// along the two CAD edges, so they are tangent there and the element's Jacobian is zero at the
// vertex whatever its other nodes do; such an element can never be proven valid. Knowing the
// cusp lets a message say that the CAD, not the mesher, stands in the way.
#pragma once

#include <vector>

#include "cad/cad_model.hpp"

namespace homesh {

struct FaceCusp {
  int face = 0, vertex = 0;  // 1-based, FreeCAD's numbering
  int edgeA = 0, edgeB = 0;  // the two edges of the face that meet there, edgeA < edgeB
  double angleDeg = 0.0;     // between their directions leaving the vertex
};

// The cusps of every face: corners whose two edges leave the vertex at most `maxAngleDeg`
// apart and whose face lies between them near the vertex (the midpoint of two points one
// twentieth of the shorter edge along each lies on the face; a slit, where the face lies all
// around, is no cusp). Degenerated edges and an edge meeting itself (a seam) are skipped.
std::vector<FaceCusp> findFaceCusps(const CadModel& cad, double maxAngleDeg = 1.0);

}  // namespace homesh
