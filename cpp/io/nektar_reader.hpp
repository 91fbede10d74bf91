// Reader of Nektar++ XML geometry files, plain or compressed (B64Z-LittleEndian), as HOMesh and
// NekMesh write them: tetrahedra, prisms, hexahedra (3D) or triangles, quadrilaterals (2D).
//
// Elements get their vertices the way Nektar++ derives them from the faces and edges, then
// become Gmsh-ordered elements of the order the curves carry (order 1 without curves). Edge
// and face nodes come from the curves (or lie straight); the nodes the format does not store
// (element interiors) are rebuilt as Nektar++ builds them: for triangles, tetrahedra and prisms
// its modified basis with the interior modes zero (nektar_expansion.hpp), for quadrilaterals and
// hexahedra the transfinite blend of the boundary. Composites named "SolidN", "FaceN" or "EdgeN"
// give the elements' and boundary cells' entities; nodes take the entity of the cells they lie on.
#pragma once

#include <string>

#include "core/mesh.hpp"

namespace homesh {

// Throws IoError naming the file and the problem.
Mesh readNektarXml(const std::string& path);

}  // namespace homesh
