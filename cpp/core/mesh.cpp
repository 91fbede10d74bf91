#include "core/mesh.hpp"

#include <string>

#include "core/error.hpp"

namespace homesh {

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
