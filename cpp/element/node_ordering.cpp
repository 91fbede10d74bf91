#include "element/node_ordering.hpp"

#include <map>
#include <string>
#include <utility>

#include "core/error.hpp"

namespace homesh {
namespace {

struct SimplexTopology {
  std::vector<std::pair<int, int>> edges;
  std::vector<std::array<int, 3>> faces;  // only for tetrahedra
};

SimplexTopology topologyOf(int dim, NodeConvention convention) {
  if (dim == 1) return {{{0, 1}}, {}};
  if (dim == 2) return {{{0, 1}, {1, 2}, {2, 0}}, {}};
  if (convention == NodeConvention::Gmsh)
    return {{{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}},
            {{{0, 2, 1}}, {{0, 1, 3}}, {{0, 3, 2}}, {{3, 1, 2}}}};
  return {{{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}},
          {{{0, 1, 3}}, {{2, 3, 1}}, {{0, 3, 2}}, {{0, 2, 1}}}};
}

// Recursive ordering of a dim-simplex of order p >= 0 (order 0: the single centre node).
std::vector<Lattice> orderSimplex(int dim, int p, NodeConvention convention) {
  std::vector<Lattice> nodes;
  if (p == 0) {
    nodes.push_back({0, 0, 0, 0});
    return nodes;
  }
  for (int k = 0; k <= dim; ++k) {
    Lattice a{0, 0, 0, 0};
    a[k] = p;
    nodes.push_back(a);
  }
  const SimplexTopology topo = topologyOf(dim, convention);
  for (const auto& [v0, v1] : topo.edges) {
    for (int i = 1; i < p; ++i) {
      Lattice a{0, 0, 0, 0};
      a[v0] = p - i;
      a[v1] = i;
      nodes.push_back(a);
    }
  }
  if (dim == 2 && p >= 3) {
    for (const Lattice& c : orderSimplex(2, p - 3, convention))
      nodes.push_back({c[0] + 1, c[1] + 1, c[2] + 1, 0});
  }
  if (dim == 3) {
    if (p >= 3) {
      for (const auto& face : topo.faces) {
        for (const Lattice& c : orderSimplex(2, p - 3, convention)) {
          Lattice a{0, 0, 0, 0};
          for (int k = 0; k < 3; ++k) a[face[k]] = c[k] + 1;
          nodes.push_back(a);
        }
      }
    }
    if (p >= 4) {
      for (const Lattice& c : orderSimplex(3, p - 4, convention))
        nodes.push_back({c[0] + 1, c[1] + 1, c[2] + 1, c[3] + 1});
    }
  }
  return nodes;
}

}  // namespace

std::vector<Lattice> simplexLattice(CellType type, int order, NodeConvention convention) {
  if (order < 1) throw ParameterError("element order must be >= 1, got " + std::to_string(order));
  switch (type) {
    case CellType::Line:
    case CellType::Triangle:
    case CellType::Tetrahedron:
      return orderSimplex(cellDimension(type), order, convention);
    default:
      throw ParameterError("no simplex lattice for " + cellShortName(type));
  }
}

std::vector<int> nodePermutationFromGmsh(CellType type, int order, NodeConvention convention) {
  const std::vector<Lattice> gmsh = simplexLattice(type, order, NodeConvention::Gmsh);
  const std::vector<Lattice> other = simplexLattice(type, order, convention);
  std::map<Lattice, int> gmshIndex;
  for (int i = 0; i < static_cast<int>(gmsh.size()); ++i) gmshIndex[gmsh[i]] = i;
  std::vector<int> perm;
  perm.reserve(other.size());
  for (const Lattice& a : other) perm.push_back(gmshIndex.at(a));
  return perm;
}

}  // namespace homesh
