// Splits a curved macro boundary layer into thin layers (../shared/DESIGN.md section 8).
//
// Every layer cell is split across its wall-normal reference direction (the wall is a prism's
// triangle 0, 1, 2, as boundary_layer.hpp makes it, or a marked hexahedron's quadrilateral
// 0, 1, 2, 3, as layer_stacks.hpp makes it; layer_cells.hpp) at the coordinates z_0 = 0 < ... < z_n
// = 1; each new node is the macro prism's own curved map at its reference point, so each thin prism
// is a sub-map of the macro one (valid where the macro prism is, its Jacobian scaled by
// z_{k+1} - z_k). With the heights the layer was grown to, the levels are set per column of
// nodes instead, so that the first layer keeps its asked height where the optimiser moved the
// macro layer's top (the thin cells then interpolate the macro map on slightly curved level
// surfaces; the split mesh is certified again either way). Nodes shared by neighbours (on the
// prisms' side faces and edges) are made once, identified by the wall vertices' integer weights and
// the level across the layer. The layer's side quadrilaterals and its climbing lines on the CAD are
// split alike, and their new nodes are projected onto their CAD face or curve (from the
// interpolated point, which lies within the macro element's interpolation error of it). Tetrahedra
// and triangles are kept, but a 2D fan's triangles (layerFanTriangles), each split into 2n - 1
// triangles on its columns' levels.
//
// The split's parts (internal): layer_splitter.hpp and the files it names.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

struct LayerSplitStats {
  // Macro elements split: prisms (2D: quadrilaterals), hexahedra, side quadrilaterals, lines.
  std::size_t prisms = 0, hexahedra = 0, quadrilaterals = 0, lines = 0;
  std::size_t projected = 0;   // new nodes on a CAD face or curve
  double maxProjection = 0.0;  // largest move onto the CAD, relative to the layer's height
  // The first layer's height along the wall normal at the wall's quadrature points (degree
  // 2P), the distance to where the normal line meets the layer's top: its range over the points
  // measured and, with grown heights, the worst relative deviation from z_1 times the grown height
  // interpolated there (0 without them), on the smooth wall and in the cells with a vertex at a
  // sharp corner (where the walls' normals spread by more than 30 degrees: a column there leans
  // between the walls, lengthened so that its top is at the height from each, or where no
  // lengthening was made (a 2D fan's cells, a column held down), follows their bisector, and
  // the height along each wall's normal falls towards the corner).
  std::size_t firstHeightMeasured = 0, cornerCells = 0;
  // Quadrature points whose normal line leaves the cell's top through a neighbour's: measured
  // there as the top point's component along the normal instead (heightAlongNormal).
  std::size_t firstHeightOffNormal = 0;
  double firstHeightCornerDeviation = 0.0;
  std::size_t plainColumns = 0;  // columns split at z unchanged (LayerHeights::plain)
  std::size_t fanTriangles = 0;  // macro fan triangles split (2 n - 1 triangles each)
  double firstHeightMin = 0.0, firstHeightMax = 0.0, firstHeightDeviation = 0.0;
};

// The heights a split keeps: `grown`, grownLayerHeights of the linear mesh the layer was grown
// in (whose vertex ids the macro mesh keeps); the columns whose top nodes are in `plain` are
// split at z unchanged (where an adjusted column made a thin cell invalid).
struct LayerHeights {
  std::vector<double> grown;
  std::set<std::int64_t> plain;
  // Wall vertex -> how much longer than the thickness its column was grown
  // (BoundaryLayerRecord::lengthened): its first level is then set and measured by the height
  // along each wall normal at the vertex, not along their mean.
  std::map<std::int64_t, double> lengthened;
  // Per node: at a wall vertex, its column's own levels (0 .. 1, as many as z: a given layer's,
  // LayerStacks::givenLevels), empty elsewhere. A column whose cell has them at every wall vertex
  // starts from their interpolation (the cell's wall weights) instead of z, unless it is plain;
  // none: z everywhere.
  std::vector<std::vector<double>> levels;
};

// `z`: the split coordinates (BoundaryLayerParameters::splitCoordinates). `cad` may be null
// (no projection). With `heights`, per-column levels and shifts as above. Throws MeshingError
// when a side quadrilateral or line does not follow the prisms' wall-to-top pairs.
Mesh splitBoundaryLayer(const Mesh& macro, const std::vector<double>& z, const CadModel* cad,
                        LayerSplitStats* stats = nullptr, const LayerHeights* heights = nullptr);

// Adds to heights.plain the columns (top nodes) of the macro cell that split element `element`
// (an index among the split mesh's elements, in block order: `layers` thin cells per macro cell,
// 2 layers - 1 per fan triangle) came from; nothing for an element outside the layer.
void keepColumnsPlain(const Mesh& macro, int layers, std::size_t element, LayerHeights& heights);

// Per node of a linear mesh with a macro layer: the distance from each wall vertex to its top
// vertex (the height grown there), NaN for every other node.
std::vector<double> grownLayerHeights(const Mesh& linear);

}  // namespace homesh
