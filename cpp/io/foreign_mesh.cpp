#include "io/foreign_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/error.hpp"
#include "element/element_measure.hpp"
#include "element/node_ordering.hpp"

namespace homesh {
namespace {

// "the 1 tetrahedron", "all 844 tetrahedra".
std::string countedName(CellType type, std::size_t count) {
  static const std::pair<CellType, std::pair<const char*, const char*>> kNames[] = {
      {CellType::Tetrahedron, {"tetrahedron", "tetrahedra"}},
      {CellType::Prism, {"prism", "prisms"}},
      {CellType::Hexahedron, {"hexahedron", "hexahedra"}},
      {CellType::Pyramid, {"pyramid", "pyramids"}}};
  for (const auto& [t, names] : kNames)
    if (t == type)
      return count == 1 ? std::string("the 1 ") + names.first
                        : "all " + std::to_string(count) + " " + names.second;
  return std::to_string(count) + " " + cellShortName(type);
}

Eigen::Vector3d point(const std::vector<double>& xyz, std::int64_t id) {
  const auto i = static_cast<std::size_t>(id);
  return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
}

NodeCoordinates gather(const Mesh& mesh, const std::int64_t* nodes, int n) {
  NodeCoordinates x(n, 3);
  for (int i = 0; i < n; ++i) x.row(i) = point(mesh.xyz, nodes[i]).transpose();
  return x;
}

// Reverses the handedness of every cell of a block whose cells all have negative volume.
void orientSolids(Mesh& mesh, const std::string& path, std::vector<std::string>* notes) {
  for (ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) != 3 || block.count() == 0) continue;
    const int n = block.nodesPerElement();
    bool allNegative = true;
    for (std::size_t e = 0; e < block.count() && allNegative; ++e)
      allNegative =
          elementMeasure(block.type, block.order, gather(mesh, block.element(e), n), nullptr) < 0.0;
    if (!allNegative) continue;
    const std::vector<int> perm = mirrorPermutation(block.type, block.order);
    std::vector<std::int64_t> cell(static_cast<std::size_t>(n));
    for (std::size_t e = 0; e < block.count(); ++e) {
      std::int64_t* nodes = block.nodes.data() + e * static_cast<std::size_t>(n);
      for (int k = 0; k < n; ++k) cell[static_cast<std::size_t>(k)] = nodes[perm[k]];
      std::copy(cell.begin(), cell.end(), nodes);
    }
    if (notes != nullptr)
      notes->push_back("'" + path + "': " + countedName(block.type, block.count()) +
                       " of the file " + (block.count() == 1 ? "has" : "have") +
                       " negative volume in its node order (a left-handed numbering): read "
                       "with the orientation reversed");
  }
}

// The plane normal most 2D elements agree with; zero (a surface mesh) when the 2D cells' nodes
// leave that plane.
void setPlane(Mesh& mesh, const std::string& path) {
  // Files of single-precision coordinates (FreeCAD's VTK) carry 7 digits.
  const auto normal = planeOfCells(mesh, 1e-5);
  if (!normal)
    throw IoError("'" + path + "': its 2D elements are degenerate (no element spans a plane)");
  mesh.planeNormal = *normal;
}

}  // namespace

void ForeignMesh::addCell(CellType type, int order, const std::int64_t* nodes,
                          std::int32_t entity) {
  auto it = std::find_if(blocks.begin(), blocks.end(),
                         [&](const ElementBlock& b) { return b.type == type && b.order == order; });
  if (it == blocks.end()) {
    ElementBlock block;
    block.type = type;
    block.order = order;
    blocks.push_back(block);
    it = blocks.end() - 1;
  }
  it->nodes.insert(it->nodes.end(), nodes, nodes + cellNumNodes(type, order));
  it->entity.push_back(entity);
}

std::string quoteExcerpt(std::string_view text, std::size_t limit) {
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < limit; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += c >= 32 && c < 127 ? static_cast<char>(c) : '?';
  }
  return out + (text.size() > limit ? "...'" : "'");
}

Mesh assembleForeignMesh(ForeignMesh raw, const std::string& path,
                         std::vector<std::string>* notes) {
  Mesh mesh;
  int dim = 0;
  for (const ElementBlock& b : raw.blocks) dim = std::max(dim, cellDimension(b.type));
  if (dim < 2) throw IoError("'" + path + "' contains no 2D or 3D elements");
  for (const ElementBlock& b : raw.blocks)
    if (b.order != raw.blocks.front().order)
      throw IoError("'" + path + "' mixes elements of orders " +
                    std::to_string(raw.blocks.front().order) + " and " + std::to_string(b.order) +
                    ", which HOMesh does not support");
  mesh.dim = dim;
  mesh.order = raw.blocks.front().order;
  mesh.blocks = std::move(raw.blocks);
  std::stable_sort(mesh.blocks.begin(), mesh.blocks.end(),
                   [](const ElementBlock& a, const ElementBlock& b) {
                     return cellDimension(a.type) > cellDimension(b.type);
                   });
  mesh.xyz = std::move(raw.xyz);
  const std::size_t n = mesh.numNodes();
  // Without CAD, a node lies on the lowest-dimensional cell that holds it (as MSH 2.2 files).
  mesh.nodeCadDim.assign(n, static_cast<std::uint8_t>(dim));
  mesh.nodeCadIndex.assign(n, 0);
  mesh.nodeCadParam.assign(2 * n, std::numeric_limits<double>::quiet_NaN());
  for (const ElementBlock& b : mesh.blocks) {
    const auto d = static_cast<std::uint8_t>(cellDimension(b.type));
    for (std::size_t e = 0; e < b.count(); ++e)
      for (int k = 0; k < b.nodesPerElement(); ++k) {
        const auto id = static_cast<std::size_t>(b.element(e)[k]);
        if (d <= mesh.nodeCadDim[id]) {
          mesh.nodeCadDim[id] = d;
          mesh.nodeCadIndex[id] = b.entity[e];
        }
      }
  }
  mesh.checkConsistency();
  if (dim == 3)
    orientSolids(mesh, path, notes);
  else
    setPlane(mesh, path);
  return mesh;
}

}  // namespace homesh
