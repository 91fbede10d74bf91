// The geometry Nektar++ builds from a file's curves, where it is not fixed by the stored points
// alone (docs/nektar-format.md, "Element interiors"):
//
// - A tetrahedron's (prism's) map is a polynomial of the element's order in Sherwin and
// Karniadakis's
//   modified (C0, collapsed-coordinate) basis whose boundary modes come from its faces and whose
//   interior modes are zero. Which polynomial that is depends on the basis (the span of its
//   boundary modes is not canonical) and on which vertex is which: Nektar++'s local vertices,
//   which the reader's Gmsh local order of a tetrahedron already follows.
// - A triangle's curve at NodalTriElec points is the polynomial through those points, which are
//   Hesthaven's electrostatic points (SIAM J. Numer. Anal. 35, 1998) as tabulated to 10 digits.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/cell_type.hpp"

namespace homesh::nektar {

// Interior nodes of a triangle, tetrahedron or prism (or a pyramid up to order 2, which has none:
// from order 3 Nektar++'s ModifiedPyr_C modes are not in our pyramid's space, mode (3, 3, 0)
// first, and MeshingError says so) from its boundary nodes, on the equispaced
// Gmsh-ordered lattice of `order`: interior = weights * boundary (rows of the nodes'
// coordinates). The element's local vertices are Nektar++'s as the reader orders them.
struct ExpansionInteriorMap {
  std::vector<int> boundary;  // node indices (Gmsh order) on the faces
  std::vector<int> interior;  // the others
  Eigen::MatrixXd weights;    // interior.size() x boundary.size()
};
// Shared and built once per shape and order (thread-safe); order 1 to kMaxOrder.
const ExpansionInteriorMap& interiorFromBoundary(CellType type, int order);

// Value of the modified basis's mode (p, q, r) (its form does not depend on the order), with
// Nektar++'s treatment of the collapsed vertex and edges. A tetrahedron's at barycentric point
// `lambda` (Nektar++'s vertices 0..3; lambda0 + lambda1 > 0 and lambda3 < 1), a prism's at
// reference point `xi` in [-1, 1]^3 (xi3 < 1). Exposed for tests.
double modifiedTetMode(int p, int q, int r, const std::array<double, 4>& lambda);
double modifiedPrismMode(int p, int q, int r, const std::array<double, 3>& xi);
// A pyramid's at reference point `xi` in [-1, 1]^3 (Nektar++'s vertices are Gmsh's, the apex
// (-1, -1, 1) above vertex 0; xi3 < 1): modA(p, eta1) modA(q, eta2) ModifiedPyr_C(p, q, r; xi3),
// the apex's function (1 + xi3)/2 (Nektar++ 5.2's Basis.cpp and StdPyrExp.cpp).
double modifiedPyramidMode(int p, int q, int r, const std::array<double, 3>& xi);
bool isInteriorPyramidMode(int p, int q, int r);
bool isInteriorTetMode(int p, int q, int r);
bool isInteriorPrismMode(int p, int q, int r);

// The NodalTriElec points of `order` on the unit triangle (vertices (0,0), (1,0), (0,1)), in
// the order a curved face lists them: the vertices, each edge's interior points from its first
// vertex to its second (edges 01, 12, 20), then the interior points row by row (rising y, each
// row by rising x). Throws ParameterError for orders without a table.
std::vector<std::array<double, 2>> triElecPoints(int order);
bool hasTriElecPoints(int order);

// The matrix that takes a triangle's values at its NodalTriElec points (in that order) to its
// values at the equispaced points of the same slots (vertices, edge points at t / order, the
// interior rows at lattice points): the same polynomial, resampled.
const Eigen::MatrixXd& triElecToEvenlySpaced(int order);

}  // namespace homesh::nektar
