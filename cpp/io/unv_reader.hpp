// Reads an I-DEAS universal file (.unv, ASCII) as FreeCAD FEM (SMESH), Salome and Gmsh write
// it: dataset 2411 (nodes, double precision) and 2412 (elements); other datasets (units 164,
// coordinate systems 2420, groups 2467/2477, results) are skipped.
//
// Elements by FE descriptor: rods and beams (11, 21 to 24; their records carry an extra line
// of orientation node and cross sections) of 2 or 3 nodes, triangles (41, 51, 61, 74, 81, 91
// linear; 42, 52, 62, 72, 82, 92 parabolic), linear quadrilaterals (44, 54, 64, 71, 84, 94),
// tetrahedra (111 linear, 118 parabolic), linear wedges (112) and bricks (115); lumped masses
// (161) are skipped. Parabolic cells list their nodes around the element, corner, mid-edge,
// corner, ...: the triangle c0 m01 c1 m12 c2 m20, the tetrahedron its face c0 c1 c2 so, then
// m03 m13 m23 and c3 (the mid-edge positions FreeCAD's files show). They are put in Gmsh's order
// here. Serendipity (8-node quadrilaterals, 15-node wedges, 20-node bricks) and cubic cells are
// refused by element: the core holds complete Lagrange elements only.
//
// Every error is an IoError naming the file, the line and, where there is one, the node or
// element label.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

// `notes` (if given) receives what the reading changed (see assembleForeignMesh).
Mesh readUnv(const std::string& path, std::vector<std::string>* notes = nullptr);

}  // namespace homesh
