// Splits a curved macro boundary layer into thin layers (../shared/DESIGN.md section 8).
//
// Every prism is split across its wall-normal reference direction (the wall is its triangle
// 0, 1, 2, as linear/boundary_layer.hpp makes it) at the coordinates z_0 = 0 < ... < z_n = 1;
// each new node is the macro prism's own curved map at its reference point, so each thin prism
// is a sub-map of the macro one (valid where the macro prism is, its Jacobian scaled by
// z_{k+1} - z_k). Nodes shared by neighbours (on the prisms' side faces and edges) are made once,
// identified by the wall vertices' integer weights and the level across the layer. The layer's
// side quadrilaterals and its climbing lines on the CAD are split alike, and their new nodes are
// projected onto their CAD face or curve (from the interpolated point, which lies within the
// macro element's interpolation error of it). Tetrahedra and triangles are kept.
#pragma once

#include <cstddef>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

struct LayerSplitStats {
  std::size_t prisms = 0, quadrilaterals = 0, lines = 0;  // macro elements split
  std::size_t projected = 0;                              // new nodes on a CAD face or curve
  double maxProjection = 0.0;  // largest move onto the CAD, relative to the layer's height
};

// Shapes a freshly elevated macro layer after its curved wall: each high-order node of a cell's
// top (but its vertices) goes to the wall's node below it, offset by the height and direction
// interpolated from the vertices' climbs (the top runs parallel to the wall and meets the top
// vertices), then the nodes between wall and top go to the blend (1 - t) W + t T at the same
// wall position, t the node's level, so each cell's first split layer has its share of the
// height everywhere. Cells: prisms (3D), quadrilaterals (2D). Nodes on a CAD face (the layer's
// sides in 3D) are projected back onto it (with `cad`; without, they stay); nodes on CAD curves
// stay. With `tops` false, only the inner nodes are placed (after the optimiser has moved the
// tops). Straight-sided tops and inner nodes fold the layer where the wall bulges by a large
// share of its height (a coarse wall around a cylinder).
void blendLayerInteriors(Mesh& mesh, const CadModel* cad, bool tops = true);

// `z`: the split coordinates (BoundaryLayerParameters::splitCoordinates). `cad` may be null
// (no projection). Throws MeshingError when a side quadrilateral or line does not follow the
// prisms' wall-to-top pairs.
Mesh splitBoundaryLayer(const Mesh& macro, const std::vector<double>& z, const CadModel* cad,
                        LayerSplitStats* stats = nullptr);

}  // namespace homesh
