// Reader of Gmsh MSH files: versions 2.2 and 4.1, ASCII and binary.
//
// Reads every complete Lagrange element HOMesh knows (lines, triangles, quadrilaterals,
// tetrahedra, prisms, hexahedra, orders 1 to 10; Gmsh's node order is ours) and skips points.
// The mesh's dimension is the highest element dimension; lower-dimensional elements become the
// boundary blocks. Node classification comes from the file: MSH 4.1 node blocks give each node's
// entity (dimension, tag); for MSH 2.2 a node takes the dimension and elementary tag of the
// lowest-dimensional element holding it. nodeCadIndex then holds Gmsh entity tags, not FreeCAD
// numbers, and there are no parameters. 2D meshes get the plane normal their elements agree on.
#pragma once

#include <string>

#include "core/mesh.hpp"

namespace homesh {

// Throws IoError naming the file, the section and what is wrong.
Mesh readMsh(const std::string& path);

}  // namespace homesh
