#include "boundary_layer/layer_cells.hpp"

#include <cstddef>

namespace homesh {

bool isLayerCell(const Mesh& mesh, const ElementBlock& block) {
  return (block.type == CellType::Prism && mesh.dim == 3) ||
         (block.type == CellType::Quadrilateral && mesh.dim == 2);
}

bool mayHoldFans(const Mesh& mesh, const ElementBlock& block) {
  return mesh.dim == 2 && block.type == CellType::Triangle;
}

std::set<std::int64_t> layerWall(const Mesh& mesh) {
  std::set<std::int64_t> wall;
  for (const ElementBlock& b : mesh.blocks)
    if (isLayerCell(mesh, b) && b.type == CellType::Quadrilateral)
      for (std::size_t e = 0; e < b.count(); ++e) wall.insert({b.element(e)[0], b.element(e)[1]});
  return wall;
}

std::vector<char> fanTriangles(const ElementBlock& block, const std::set<std::int64_t>& wall) {
  std::vector<char> fan(block.count(), 0);
  if (wall.empty()) return fan;
  for (std::size_t e = 0; e < block.count(); ++e)
    for (int k = 0; k < 3; ++k)
      if (wall.count(block.element(e)[k]) != 0) fan[e] = 1;
  return fan;
}

std::vector<char> layerFanTriangles(const Mesh& mesh, const ElementBlock& block) {
  if (mayHoldFans(mesh, block)) return fanTriangles(block, layerWall(mesh));
  std::vector<char> none(block.count(), 0);  // (a braced list would hold two chars)
  return none;
}

std::map<LatticePoint, int> latticeIndex(const ReferenceElement& ref) {
  std::map<LatticePoint, int> index;
  for (int r = 0; r < ref.numNodes(); ++r) index[ref.lattice()[static_cast<std::size_t>(r)]] = r;
  return index;
}

}  // namespace homesh
