#include "linear/edge_split.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace homesh {
namespace {

Eigen::Vector3d nodePoint(const Mesh& mesh, std::int64_t i) {
  return {mesh.xyz[3 * i], mesh.xyz[3 * i + 1], mesh.xyz[3 * i + 2]};
}

MeshEdge ordered(std::int64_t a, std::int64_t b) {
  return a < b ? MeshEdge{a, b} : MeshEdge{b, a};
}

double simplexVolumeAt(const Mesh& mesh, const std::array<Eigen::Vector3d, 4>& p) {
  if (mesh.dim == 3) return (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]) / 6.0;
  const Eigen::Vector3d normal(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
  return 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).dot(normal);
}

}  // namespace

std::set<MeshEdge> boundaryEdges(const Mesh& mesh) {
  std::set<MeshEdge> edges;
  for (const ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) >= mesh.dim) continue;
    const int nv = cellNumVertices(block.type);
    if (nv < 2) continue;
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* v = block.element(e);
      if (nv == 2) {
        edges.insert(ordered(v[0], v[1]));
      } else {
        for (int k = 0; k < nv; ++k) edges.insert(ordered(v[k], v[(k + 1) % nv]));
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

bool splitInteriorEdge(Mesh& mesh, const MeshEdge& edge, const Eigen::Vector3d& point) {
  if (mesh.order != 1) throw ParameterError("edge splitting needs a linear mesh");
  const CellType cellType = mesh.dim == 3 ? CellType::Tetrahedron : CellType::Triangle;
  const auto block = std::find_if(mesh.blocks.begin(), mesh.blocks.end(),
                                  [&](const ElementBlock& b) { return b.type == cellType; });
  if (block == mesh.blocks.end())
    throw ParameterError("edge splitting needs a mesh of " + cellShortName(cellType) + "s");
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == mesh.dim && b.type != cellType)
      throw ParameterError("edge splitting supports simplex meshes only, not " +
                           cellShortName(b.type) + "s");
  const std::string name =
      "edge (" + std::to_string(edge[0]) + ", " + std::to_string(edge[1]) + ")";
  if (boundaryEdges(mesh).count(ordered(edge[0], edge[1])) > 0)
    throw ParameterError(name + " lies on a boundary cell: only interior edges are split");

  const int nv = mesh.dim + 1;
  // The cells around the edge and, per cell, the local positions of the edge's two ends.
  struct Around {
    std::size_t cell;
    int a, b;
  };
  std::vector<Around> around;
  for (std::size_t e = 0; e < block->count(); ++e) {
    const std::int64_t* v = block->element(e);
    int a = -1, b = -1;
    for (int k = 0; k < nv; ++k) {
      if (v[k] == edge[0]) a = k;
      if (v[k] == edge[1]) b = k;
    }
    if (a >= 0 && b >= 0) around.push_back({e, a, b});
  }
  if (around.empty()) throw ParameterError(name + " is not an edge of the mesh's cells");

  // Every half must stay positive before the mesh changes.
  for (const Around& c : around) {
    const std::int64_t* v = block->element(c.cell);
    std::array<Eigen::Vector3d, 4> p;
    for (int k = 0; k < nv; ++k) p[static_cast<std::size_t>(k)] = nodePoint(mesh, v[k]);
    for (const int replaced : {c.a, c.b}) {
      std::array<Eigen::Vector3d, 4> half = p;
      half[static_cast<std::size_t>(replaced)] = point;
      if (!(simplexVolumeAt(mesh, half) > 0.0)) return false;
    }
  }

  const std::int32_t entity = block->entity[around.front().cell];
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double xyz[3] = {point.x(), point.y(), point.z()};
  const std::int64_t m = mesh.addNode(xyz, mesh.dim, entity, nan, nan);
  for (const Around& c : around) {
    const auto first = c.cell * static_cast<std::size_t>(nv);
    std::vector<std::int64_t> second(
        block->nodes.begin() + static_cast<std::ptrdiff_t>(first),
        block->nodes.begin() + static_cast<std::ptrdiff_t>(first) + nv);
    block->nodes[first + static_cast<std::size_t>(c.b)] = m;  // keeps a
    second[static_cast<std::size_t>(c.a)] = m;                // keeps b
    block->nodes.insert(block->nodes.end(), second.begin(), second.end());
    block->entity.push_back(block->entity[c.cell]);
  }
  mesh.checkConsistency();
  return true;
}

}  // namespace homesh
