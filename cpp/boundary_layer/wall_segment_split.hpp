// Before a 2D layer grows (internal to boundary_layer/): wall segments on layer curves along
// which the CAD curve turns by more than 30 degrees are halved where the curve has turned half
// way, so that no layer cell's wall turns too far for one cell (its top arc would bulge into
// the triangles beyond, or its corners' normals spread and cost the first layer its height).
#pragma once

#include "boundary_layer/layer_parameters.hpp"
#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh::layer_growth {

// Halves the wall segments of layer curves along which the curve turns too much for one cell
// (also the NACA 0012's nose, radius 0.0158 against segments 0.1 long: the two cells' order-4
// walls met there at more than 30 degrees, and the first layer's height along their normals
// was 5.8 % off). The new node is where the curve has turned half way: on a spline whose
// curvature peaks at one end of a segment (T106's shoulders), the mean parameter left one half
// still turning most of the way (worst element at order 4 0.054 against 0.084).
// Returns the halvings.
int splitTightWallSegments(Mesh& planar, const CadModel& cad, const BoundaryLayerParameters& p);

}  // namespace homesh::layer_growth
