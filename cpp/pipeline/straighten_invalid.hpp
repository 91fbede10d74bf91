// Repair of a given mesh's elements that curving and the optimiser left invalid (NekMesh's
// "linearise" of its industrial pipeline): their nodes off the CAD go back to where the
// straight-sided element has them. A curved given mesh cannot be repaired by meshing again (the
// mesh is the user's), and an element made invalid by the curving of its neighbours (a flat
// pyramid Gmsh stands on a boundary layer's top, its apex within the curved top's bulge) is
// often valid straight. Every element has one map per shared edge and face: the straight-sided
// map restricted to an edge is linear, to a quadrilateral face bilinear, whichever element
// it is taken from, so neighbours keep sharing their nodes.
#pragma once

#include <cstddef>

#include "core/mesh.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

// Moves the nodes of `mesh` that lie off the CAD (nodeCadDim == dim) and belong to an element
// that `quality` (of this mesh) finds invalid or undecided onto that element's straight-sided
// map. Returns the number of nodes moved.
std::size_t straightenInvalidElements(Mesh& mesh, const QualitySummary& quality);

}  // namespace homesh
