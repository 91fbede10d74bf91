// Bisection of interior edges of a linear simplex mesh (tetrahedra in 3D, triangles in 2D).
//
// Splitting edge (a, b) at a new node m replaces every cell around the edge by two cells: one
// with b replaced by m, one with a replaced by m. With m on the segment the two halves keep the
// cell's orientation and their volumes add up to the cell's; m may also be placed off the
// segment (the caller's choice, e.g. on the side of a curved CAD face where the solid is), in
// which case every new cell is checked to have positive volume before anything changes.
//
// An interior edge (an edge of no lower-dimensional cell: no boundary triangle in 3D, no boundary
// line in 2D) leaves the boundary blocks as they are, the new node inside the cells' entity (its
// CAD solid, or face in 2D). An edge on the boundary also splits the boundary cells on it, the
// new node on their CAD face or curve (the caller projects it there).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <set>
#include <string>

#include "core/mesh.hpp"

namespace homesh {

using MeshEdge = std::array<std::int64_t, 2>;  // node ids, smaller first

// The edge between nodes a and b (smaller id first).
inline MeshEdge meshEdge(std::int64_t a, std::int64_t b) {
  return a < b ? MeshEdge{a, b} : MeshEdge{b, a};
}

// Coordinates of node i.
inline Eigen::Vector3d nodePoint(const Mesh& mesh, std::int64_t i) {
  return {mesh.xyz[3 * i], mesh.xyz[3 * i + 1], mesh.xyz[3 * i + 2]};
}

// The edges of the mesh's lower-dimensional cells (boundary triangles' edges in 3D, boundary
// lines in 2D), smaller id first.
std::set<MeshEdge> boundaryEdges(const Mesh& mesh);

// The block holding a linear volume mesh's tetrahedra, or nullptr when it has none. Throws
// ParameterError naming `what` ("flips") when the mesh is not linear and 3D, or its cells are
// not all tetrahedra in one block (what local changes to its connectivity need).
ElementBlock* tetrahedronBlock(Mesh& mesh, const std::string& what);

// Signed volume (3D) or area against mesh.planeNormal (2D) of the simplex on `nodes`.
double simplexVolume(const Mesh& mesh, const std::int64_t* nodes);

// Where the new node of a split lies on the CAD (core/mesh.hpp's node records).
struct SplitNode {
  Eigen::Vector3d point;
  int cadDim = 3;  // mesh.dim: inside the cells' entity (cadIndex 0: take the cells' entity)
  int cadIndex = 0;
  double param0 = std::numeric_limits<double>::quiet_NaN();
  double param1 = std::numeric_limits<double>::quiet_NaN();
};

// Splits edge `edge` of linear `mesh` at `node`: the node is appended, and every cell of every
// block that has both ends (the cells around the edge and, for an edge on the boundary, the
// boundary triangles or lines on it) is halved: each keeps its slot, its second half is
// appended to its block. Returns false, changing nothing, when a new cell of dimension mesh.dim
// would not have positive volume. Throws ParameterError when the mesh is not a linear simplex
// mesh or the edge is not an edge of its cells.
bool splitEdge(Mesh& mesh, const MeshEdge& edge, const SplitNode& node);

// splitEdge for an interior edge, the new node inside the cells' entity. Throws ParameterError
// also when the edge lies on a boundary cell.
bool splitInteriorEdge(Mesh& mesh, const MeshEdge& edge, const Eigen::Vector3d& point);

}  // namespace homesh
