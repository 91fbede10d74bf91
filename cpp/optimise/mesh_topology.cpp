#include "optimise/mesh_topology.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>

#include "core/error.hpp"
#include "element/node_ordering.hpp"

namespace homesh {
namespace {

// A facet of the reference lattice: the points with c . lattice == value * P.
struct FacetPlane {
  std::array<int, 3> c;
  int value;
};

std::vector<FacetPlane> facetPlanes(CellType type) {
  switch (type) {
    case CellType::Triangle:
      return {{{0, 1, 0}, 0}, {{1, 0, 0}, 0}, {{1, 1, 0}, 1}};
    case CellType::Quadrilateral:
      return {{{1, 0, 0}, 0}, {{1, 0, 0}, 1}, {{0, 1, 0}, 0}, {{0, 1, 0}, 1}};
    case CellType::Tetrahedron:
      return {{{1, 0, 0}, 0}, {{0, 1, 0}, 0}, {{0, 0, 1}, 0}, {{1, 1, 1}, 1}};
    case CellType::Prism:
      return {{{1, 0, 0}, 0}, {{0, 1, 0}, 0}, {{1, 1, 0}, 1}, {{0, 0, 1}, 0}, {{0, 0, 1}, 1}};
    case CellType::Hexahedron:
      return {{{1, 0, 0}, 0}, {{1, 0, 0}, 1}, {{0, 1, 0}, 0},
              {{0, 1, 0}, 1}, {{0, 0, 1}, 0}, {{0, 0, 1}, 1}};
    case CellType::Pyramid:  // the base, then the triangles (apex above the base's corner 0)
      return {{{0, 0, 1}, 0}, {{0, 1, 0}, 0}, {{1, 0, 0}, 0}, {{1, 0, 1}, 1}, {{0, 1, 1}, 1}};
    default:
      throw ParameterError("no facet topology for " + cellShortName(type) + " cells");
  }
}

// Local node indices on each facet, and the local corners (vertices) among them.
struct FacetNodes {
  std::vector<std::vector<int>> nodes, corners;
};

FacetNodes facetNodes(CellType type, int order) {
  const std::vector<LatticePoint> lattice = latticeOrder(type, order, NodeConvention::Gmsh);
  const int nv = cellNumVertices(type);
  FacetNodes out;
  for (const FacetPlane& f : facetPlanes(type)) {
    std::vector<int> nodes, corners;
    for (int i = 0; i < static_cast<int>(lattice.size()); ++i) {
      const LatticePoint& p = lattice[i];
      if (f.c[0] * p[0] + f.c[1] * p[1] + f.c[2] * p[2] != f.value * order) continue;
      nodes.push_back(i);
      if (i < nv) corners.push_back(i);
    }
    out.nodes.push_back(std::move(nodes));
    out.corners.push_back(std::move(corners));
  }
  return out;
}

}  // namespace

std::vector<char> boundaryNodes(std::size_t numNodes,
                                const std::vector<const ElementBlock*>& blocks, bool interfaces) {
  using Key = std::array<std::int64_t, 4>;
  struct Use {
    int count = 0;
    std::size_t block = 0, element = 0;
    int facet = 0;
    bool interface = false;  // between elements of different entities
  };
  std::map<Key, Use> facets;
  std::vector<FacetNodes> local;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const ElementBlock& cells = *blocks[b];
    local.push_back(facetNodes(cells.type, cells.order));
    const FacetNodes& fn = local.back();
    for (std::size_t e = 0; e < cells.count(); ++e) {
      const std::int64_t* v = cells.element(e);
      for (int f = 0; f < static_cast<int>(fn.corners.size()); ++f) {
        Key key{-1, -1, -1, -1};
        for (std::size_t k = 0; k < fn.corners[f].size(); ++k) key[k] = v[fn.corners[f][k]];
        std::sort(key.begin(), key.begin() + static_cast<std::ptrdiff_t>(fn.corners[f].size()));
        Use& use = facets[key];
        if (++use.count == 1)
          use = {1, b, e, f, false};
        else if (blocks[use.block]->entity[use.element] != cells.entity[e])
          use.interface = true;
      }
    }
  }
  std::vector<char> boundary(numNodes, 0);
  for (const auto& [key, use] : facets) {
    if (use.count != 1 && !(interfaces && use.interface)) continue;
    const std::int64_t* v = blocks[use.block]->element(use.element);
    for (const int i : local[use.block].nodes[use.facet]) boundary[v[i]] = 1;
  }
  return boundary;
}

}  // namespace homesh
