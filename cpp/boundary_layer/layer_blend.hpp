// After elevation, the macro layer made parallel to its curved wall (the pipeline's step before
// the optimiser; the split, layer_split.hpp, comes last).
#pragma once

#include <cstdint>
#include <set>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

// Shapes a freshly elevated macro layer after its curved wall: each high-order node of a cell's
// top (but its vertices) goes to the wall's node below it, offset by the height and direction
// interpolated from the vertices' climbs (the top runs parallel to the wall and meets the top
// vertices; the direction is the wall's normal, in 2D with `cad` the CAD curve's own at the wall
// node, corrected by the vertices' climbs against the same normals there). In a cell with a
// vertex in `sharpColumns` (BoundaryLayerRecord's: the linear mesh's wall vertices, which
// elevation keeps), the node is raised along the wall's normal by the vertices' climbs' heights
// along their normals, interpolated, and leant by their leans across those normals,
// interpolated: on a flat wall the plane through the top vertices, even between a column
// leaning at a sharp edge and an upright one. Then the nodes between wall and top go to the
// blend (1 - t) W + t T at the same wall position, t the node's level, so each cell's first
// split layer has its share of the height everywhere. Cells: prisms (3D), quadrilaterals (2D).
// Nodes on a CAD face (the layer's sides in 3D) are projected back onto it (with `cad`; without,
// they stay); nodes on CAD curves stay. With `tops` false, only the inner nodes are placed
// (after the optimiser has moved the tops). Straight-sided tops and inner nodes fold the layer
// where the wall bulges by a large share of its height (a coarse wall around a cylinder).
void blendLayerInteriors(Mesh& mesh, const CadModel* cad, bool tops = true,
                         const std::set<std::int64_t>* sharpColumns = nullptr);

}  // namespace homesh
