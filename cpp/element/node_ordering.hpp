// Node orderings of complete Lagrange simplices (line, triangle, tetrahedron).
//
// A node of an order-P simplex is named by its integer barycentric coordinates (a_0, ..., a_d),
// a_k >= 0, sum a_k = P: node position = sum_k (a_k / P) * vertex_k for equispaced nodes, and the
// same lattice index names the corresponding node of any symmetric node set. Vertex k of the
// reference simplex is the origin for k = 0 and the k-th unit vector otherwise.
//
// Both Gmsh and VTK order nodes as: vertices, edge interiors (edge by edge, from the edge's first
// vertex to its second), face interiors (each a recursively ordered triangle of order P-3 whose
// vertices are the face's vertices in the listed order), then the cell interior (recursively, a
// simplex of order P-4 for a tetrahedron). They differ only in the edge and face lists. The C++
// tests check the Gmsh order against Gmsh's getElementProperties up to order 10; the Python
// tests (tests/python/test_vtk_reading.py) check the VTK order by letting VTK interpolate our
// VTU cells.
#pragma once

#include <array>
#include <vector>

#include "core/cell_type.hpp"

namespace homesh {

enum class NodeConvention { Gmsh, Vtk };

// Integer barycentric coordinates; entries beyond the simplex dimension are zero.
using Lattice = std::array<int, 4>;

// The lattice of every node of a Line, Triangle or Tetrahedron of the given order, in the node
// order of `convention`. Throws ParameterError for other shapes or order < 1.
std::vector<Lattice> simplexLattice(CellType type, int order, NodeConvention convention);

// perm[i] = index, in Gmsh order, of the i-th node in `convention` order.
std::vector<int> nodePermutationFromGmsh(CellType type, int order, NodeConvention convention);

}  // namespace homesh
