// Raises a linear mesh to order P and puts the new boundary nodes on the CAD.
//
// Every shape: lines, triangles, quadrilaterals, tetrahedra, prisms, pyramids and
// hexahedra, mixed in one mesh. New nodes are shared between the elements that contain them: a
// node is identified by the global vertices of the edge, face or cell it belongs to and the
// integer weights (times P^3) its straight-sided position gives them, which every neighbour
// computes identically whatever its local orientation or shape. Nodes on a
// CAD curve or face (known from the linear mesh's boundary lines and triangles) are placed on it
// and record their parameters: along curves spaced in arc length from the end vertices'
// parameters, along edges inside faces spaced in (u, v) towards the geodesic, inside boundary
// triangles as a relaxed lattice in (u, v) (curve_node_placement.hpp, face_node_placement.hpp);
// where such a placement fails its checks (order along the edge, no flipped lattice triangle,
// inside the face's trimming) the nodes are projected onto the entity. Inside boundary
// quadrilaterals the nodes are the transfinite (Coons) interpolation in (u, v) of the placed
// edges, checked unflipped and inside the trimming, else projected. Interior nodes stay at
// their straight-sided positions (the optimiser curves the interior later).
#pragma once

#include <cstddef>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

// How the new boundary nodes were placed (counts of mesh edges and triangles). "AtStart": the
// spacing optimum failed its checks and the monotone start was kept; "Projected": the start
// failed too and the nodes were projected onto the CAD one by one.
struct CurvingStats {
  std::size_t curveEdges = 0, curveEdgesAtStart = 0;
  std::size_t faceEdges = 0, faceEdgesAtStart = 0, faceEdgesProjected = 0;
  std::size_t faceInteriors = 0, faceInteriorsAtStart = 0, faceInteriorsProjected = 0;
  std::size_t quadInteriors = 0, quadInteriorsProjected = 0;  // boundary quadrilaterals
};

// `linear` must have order 1. `cad` may be null (no projection: a straight-sided order-P mesh).
// With `layer` (a 2D mesh whose quadrilaterals are a macro boundary layer, wall 0-1 and tops
// 3-2), the wall edges' nodes are spaced on the layer's offset (curve_node_placement.hpp)
// instead of in arc length; without it quadrilaterals are cells like any other.
// Throws ParameterError for an order outside 1..10.
Mesh elevateOrder(const Mesh& linear, int order, const CadModel* cad, CurvingStats* stats = nullptr,
                  bool layer = false);

// The same for a mesh of any order: each new node is the source element's own (curved) map
// evaluated at the node's reference position, so raising the order keeps the geometry exactly
// and lowering it interpolates it (what NekMesh does before optimising at a lower order). Nodes
// the new mesh no longer uses are dropped and the rest renumbered in order. With `cad`, new
// nodes on CAD curves and faces are placed on them as above, but with `layer` in 3D (a mesh
// whose prisms are a macro boundary layer, wall 0-1-2 and tops 3-4-5) the edges of the layer's
// top that lie on a CAD face (the layer's sides) keep the source's shape, projected onto the
// face: placed afresh between their ends they would run straight where the source had them
// parallel to the wall.
Mesh changeOrder(const Mesh& mesh, int order, const CadModel* cad, CurvingStats* stats = nullptr,
                 bool layer = false);

}  // namespace homesh
