#include "core/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace homesh {

namespace {

// The unit normal of the straight triangle through the cell's first three nodes, zero when they
// are collinear. The edges are scaled to unit size first: coordinates near the largest double
// would overflow the cross product.
std::array<double, 3> unitNormal(const Mesh& mesh, const std::int64_t* v) {
  double a[3], c[3], scale = 0.0;
  for (int k = 0; k < 3; ++k) {
    a[k] = mesh.xyz[3 * v[1] + k] - mesh.xyz[3 * v[0] + k];
    c[k] = mesh.xyz[3 * v[2] + k] - mesh.xyz[3 * v[0] + k];
    scale = std::max({scale, std::abs(a[k]), std::abs(c[k])});
  }
  if (!(scale > 0.0) || !std::isfinite(scale)) return {0.0, 0.0, 0.0};
  for (int k = 0; k < 3; ++k) {
    a[k] /= scale;
    c[k] /= scale;
  }
  std::array<double, 3> n{a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2],
                          a[0] * c[1] - a[1] * c[0]};
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(length > 0.0)) return {0.0, 0.0, 0.0};
  for (double& x : n) x /= length;
  return n;
}

}  // namespace

std::int64_t Mesh::addNode(const double p[3], int cadDim, int cadIndex, double param0,
                           double param1) {
  const auto id = static_cast<std::int64_t>(numNodes());
  xyz.insert(xyz.end(), p, p + 3);
  nodeCadDim.push_back(static_cast<std::uint8_t>(cadDim));
  nodeCadIndex.push_back(cadIndex);
  nodeCadParam.push_back(param0);
  nodeCadParam.push_back(param1);
  return id;
}

std::size_t Mesh::numElements() const {
  std::size_t n = 0;
  for (const auto& block : blocks)
    if (cellDimension(block.type) == dim) n += block.count();
  return n;
}

std::array<double, 3> Mesh::cellNormal(const std::int64_t* cell) const {
  if (!isSurface()) return planeNormal;
  return unitNormal(*this, cell);
}

namespace {

bool isZero(const std::array<double, 3>& n) {
  return n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
}

// Whether every node of a cell lies within `tolerance` times their bounding-box diagonal of one
// plane with unit normal `normal` (nodes no cell uses do not count).
bool nodesInPlane(const Mesh& mesh, const std::array<double, 3>& normal, double tolerance) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo = kInf, hi = -kInf;
  std::array<double, 3> boxLo{kInf, kInf, kInf}, boxHi{-kInf, -kInf, -kInf};
  for (const ElementBlock& b : mesh.blocks)
    for (const std::int64_t i : b.nodes) {
      double h = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double x = mesh.xyz[3 * i + k];
        h += normal[k] * x;
        boxLo[k] = std::min(boxLo[k], x);
        boxHi[k] = std::max(boxHi[k], x);
      }
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
  if (!(hi >= lo)) return true;  // no cell
  double diagonal = 0.0;
  for (int k = 0; k < 3; ++k) diagonal += (boxHi[k] - boxLo[k]) * (boxHi[k] - boxLo[k]);
  return hi - lo <= tolerance * std::sqrt(diagonal);
}

}  // namespace

std::optional<std::array<double, 3>> planeOfCells(const Mesh& mesh, double tolerance) {
  std::array<double, 3> sum{0.0, 0.0, 0.0}, first{0.0, 0.0, 0.0};
  for (const ElementBlock& b : mesh.blocks) {
    if (cellDimension(b.type) != 2) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::array<double, 3> n = unitNormal(mesh, b.element(e));
      if (isZero(first)) first = n;
      for (int k = 0; k < 3; ++k) sum[k] += n[k];
    }
  }
  if (isZero(first)) return std::nullopt;
  const double length = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
  // (A sum far below one cell's: the cells face both ways, a closed shell perhaps.)
  std::array<double, 3> normal = first;
  if (length > 1e-6)
    for (int k = 0; k < 3; ++k) normal[k] = sum[k] / length;
  if (nodesInPlane(mesh, normal, tolerance)) return normal;
  return std::array<double, 3>{0.0, 0.0, 0.0};
}

void Mesh::checkConsistency() const {
  const std::size_t n = numNodes();
  if (xyz.size() != 3 * n || nodeCadDim.size() != n || nodeCadIndex.size() != n ||
      nodeCadParam.size() != 2 * n)
    throw Error("mesh: node arrays have inconsistent sizes");
  for (const auto& block : blocks) {
    if (block.nodes.size() != block.count() * static_cast<std::size_t>(block.nodesPerElement()))
      throw Error("mesh: block of " + cellShortName(block.type) +
                  " has a connectivity size that is not a multiple of its node count");
    for (const auto id : block.nodes)
      if (id < 0 || static_cast<std::size_t>(id) >= n)
        throw Error("mesh: element refers to node " + std::to_string(id) + " but the mesh has " +
                    std::to_string(n) + " nodes");
  }
}

std::vector<std::pair<const ElementBlock*, std::size_t>> elementsOf(const Mesh& mesh) {
  std::vector<std::pair<const ElementBlock*, std::size_t>> list;
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == mesh.dim)
      for (std::size_t e = 0; e < b.count(); ++e) list.emplace_back(&b, e);
  return list;
}

void compactNodes(Mesh& mesh) {
  std::vector<std::int64_t> newId(mesh.numNodes(), -1);
  for (const ElementBlock& block : mesh.blocks)
    for (const std::int64_t id : block.nodes) newId[id] = 0;
  std::int64_t next = 0;
  for (std::size_t i = 0; i < newId.size(); ++i) {
    if (newId[i] < 0) continue;
    newId[i] = next;
    const auto j = static_cast<std::size_t>(next++);
    for (int c = 0; c < 3; ++c) mesh.xyz[3 * j + c] = mesh.xyz[3 * i + c];
    mesh.nodeCadDim[j] = mesh.nodeCadDim[i];
    mesh.nodeCadIndex[j] = mesh.nodeCadIndex[i];
    mesh.nodeCadParam[2 * j] = mesh.nodeCadParam[2 * i];
    mesh.nodeCadParam[2 * j + 1] = mesh.nodeCadParam[2 * i + 1];
  }
  const auto n = static_cast<std::size_t>(next);
  mesh.xyz.resize(3 * n);
  mesh.nodeCadDim.resize(n);
  mesh.nodeCadIndex.resize(n);
  mesh.nodeCadParam.resize(2 * n);
  for (ElementBlock& block : mesh.blocks)
    for (std::int64_t& id : block.nodes) id = newId[id];
}

}  // namespace homesh
