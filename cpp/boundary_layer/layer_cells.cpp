#include "boundary_layer/layer_cells.hpp"

#include <cstddef>
#include <string>

#include "core/error.hpp"

namespace homesh {

bool isLayerCell(const Mesh& mesh, const ElementBlock& block) {
  return (mesh.dim == 3 && (block.type == CellType::Prism ||
                            (block.type == CellType::Hexahedron && block.layerCells))) ||
         (block.type == CellType::Quadrilateral && mesh.dim == 2);
}

std::array<double, 4> LayerShape::weights(double a, double b) const {
  switch (wall) {
    case CellType::Triangle:
      return {1.0 - a - b, a, b, 0.0};
    case CellType::Quadrilateral:
      return {(1.0 - a) * (1.0 - b), a * (1.0 - b), a * b, (1.0 - a) * b};
    default:
      return {1.0 - a, a, 0.0, 0.0};
  }
}

std::array<int, 4> LayerShape::latticeWeights(const LatticePoint& c, int p) const {
  switch (wall) {
    case CellType::Triangle:
      return {p - c[0] - c[1], c[0], c[1], 0};
    case CellType::Quadrilateral:
      return {(p - c[0]) * (p - c[1]), c[0] * (p - c[1]), c[0] * c[1], (p - c[0]) * c[1]};
    default:
      return {p - c[0], c[0], 0, 0};
  }
}

bool LayerShape::inWall(double a, double b, double tolerance) const {
  const bool inA = a >= -tolerance && a <= 1.0 + tolerance;
  switch (wall) {
    case CellType::Triangle:
      return inA && b >= -tolerance && a + b <= 1.0 + tolerance;
    case CellType::Quadrilateral:
      return inA && b >= -tolerance && b <= 1.0 + tolerance;
    default:
      return inA;
  }
}

LayerShape layerShape(CellType type) {
  switch (type) {
    case CellType::Prism:
      return {type, 3, 2, CellType::Triangle};
    case CellType::Hexahedron:
      return {type, 4, 2, CellType::Quadrilateral};
    case CellType::Quadrilateral:
      return {type, 2, 1, CellType::Line};
    default:
      throw ParameterError("a " + cellShortName(type) + " is no boundary-layer cell");
  }
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
