// Local reconnection of a linear tetrahedral mesh that takes flat cells (slivers) away.
//
// A sliver has four vertices nearly in one plane and no short edge. Splitting one of its edges
// makes two halves as flat as itself, and the optimiser can inflate it only by moving its
// vertices against every other cell around them: repair rounds found such cells, with one
// vertex on the boundary and three inside, that stay inverted through every sweep. A flip
// replaces the cells around one interior edge or face of the sliver by others on the same
// vertices, the sliver among those that go:
//   - edge removal: the n cells around an interior edge (a, b), whose other vertices form a ring
//     r_0 .. r_{n-1}, become 2 (n - 2): a triangulation of the ring, each triangle joined to a and
//     to b (n = 3 is the 3-2 flip, n = 4 the 4-4 flip);
//   - face removal (the 2-3 flip): the two cells on an interior face become three around the
//     edge that joins their opposite vertices.
// The boundary triangles, and so everything that lies on the CAD, stay as they are.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

// Shape of the tetrahedron (p0, p1, p2, p3): 6 sqrt(2) V / l^3, with V its signed volume and l
// the root mean square of its six edge lengths: 1 for the regular tetrahedron, 0 when flat,
// negative when inverted.
double tetShape(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                const Eigen::Vector3d& p3);

// A flip is made only when the worst shape it makes beats the worst it removes by this.
inline constexpr double kFlipShapeGain = 0.02;

struct FlipOutcome {
  std::size_t flips = 0;         // flips made
  std::size_t cellsFlipped = 0;  // of the cells asked for, those a flip took away
};

// For each cell of `cells` (indices among the mesh's tetrahedra, in element order) that no
// earlier flip of this call changed: every edge removal (rings of 3 to 7 cells) and face removal
// that takes the cell away is judged, and of those whose worst new cell has a positive shape
// that beats the worst shape among the cells they remove by kFlipShapeGain, the one whose worst
// new cell is best is made. Shapes are judged at `positions` (3 per node; empty: the mesh's own
// coordinates), e.g. where the optimiser has moved the vertices of the curved mesh made from
// this one; every new cell must also have positive volume at the mesh's own coordinates (the
// linear mesh stays a valid mesh). The cells are taken to be positive as stored (Gmsh's
// orientation, which splits keep): the orientation of new cells follows from that. A flip is
// left out when it would add an edge that already exists or whose ends lie on one boundary face,
// or a face whose vertices all do (the face of a node is the entity of a boundary triangle on it:
// a chord of a curved face is what curving cannot follow), or when its cells lie in different
// solids. Cells that stay keep their order; new cells follow them (the element order changes).
// Throws ParameterError when the mesh is not a linear tetrahedral mesh with its tetrahedra in one
// block, a cell index is out of range, or `positions` does not have 3 values per node.
FlipOutcome flipAwayCells(Mesh& mesh, const std::vector<std::size_t>& cells,
                          const std::vector<double>& positions = {});

}  // namespace homesh
