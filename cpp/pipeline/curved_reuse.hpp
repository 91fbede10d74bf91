// Reuse of a curved mesh's work in the next repair round.
//
// A repair round changes the linear mesh only near the elements it repairs (a split touches the
// cells around the split edges; a refinement sphere, the cells Gmsh remeshes near it). Curving
// and optimising the whole new mesh again would redo, far from any change, work whose result is
// already known. Here a cell of the new linear mesh that also is in the old one (the same vertex
// coordinates in the same order: a bitwise match, so only cells the round left alone qualify)
// takes every high-order node of its old curved element, coordinates and CAD parameters; the
// optimiser then only needs to work on the new cells and a few layers around them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

struct CurvedReuse {
  std::vector<char> fresh;  // per element of the new mesh (block order): 1 when its cell is new
  // Per element of the new mesh: the index (block order) of the old element whose nodes it
  // took, -1 for a new cell (KnownQuality's source: its quality need not be measured again).
  std::vector<std::int64_t> source;
  std::size_t reused = 0;  // elements that took their old curved nodes
};

// `oldLinear` and `oldCurved` are a linear mesh and its elevation (elements in the same order,
// as elevateOrder keeps them), `newLinear` and `newCurved` likewise, of the same order. Writes
// the reused nodes into newCurved. Nodes shared by a reused and a new element take the reused
// element's values (they are the same node of both). Throws ParameterError when a linear and a
// curved mesh do not have the same elements or the two curved meshes differ in order.
CurvedReuse reuseCurvedNodes(const Mesh& oldLinear, const Mesh& oldCurved, const Mesh& newLinear,
                             Mesh& newCurved);

}  // namespace homesh
