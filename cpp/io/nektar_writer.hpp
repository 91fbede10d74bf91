// Nektar++ XML geometry (the format NekMesh writes, Nektar++ 5.x).
//
// VERTEX, EDGE, FACE (3D), ELEMENT (tetrahedra A, prisms R, hexahedra H; 2D triangles T and
// quadrilaterals Q), CURVED (at order 2 and above every edge with its PolyEvenlySpaced points,
// every face and 2D element with NodalTriEvenlySpaced or tensor points, as NekMesh does), COMPOSITE
// (one per element type and CAD solid or face, named "SolidN" / "FaceN", and one per boundary group
// "FaceN" / "EdgeN"), DOMAIN and a default EXPANSIONS block. Entities are oriented the way Nektar++
// requires (tetrahedra by vertex id with positive volume, triangle faces by ascending vertex id,
// prisms with their highest vertex pair at the apex). Compressed: every section as zlib + base64
// ("B64Z-LittleEndian") binary records. Element-interior nodes of 3D elements are not part of
// the format: Nektar++ builds the element from its faces.
#pragma once

#include <string>
#include <vector>

#include "io/mesh_writers.hpp"

#include "core/mesh.hpp"

namespace homesh {

// Throws ParameterError for element types Nektar++ has no counterpart for (and for pyramids
// above order 2, checkNektarPyramids), IoError on write.
// `groups` (checked by checkGroups): one boundary composite per group, named after it, holding
// the faces (2D: edges) of all its entities, in place of their own "FaceN" composites.
void checkNektarPyramids(const Mesh& mesh);
void writeNektarXml(const Mesh& mesh, const std::string& path, bool compressed,
                    const std::vector<NamedGroup>& groups = {});

}  // namespace homesh
