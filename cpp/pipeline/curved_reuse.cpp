#include "pipeline/curved_reuse.hpp"

#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>
#include <utility>

#include "core/error.hpp"

namespace homesh {
namespace {

// A cell's type and its vertex coordinates in order, as raw bytes: equal keys mean the same
// cell at the same place, bit for bit.
std::string cellKey(const Mesh& mesh, const ElementBlock& b, std::size_t e) {
  const int nv = cellNumVertices(b.type);
  std::string key(sizeof(int) + sizeof(double) * 3 * static_cast<std::size_t>(nv), '\0');
  const int type = static_cast<int>(b.type);
  std::memcpy(key.data(), &type, sizeof(int));
  const std::int64_t* v = b.element(e);
  for (int k = 0; k < nv; ++k)
    std::memcpy(key.data() + sizeof(int) + sizeof(double) * 3 * static_cast<std::size_t>(k),
                &mesh.xyz[3 * v[k]], 3 * sizeof(double));
  return key;
}

void checkPair(const Mesh& linear, const Mesh& curved, const char* which) {
  if (linear.numElements() != curved.numElements())
    throw ParameterError(std::string(which) + " linear mesh has " +
                         std::to_string(linear.numElements()) + " elements, its curved mesh " +
                         std::to_string(curved.numElements()));
}

}  // namespace

CurvedReuse reuseCurvedNodes(const Mesh& oldLinear, const Mesh& oldCurved, const Mesh& newLinear,
                             Mesh& newCurved) {
  checkPair(oldLinear, oldCurved, "the old");
  checkPair(newLinear, newCurved, "the new");
  if (oldCurved.order != newCurved.order)
    throw ParameterError("the curved meshes have orders " + std::to_string(oldCurved.order) +
                         " and " + std::to_string(newCurved.order));
  const auto oldCells = elementsOf(oldLinear), oldElements = elementsOf(oldCurved);
  const auto newCells = elementsOf(newLinear), newElements = elementsOf(newCurved);

  std::unordered_map<std::string, std::size_t> where;
  where.reserve(oldCells.size());
  for (std::size_t i = 0; i < oldCells.size(); ++i)
    where.emplace(cellKey(oldLinear, *oldCells[i].first, oldCells[i].second), i);

  CurvedReuse result;
  result.fresh.assign(newCells.size(), 1);
  result.source.assign(newCells.size(), -1);
  for (std::size_t i = 0; i < newCells.size(); ++i) {
    const auto found = where.find(cellKey(newLinear, *newCells[i].first, newCells[i].second));
    if (found == where.end()) continue;
    const auto& [ob, oe] = oldElements[found->second];
    const auto& [nb, ne] = newElements[i];
    if (ob->type != nb->type) continue;
    const std::int64_t* from = ob->element(oe);
    const std::int64_t* to = nb->element(ne);
    const int n = nb->nodesPerElement();
    bool same = true;  // every node on the same CAD entity (it is the same element)
    for (int k = 0; k < n && same; ++k)
      same = oldCurved.nodeCadDim[from[k]] == newCurved.nodeCadDim[to[k]] &&
             oldCurved.nodeCadIndex[from[k]] == newCurved.nodeCadIndex[to[k]];
    if (!same) continue;
    for (int k = 0; k < n; ++k) {
      for (int c = 0; c < 3; ++c) newCurved.xyz[3 * to[k] + c] = oldCurved.xyz[3 * from[k] + c];
      for (int c = 0; c < 2; ++c)
        newCurved.nodeCadParam[2 * to[k] + c] = oldCurved.nodeCadParam[2 * from[k] + c];
    }
    result.fresh[i] = 0;
    result.source[i] = static_cast<std::int64_t>(found->second);
    ++result.reused;
  }
  return result;
}

}  // namespace homesh
