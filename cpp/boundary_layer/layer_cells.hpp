// Which cells, nodes and triangles make a macro boundary layer (boundary_layer.hpp grows it;
// layer_stacks.hpp recognises a given one): its cells (prisms, and hexahedra of a block marked
// as layer cells, in 3D; quadrilaterals in 2D), their shape (wall vertices, tops, the axis across
// the layer), its wall vertices, the 2D fans' triangles at sharp convex corners, and the lattice
// index every layer routine reads its cells' nodes by.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "core/mesh.hpp"
#include "element/reference_element.hpp"

namespace homesh {

// Whether the block holds a macro layer's cells: prisms, and hexahedra marked
// ElementBlock::layerCells, in 3D; quadrilaterals in 2D (whose other quadrilaterals, in 3D, are
// the layer's sides on the CAD).
bool isLayerCell(const Mesh& mesh, const ElementBlock& block);

// A layer cell's shape. Its wall vertices are 0 .. walls - 1 (a prism's triangle 0, 1, 2, a
// hexahedron's quadrilateral 0, 1, 2, 3, a 2D quadrilateral's edge 0, 1), each with its top: 3,
// 4, 5 above a prism's, 4, 5, 6, 7 above a hexahedron's, 3 and 2 above a quadrilateral's. The
// lattice axis `across` runs from the wall (0) to the top (P); the others are the wall's own
// reference coordinates (a, b) (b is 0 on a 2D edge).
struct LayerShape {
  CellType type = CellType::Prism;
  int walls = 3;
  std::size_t across = 2;
  CellType wall = CellType::Triangle;  // the wall's cell type

  std::int64_t top(const std::int64_t* v, int k) const {
    return type == CellType::Quadrilateral ? v[3 - k] : v[k + walls];
  }
  // The wall vertices' weights at wall point (a, b): barycentric on a triangle, bilinear on a
  // quadrilateral, linear on an edge (unused entries 0).
  std::array<double, 4> weights(double a, double b) const;
  // The same at lattice point `c` of order `p`, as integers summing to P (P^2 for a hexahedron).
  std::array<int, 4> latticeWeights(const LatticePoint& c, int p) const;
  // Whether (a, b) lies in the wall's reference cell, to `tolerance`.
  bool inWall(double a, double b, double tolerance) const;
};

// The shape of a layer cell of `type` (Prism, Hexahedron, Quadrilateral).
LayerShape layerShape(CellType type);

// In 2D, per element of `block`, 1 for a triangle of a macro layer's fan (at a sharp convex corner
// of the wall, boundary_layer.hpp): a triangle with a vertex on the wall of a layer
// quadrilateral (the fill never reaches the wall); that vertex is the fan's corner, the two
// others tops of its columns. All 0 for any other block, and in 3D.
std::vector<char> layerFanTriangles(const Mesh& mesh, const ElementBlock& block);

// Whether layer fans can be in the block: 2D triangles.
bool mayHoldFans(const Mesh& mesh, const ElementBlock& block);

// The wall vertices of a 2D mesh's layer quadrilaterals (0 and 1 of each).
std::set<std::int64_t> layerWall(const Mesh& mesh);

// Per element of `block` (triangles), 1 where a vertex is in `wall` (layerWall): the fan flags
// of layerFanTriangles, with the wall found once by the caller.
std::vector<char> fanTriangles(const ElementBlock& block, const std::set<std::int64_t>& wall);

// Node index (in the element's node order) of each lattice point of `ref`.
std::map<LatticePoint, int> latticeIndex(const ReferenceElement& ref);

}  // namespace homesh
