// Which cells, nodes and triangles make a macro boundary layer (boundary_layer.hpp grows it):
// its cells (prisms in 3D, quadrilaterals in 2D), its wall vertices, the 2D fans' triangles at
// sharp convex corners, and the lattice index every layer routine reads its cells' nodes by.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "core/mesh.hpp"
#include "element/reference_element.hpp"

namespace homesh {

// Whether the block holds a macro layer's cells: prisms in 3D, quadrilaterals in 2D (whose
// other quadrilaterals, in 3D, are the layer's sides on the CAD).
bool isLayerCell(const Mesh& mesh, const ElementBlock& block);

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
