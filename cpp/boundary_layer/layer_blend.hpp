// After elevation, the macro layer made parallel to its curved wall (the pipeline's step before
// the optimiser; the split, layer_split.hpp, comes last).
#pragma once

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

// Shapes a freshly elevated macro layer after its curved wall: each high-order node of a cell's
// top (but its vertices) goes to the wall's node below it, offset by the height and direction
// interpolated from the vertices' climbs (the top runs parallel to the wall and meets the top
// vertices; the direction is the wall's normal, in 2D with `cad` the CAD curve's own at the wall
// node, corrected by the vertices' climbs against the same normals there), then the nodes
// between wall and top go to the blend (1 - t) W + t T at the same
// wall position, t the node's level, so each cell's first split layer has its share of the
// height everywhere. Cells: prisms (3D), quadrilaterals (2D). Nodes on a CAD face (the layer's
// sides in 3D) are projected back onto it (with `cad`; without, they stay); nodes on CAD curves
// stay. With `tops` false, only the inner nodes are placed (after the optimiser has moved the
// tops). Straight-sided tops and inner nodes fold the layer where the wall bulges by a large
// share of its height (a coarse wall around a cylinder).
void blendLayerInteriors(Mesh& mesh, const CadModel* cad, bool tops = true);

}  // namespace homesh
