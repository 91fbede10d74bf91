// Topology of a mesh's elements: which nodes lie on its boundary.
#pragma once

#include <cstddef>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

// For each node (numNodes of them), 1 if it lies on a facet (a face of a 3D element, an edge of
// a 2D element) that belongs to exactly one of the elements in `blocks`, or that separates
// elements of different entities (an internal interface: the surface between two CAD solids),
// else 0. Facets are matched by their corner vertices, so conforming high-order meshes of any
// order work.
// With `interfaces` false, only the facets of exactly one element count.
std::vector<char> boundaryNodes(std::size_t numNodes,
                                const std::vector<const ElementBlock*>& blocks,
                                bool interfaces = true);

}  // namespace homesh
