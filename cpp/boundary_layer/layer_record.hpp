// What growing a boundary layer made: the macro heights, where it had to be grown thinner than
// asked, its cells, and how far the optimiser later let its top move (BoundaryLayerRecord, the
// report's "boundary_layer").
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "boundary_layer/layer_parameters.hpp"

namespace homesh {

// How much of one layer face (2D: curve) got the height asked: its columns (one per wall node),
// how many were grown thinner, the smallest share grown and where.
struct LayerShrink {
  int face = 0;
  std::array<double, 3> where{};  // the wall node with the smallest factor (when nodes > 0)
  double factor = 1.0;            // grown height / asked thickness there
  std::size_t nodes = 0;          // wall nodes of the face whose height was reduced
  std::size_t columns = 0;        // wall nodes of the face
  // The narrowest gap that held a column of the face down (the layer keeps 2.5 of its heights
  // clear of the wall across its normal): its width along the normal, the wall's face (2D:
  // curve; 0: no column was held down so), where, the thickness asked there and the height it
  // left room for.
  struct Gap {
    double width = 0.0;
    int across = 0;
    std::array<double, 3> where{};
    double asked = 0.0, room = 0.0;
  } gap;
  // Share of the face's columns grown to the height asked.
  double fullHeight() const {
    return columns == 0 ? 1.0 : 1.0 - static_cast<double>(nodes) / static_cast<double>(columns);
  }
};

// How far the optimiser let a macro layer's top move (BoundaryLayerRecord::release).
enum class LayerRelease { None, Parallel, Sides, Free };
// "none", "parallel", "parallel_and_sides", "free"
const char* layerReleaseName(LayerRelease release);

struct BoundaryLayerRecord {
  BoundaryLayerParameters parameters;
  double thicknessMin = 0, thicknessMax = 0;  // macro heights grown at the wall nodes
  // (The first split layer's height, as measured, is the split's: LayerSplitStats.)
  std::vector<LayerShrink> faces;  // every layer face (2D: curve), in order
  // The faces where the layer was grown thinner than asked somewhere.
  std::vector<LayerShrink> shrunk() const;
  std::size_t cells = 0;  // macro cells: prisms (3D), quadrilaterals (2D)
  // 2D: triangles of the fans at sharp convex corners of the wall (a column per wall curve's
  // normal there and between them, instead of one along the bisector): part of the layer, split
  // into thin triangles (layer_split.hpp).
  std::size_t fanTriangles = 0;
  // 2D: wall segments halved before the growth, where the curve turns by more than 30 degrees
  // along one.
  std::size_t wallSplits = 0;
  std::size_t sideQuadrilaterals = 0, wallNodes = 0;
  // 3D: wall node (of the grown linear mesh) -> how many times the thickness its column was
  // grown along its direction, where more than 1: at a sharp edge or corner the column leans
  // between the layer faces and is lengthened so that its top lies at the thickness from each
  // (the split then measures its first level the same way: LayerHeights::lengthened).
  std::map<std::int64_t, double> lengthened;
  // 3D: the wall nodes among them where layer faces meet at a sharp edge or corner (their columns
  // lean between the faces by design; blendLayerInteriors raises the top beside them along the
  // wall's normal). The others were lengthened for leaning from their face's normal.
  std::set<std::int64_t> sharpColumns;
  int shrinkPasses = 0;
  // The optimiser keeps the macro layer as grown unless elements stay invalid; then it lets the
  // layer's top move around them, first parallel to the wall (the heights stay; its nodes on
  // the layer's side faces fixed, then sliding on them), then, if still needed, freely (the split
  // then sets its levels per column so that the first layer keeps its height where it can; the
  // outer layers absorb the change).
  LayerRelease release = LayerRelease::None;
  double seconds = 0.0;
};

}  // namespace homesh
