// Bisection of interior edges of a linear simplex mesh (tetrahedra in 3D, triangles in 2D).
//
// Splitting edge (a, b) at a new node m replaces every cell around the edge by two cells: one
// with b replaced by m, one with a replaced by m. With m on the segment the two halves keep the
// cell's orientation and their volumes add up to the cell's; m may also be placed off the
// segment (the caller's choice, e.g. on the side of a curved CAD face where the solid is), in
// which case every new cell is checked to have positive volume before anything changes.
//
// Only interior edges are split (an edge of no lower-dimensional cell: no boundary triangle in
// 3D, no boundary line in 2D), so the boundary blocks and every node on the CAD stay as they
// are; the new node lies inside the cells' entity (its CAD solid, or face in 2D).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <set>

#include "core/mesh.hpp"

namespace homesh {

using MeshEdge = std::array<std::int64_t, 2>;  // node ids, smaller first

// The edges of the mesh's lower-dimensional cells (boundary triangles' edges in 3D, boundary
// lines in 2D), smaller id first.
std::set<MeshEdge> boundaryEdges(const Mesh& mesh);

// Signed volume (3D) or area against mesh.planeNormal (2D) of the simplex on `nodes`.
double simplexVolume(const Mesh& mesh, const std::int64_t* nodes);

// Splits interior edge `edge` of linear `mesh` at `point`: the new node is appended (CAD
// dimension mesh.dim, entity the cells'), the cells around the edge are halved (each keeps its
// slot, its second half is appended to the block). Returns false, changing nothing, when a new
// cell would not have positive volume. Throws ParameterError when the mesh is not a linear
// simplex mesh, or the edge is not an edge of its cells, or lies on a boundary cell.
bool splitInteriorEdge(Mesh& mesh, const MeshEdge& edge, const Eigen::Vector3d& point);

}  // namespace homesh
