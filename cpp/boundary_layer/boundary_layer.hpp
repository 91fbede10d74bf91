// Macro boundary layer (3D): one layer of prisms grown from chosen CAD faces, the rest of the
// solid refilled with tetrahedra (../shared/DESIGN.md section 3; NekMesh's method).
//
// From a linear tetrahedral mesh (generateLinearMesh) only the surface is kept. Every node of a
// layer face moves inwards along a smoothed normal (angle-weighted facet normals, relaxed with
// its neighbours) by the thickness there; a node that also lies on a face without a layer moves
// tangent to that face and is projected onto it (onto the common curve where two such faces
// meet), so the layer's side faces are quadrilaterals on the CAD. Heights shrink locally (and
// grade smoothly around) where a prism would fold, where a neighbouring face's triangle would
// fold when its node moves up, or where the normal, extended to 2.5 thicknesses, crosses another
// wall (thin gaps, the layer meeting itself). The layer's top and the other faces' triangles
// close a surface that Gmsh fills with tetrahedra (fillTetrahedra).
//
// The prisms are the macro elements the later stages curve and optimise; the split into thin
// layers (layer_split.hpp) comes last. Every prism has its wall triangle as vertices
// 0, 1, 2 (Gmsh's prism order) and its top as 3, 4, 5.
//
// 2D: quadrilaterals (wall 0, 1; tops 3 above 0 and 2 above 1) from chosen curves of a planar
// face. Where two layer curves meet at a sharp convex corner, the corner node gets a fan: a
// column along each curve's own normal (each side's quadrilateral uses its own) and columns
// between them, with triangles (corner, top, top) between consecutive columns, appended to the
// triangle block; they are part of the layer (layerFanTriangles in boundary_layer/layer_cells.hpp).
//
// In a model of several solids, each solid that a layer face grows into (the one it bounds; of the
// two it lies between, the one named) grows its own layer and the others keep their tetrahedra
// (layer_solids.hpp); a layer grown into both sides of a face, or whose side would change what
// another solid touches, is refused (not made yet).
//
// The stage's parts: layer_parameters.hpp (what is asked), layer_record.hpp (what was made),
// layer_grower_3d.hpp and layer_grower_2d.hpp (the growth), layer_solids.hpp (3D models of
// several solids), wall_segment_split.hpp (2D walls halved first), layer_growth.hpp (what the
// growers share).
#pragma once

#include "boundary_layer/layer_parameters.hpp"
#include "boundary_layer/layer_record.hpp"
#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "linear/linear_mesher.hpp"

namespace homesh {

// `volume`: a linear tetrahedral mesh of one or more solids with its boundary triangles (of one
// solid: outward, as generateLinearMesh makes them). Returns the linear mesh with the macro
// layer: blocks tetrahedra, prisms, boundary triangles, boundary quadrilaterals (the layer's sides
// on faces without a layer), lines. `fill` gives the largest tetrahedron size. Throws
// ParameterError (a face that does not exist, a thickness that is not positive somewhere, a layer
// face between two solids or beside another solid) or MeshingError naming the face and the place
// where no layer can be grown.
Mesh growBoundaryLayer(const Mesh& volume, const CadModel& cad,
                       const BoundaryLayerParameters& parameters, const LinearMeshOptions& fill,
                       BoundaryLayerRecord& record);

}  // namespace homesh
