// The 2D boundary layer's growth (internal to boundary_layer/; growBoundaryLayer calls it):
// quadrilaterals (wall 0, 1; tops 3 above 0 and 2 above 1) grown from chosen CAD curves of a
// planar triangle mesh of one face, the rest refilled with triangles (fillTriangles). A wall
// node on a curve without a layer climbs it, and the climb becomes a line of that curve; where
// two layer curves meet at a sharp convex corner the corner gets a fan of columns, whose
// triangles (corner, top, top) are appended to the triangle block (layerFanTriangles).
#pragma once

#include "boundary_layer/layer_parameters.hpp"
#include "boundary_layer/layer_record.hpp"
#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "linear/linear_mesher.hpp"

namespace homesh::layer_growth {

// As growBoundaryLayer (boundary_layer.hpp) for a planar mesh (dim 2) whose tight wall
// segments are already halved (splitTightWallSegments); fills `record` but its time and wall
// splits. Throws ParameterError or MeshingError as that says.
Mesh growLayer2D(const Mesh& planar, const CadModel& cad, const BoundaryLayerParameters& p,
                 const LinearMeshOptions& fill, BoundaryLayerRecord& record);

}  // namespace homesh::layer_growth
