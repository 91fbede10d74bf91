// The boundary layer of a linear mesh another tool made, recognised and agglomerated (issue 47,
// DESIGN.md section 8 run backwards): the stacks of prisms and hexahedra that stand on the wall,
// each one macro cell, so that curving and optimisation act on a well-shaped cell, and the levels
// to split them back into exactly the given layers (layer_split.hpp) once they are curved.
//
// A prism stack is a column of prisms from a wall (a boundary triangle that is a triangular face
// of a prism) outwards, each sharing its far triangle with the next, ending where the far triangle
// is a face of a tetrahedron or pyramid. A hexahedral stack is the same on a boundary
// quadrilateral, through opposite faces of hexahedra, ending at a pyramid. Every prism must be in
// one stack; a hexahedron's faces are all quadrilaterals, so a climb from a boundary face that
// runs along the layer (from its side on the CAD) or through a far-field block to the boundary
// again is no stack, and the hexahedra in no stack stay as given. A stack's nodes form columns,
// one per wall vertex: the node at each level above it. The macro cell is the wall face and the
// stack's last face; the boundary quadrilaterals of the stacks' sides (on the CAD faces the layer
// meets) and the lines climbing along CAD curves merge alike, so every node inside the layer goes.
// The levels are each column's node distances, cumulative along the column and divided by its
// length; the split keeps each column's own levels (interpolated between the wall vertices inside
// a cell), with its first level set by its own first-layer height.
#pragma once

#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

// What was recognised (the report's "given_layers").
struct LayerStacksRecord {
  int layers = 0;               // cells per stack, the same in every stack
  std::size_t stacks = 0;       // macro cells
  std::size_t hexStacks = 0;    // of which macro hexahedra
  std::size_t columns = 0;      // wall vertices
  std::size_t sidesMerged = 0;  // macro side quadrilaterals
  std::vector<double> levels;   // 0 = z_0 < ... < z_layers = 1: the mean of the columns'
  double levelSpread = 0.0;     // largest |a column's level - the mean|
  double firstHeightMin = 0.0, firstHeightMax = 0.0;  // the given first layer's heights
  std::set<int> walls;                                // the CAD faces the stacks stand on
};

struct LayerStacks {
  // The mesh with each stack one macro cell (the prisms in one block where the first prism block
  // was, the hexahedra in one block marked ElementBlock::layerCells where the first hexahedron
  // block was; their walls and tops as layer_cells.hpp says), the sides merged and the layer's
  // inner nodes dropped; every other cell as given.
  Mesh macro;
  LayerStacksRecord record;
  // Per node of `macro`: at a wall vertex, the height of its column's first layer (the distance
  // to the next node up); NaN elsewhere.
  std::vector<double> firstHeights;
  // Per node of `macro`: at a wall vertex, its column's levels (its node distances, cumulative
  // and divided by its length: 0 .. 1, layers + 1 of them); empty elsewhere (LayerHeights::levels).
  std::vector<std::vector<double>> givenLevels;
  // Why the hexahedra's stacks were left out (they then stay as given while the prisms' stacks
  // are agglomerated); empty when they were not.
  std::string hexahedraLeftOut;
};

// `mesh`: as classifyOnCad leaves it (cells positive, the boundary's triangles, quadrilaterals
// and lines in blocks of their own with their CAD entities). Returns nothing, with the reason
// in `why`, when it holds no stack (why empty when it holds no prisms nor hexahedral stacks) or
// its prisms are not such stacks: a prism with both triangles on the boundary, one in no stack or
// in two, stacks of different heights, a node inside the layer that another cell uses. Where the
// stacks fail only with the hexahedra's (a hexahedron in two, their heights not the prisms'),
// the prisms' are taken alone and hexahedraLeftOut says why. `hexahedra` false: the prisms'
// stacks only (the hexahedra stay as given).
std::optional<LayerStacks> recogniseLayerStacks(const Mesh& mesh, std::string& why,
                                                bool hexahedra = true);

}  // namespace homesh
