#include "linear/edge_split.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace homesh {
namespace {

double simplexVolumeAt(const Mesh& mesh, const std::array<Eigen::Vector3d, 4>& p) {
  if (mesh.dim == 3) return (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]) / 6.0;
  const Eigen::Vector3d normal(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
  return 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).dot(normal);
}

}  // namespace

ElementBlock* tetrahedronBlock(Mesh& mesh, const std::string& what) {
  if (mesh.dim != 3 || mesh.order != 1)
    throw ParameterError(what + " need a linear volume mesh (order 1, 3D)");
  ElementBlock* block = nullptr;
  for (ElementBlock& b : mesh.blocks) {
    if (cellDimension(b.type) != 3) continue;
    if (b.type != CellType::Tetrahedron || block != nullptr)
      throw ParameterError(what + " need the cells in one block of tetrahedra");
    block = &b;
  }
  return block;
}

std::set<MeshEdge> boundaryEdges(const Mesh& mesh) {
  std::set<MeshEdge> edges;
  for (const ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) >= mesh.dim) continue;
    const int nv = cellNumVertices(block.type);
    if (nv < 2) continue;
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* v = block.element(e);
      if (nv == 2) {
        edges.insert(meshEdge(v[0], v[1]));
      } else {
        for (int k = 0; k < nv; ++k) edges.insert(meshEdge(v[k], v[(k + 1) % nv]));
      }
    }
  }
  return edges;
}

double simplexVolume(const Mesh& mesh, const std::int64_t* nodes) {
  std::array<Eigen::Vector3d, 4> p;
  for (int k = 0; k <= mesh.dim; ++k) p[static_cast<std::size_t>(k)] = nodePoint(mesh, nodes[k]);
  return simplexVolumeAt(mesh, p);
}

bool splitEdge(Mesh& mesh, const MeshEdge& edge, const SplitNode& node) {
  if (mesh.order != 1) throw ParameterError("edge splitting needs a linear mesh");
  const CellType cellType = mesh.dim == 3 ? CellType::Tetrahedron : CellType::Triangle;
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == mesh.dim && b.type != cellType)
      throw ParameterError("edge splitting supports simplex meshes only, not " +
                           cellShortName(b.type) + "s");
  const std::string name =
      "edge (" + std::to_string(edge[0]) + ", " + std::to_string(edge[1]) + ")";

  // Per block, the cells with both ends and the local positions of the ends.
  struct Around {
    std::size_t cell;
    int a, b;
  };
  std::vector<std::vector<Around>> around(mesh.blocks.size());
  std::int32_t entity = 0;
  bool hasCell = false;
  for (std::size_t k = 0; k < mesh.blocks.size(); ++k) {
    const ElementBlock& block = mesh.blocks[k];
    const int nv = cellNumVertices(block.type);
    if (nv < 2) continue;
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* v = block.element(e);
      int a = -1, b = -1;
      for (int i = 0; i < nv; ++i) {
        if (v[i] == edge[0]) a = i;
        if (v[i] == edge[1]) b = i;
      }
      if (a < 0 || b < 0) continue;
      around[k].push_back({e, a, b});
      if (block.type == cellType) {
        hasCell = true;
        entity = block.entity[e];
        // Both halves must stay positive before the mesh changes.
        std::array<Eigen::Vector3d, 4> p;
        for (int i = 0; i < nv; ++i) p[static_cast<std::size_t>(i)] = nodePoint(mesh, v[i]);
        for (const int replaced : {a, b}) {
          std::array<Eigen::Vector3d, 4> half = p;
          half[static_cast<std::size_t>(replaced)] = node.point;
          if (!(simplexVolumeAt(mesh, half) > 0.0)) return false;
        }
      }
    }
  }
  if (!hasCell) throw ParameterError(name + " is not an edge of the mesh's cells");

  const double xyz[3] = {node.point.x(), node.point.y(), node.point.z()};
  const std::int64_t m = mesh.addNode(xyz, node.cadDim, node.cadIndex > 0 ? node.cadIndex : entity,
                                      node.param0, node.param1);
  for (std::size_t k = 0; k < mesh.blocks.size(); ++k) {
    ElementBlock& block = mesh.blocks[k];
    const auto nv = static_cast<std::size_t>(cellNumVertices(block.type));
    for (const Around& c : around[k]) {
      const std::size_t first = c.cell * nv;
      std::vector<std::int64_t> second(
          block.nodes.begin() + static_cast<std::ptrdiff_t>(first),
          block.nodes.begin() + static_cast<std::ptrdiff_t>(first + nv));
      block.nodes[first + static_cast<std::size_t>(c.b)] = m;  // keeps a
      second[static_cast<std::size_t>(c.a)] = m;               // keeps b
      block.nodes.insert(block.nodes.end(), second.begin(), second.end());
      block.entity.push_back(block.entity[c.cell]);
    }
  }
  mesh.checkConsistency();
  return true;
}

bool splitInteriorEdge(Mesh& mesh, const MeshEdge& edge, const Eigen::Vector3d& point) {
  if (boundaryEdges(mesh).count(meshEdge(edge[0], edge[1])) > 0)
    throw ParameterError("edge (" + std::to_string(edge[0]) + ", " + std::to_string(edge[1]) +
                         ") lies on a boundary cell: only interior edges are split");
  SplitNode node;
  node.point = point;
  node.cadDim = mesh.dim;
  return splitEdge(mesh, edge, node);
}

}  // namespace homesh
