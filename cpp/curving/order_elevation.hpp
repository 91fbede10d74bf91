// Raises a linear mesh to order P and puts the new boundary nodes on the CAD.
//
// New nodes are shared between the elements that contain them: a node is identified by the
// global vertices of the edge, face or cell it belongs to and its integer barycentric index
// there, which every neighbour computes identically whatever its local orientation. Nodes on a
// CAD curve or face (known from the linear mesh's boundary lines and triangles) are projected
// onto it and record their parameters; interior nodes stay at their straight-sided positions
// (the optimiser curves the interior later).
#pragma once

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

// `linear` must have order 1. `cad` may be null (no projection: a straight-sided order-P mesh).
// Throws ParameterError for an order outside 1..10.
Mesh elevateOrder(const Mesh& linear, int order, const CadModel* cad);

// The same for a mesh of any order: each new node is the source element's own (curved) map
// evaluated at the node's reference position, so raising the order keeps the geometry exactly
// and lowering it interpolates it (what NekMesh does before optimising at a lower order). Nodes
// the new mesh no longer uses are dropped and the rest renumbered in order. With `cad`, new
// nodes on CAD curves and faces are projected onto them as above.
Mesh changeOrder(const Mesh& mesh, int order, const CadModel* cad);

}  // namespace homesh
