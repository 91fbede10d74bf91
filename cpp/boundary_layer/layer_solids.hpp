// The 3D layer in a model of several solids (internal to boundary_layer/; growBoundaryLayer
// calls it): each solid that a layer face grows into (the one it bounds, or of the two it lies
// between the one named: BoundaryLayerParameters::solids) grows its own layer from its own part
// of the linear mesh (growLayer3D: its tetrahedra, its boundary triangles turned outward of it,
// the lines on its boundary), every other solid keeps its tetrahedra as they are, and the parts
// are joined on the model's surface nodes, which keep their numbers. A layer must leave alone
// what another solid touches, since that solid's tetrahedra are not remade: a layer whose side
// would climb a face between two solids, or with a wall node another solid shares other than on
// a layer face between them, is refused with a ParameterError naming the faces, the solids and
// the place (not made yet), as is a face between two solids with neither or both named.
#pragma once

#include "boundary_layer/layer_parameters.hpp"
#include "boundary_layer/layer_record.hpp"
#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "linear/linear_mesher.hpp"

namespace homesh::layer_growth {

// As growLayer3D for a volume mesh of one or more solids (one: growLayer3D itself); fills
// `record` (the solids' records joined: their faces in order, counts summed, the thickness range
// over all) but its time.
Mesh growLayerInSolids(const Mesh& volume, const CadModel& cad, const BoundaryLayerParameters& p,
                       const LinearMeshOptions& fill, BoundaryLayerRecord& record);

}  // namespace homesh::layer_growth
