// Carries the curved boundary's displacement into the high-order nodes inside the domain.
//
// Elevation (order_elevation.hpp) leaves every node inside the domain at its straight-sided
// position: next to a curved face the element then bends within its outer layer of nodes
// only, which at order 4 and above costs much of its quality and the optimiser's first sweeps
// to undo. Here each tetrahedron's nodes inside the domain move by the lowest-order extension
// of its boundary's displacement D = x - x_straight, in barycentric coordinates l:
//   E(l)   = sum over edges ij of (l_i + l_j)^2 d_ij(l_j / (l_i + l_j))
//   F_f(l) = (1 - l_o)^3 r_f(l_f / (1 - l_o))     (face f, o the vertex opposite it)
// where d_ij interpolates D along edge ij and r_f interpolates, over face f, what D adds to E
// there. Both are exact for a quadratic element: a tetrahedron whose edges curve as parabolas
// (and whose faces follow them) gets exactly the quadratic element's map at every order.
// A face inside the domain takes E from its own edges (so both its tetrahedra agree), then the
// nodes inside each tetrahedron E plus the F_f of its faces. Edges inside the domain stay
// straight (their ends do not move). Nodes on the CAD, and the nodes of every other cell
// (prisms, pyramids, hexahedra: a boundary layer keeps the shape its blend gave it), stay.
#pragma once

#include <cstddef>

#include "core/mesh.hpp"

namespace homesh {

// For a 3D mesh of order 3 or more (others are left as they are): moves the nodes inside the
// domain (nodeCadDim 3) of its tetrahedra as above, and returns how many it moved.
std::size_t blendInteriorNodes(Mesh& mesh);

}  // namespace homesh
