// Node orderings of complete Lagrange elements (line, triangle, quadrilateral, tetrahedron,
// prism, hexahedron in Gmsh's, VTK's and CGNS's conventions; pyramid in Gmsh's and CGNS's).
//
// A node of an order-P element is named by its integer lattice point c = (i, j, k): its
// equispaced reference position is c / P (unused coordinates are 0). Vertices are at the
// corners: triangle (0,0) (P,0) (0,P); quadrilateral (0,0) (P,0) (P,P) (0,P); tetrahedron the
// origin and P times the unit vectors; prism the triangle at k = 0 then at k = P; hexahedron the
// quadrilateral at k = 0 then at k = P; pyramid the square (0,0) (P,0) (P,P) (0,P) at k = 0 and
// the apex (0,0,P) above its first corner, its level k holding 0 <= i, j <= P - k (an affine
// image of Gmsh's pyramid, whose apex is above the square's centre). Any node set (equispaced, GLL,
// warp & blend) names its nodes by the same lattice points, so connectivity does not depend on the
// node set.
//
// Gmsh orders nodes as vertices, edge interiors (edge by edge, from its first vertex to its
// second), face interiors (each a recursively ordered triangle or quadrilateral on the face's
// vertices in Gmsh's face order) and the cell interior (recursively; for prisms, triangle
// interior by line interior). VTK uses the same recursion for triangles and tetrahedra with
// other edge/face lists, and row-major (i fastest) interiors for quadrilaterals, hexahedra and
// wedges. CGNS (orders 1 to 4) lists vertices, edges and face interiors in the SIDS's order, a
// quadrilateral face's interior ring by ring from the node next to its first corner, and the
// interiors of prisms, pyramids and hexahedra level by level from the base (io/cgns_elements.hpp).
// The C++ tests check the Gmsh order against Gmsh's getElementProperties and the CGNS order
// against the SIDS's figures; the Python tests (tests/python/test_vtk_reading.py,
// test_cgns_files.py) check the VTK order by letting VTK interpolate our VTU cells, and the CGNS
// order against VTK's CGNS reader.
#pragma once

#include <array>
#include <vector>

#include "core/cell_type.hpp"

namespace homesh {

// Cgns: the SIDS's numbering (orders 1 to 4 only, the orders CGNS names).
enum class NodeConvention { Gmsh, Vtk, Cgns };

using LatticePoint = std::array<int, 3>;

// The lattice point of every node of a shape of the given order, in `convention`'s order.
// Throws ParameterError for unsupported shapes or order < 1.
std::vector<LatticePoint> latticeOrder(CellType type, int order, NodeConvention convention);

// perm[i] = index, in Gmsh order, of the i-th node in `convention` order.
std::vector<int> nodePermutationFromGmsh(CellType type, int order, NodeConvention convention);

// The nodes of the element's mirror image: perm[i] = index, in Gmsh order, of the node that
// takes the place of node i when the first two reference axes are swapped (for a line, when
// it is reversed). Listing an element's nodes as nodes[perm[i]] describes the same curved
// element with the opposite orientation (its Jacobian changes sign everywhere); perm is its
// own inverse. Readers use it for files written in the mirrored convention.
std::vector<int> mirrorPermutation(CellType type, int order);

// Integer barycentric coordinates (a0, a1, ..., ad) of a simplex lattice point: a_k = c_{k-1}
// for k >= 1 and a0 = P - sum. For simplices only.
std::array<int, 4> simplexBarycentric(const LatticePoint& c, int dim, int order);

}  // namespace homesh
