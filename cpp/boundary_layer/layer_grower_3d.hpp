// The 3D boundary layer's growth (internal to boundary_layer/; growBoundaryLayer calls it):
// prisms grown from chosen CAD faces of a linear tetrahedral mesh of one solid, whose surface
// alone is kept; the rest of the solid is refilled with tetrahedra (fillTetrahedra). Every
// prism has its wall triangle as vertices 0, 1, 2 and its top as 3, 4, 5; the layer's sides on
// faces without a layer are quadrilaterals on the CAD, its climbs on curves lines of that curve.
#pragma once

#include "boundary_layer/layer_parameters.hpp"
#include "boundary_layer/layer_record.hpp"
#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "linear/linear_mesher.hpp"

namespace homesh::layer_growth {

// As growBoundaryLayer (boundary_layer.hpp) for a volume mesh (dim 3); fills `record` but its
// time. Throws ParameterError or MeshingError as that says.
Mesh growLayer3D(const Mesh& volume, const CadModel& cad, const BoundaryLayerParameters& p,
                 const LinearMeshOptions& fill, BoundaryLayerRecord& record);

}  // namespace homesh::layer_growth
