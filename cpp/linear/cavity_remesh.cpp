#include "linear/cavity_remesh.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "linear/edge_split.hpp"

namespace homesh {
namespace {

using Triangle = std::array<std::int64_t, 3>;

// The faces of a positive tetrahedron (0, 1, 2, 3), each ordered so that its normal (right-hand
// rule) points out of the cell.
constexpr int kOutwardFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

Triangle sortedKey(const Triangle& t) {
  Triangle k = t;
  std::sort(k.begin(), k.end());
  return k;
}

// The cavity's surface, per solid: faces of marked cells that no other marked cell of the same
// solid shares, oriented out of the cavity.
std::map<std::pair<int, Triangle>, Triangle> cavitySurface(const ElementBlock& tets,
                                                           const std::vector<char>& marked) {
  std::map<std::pair<int, Triangle>, std::pair<int, Triangle>> faces;  // -> (count, oriented)
  for (std::size_t c = 0; c < tets.count(); ++c) {
    if (marked[c] == 0) continue;
    const std::int64_t* v = tets.element(c);
    for (const auto& f : kOutwardFaces) {
      const Triangle t{v[f[0]], v[f[1]], v[f[2]]};
      auto& entry = faces[{tets.entity[c], sortedKey(t)}];
      ++entry.first;
      entry.second = t;
    }
  }
  std::map<std::pair<int, Triangle>, Triangle> surface;
  for (const auto& [key, entry] : faces)
    if (entry.first == 1) surface.emplace(key, entry.second);
  return surface;
}

// Vertices where the surface of one solid's cavity is not a closed 2-manifold: an edge on other
// than two of its triangles, or triangles around the vertex that form more than one fan.
std::set<std::pair<int, std::int64_t>> nonManifoldVertices(
    const std::map<std::pair<int, Triangle>, Triangle>& surface) {
  std::map<std::pair<int, MeshEdge>, int> edgeCount;
  std::map<std::pair<int, std::int64_t>, std::vector<MeshEdge>> link;  // opposite edges
  for (const auto& [key, t] : surface)
    for (int i = 0; i < 3; ++i) {
      ++edgeCount[{key.first, meshEdge(t[i], t[(i + 1) % 3])}];
      link[{key.first, t[i]}].push_back(meshEdge(t[(i + 1) % 3], t[(i + 2) % 3]));
    }
  std::set<std::pair<int, std::int64_t>> bad;
  for (const auto& [key, n] : edgeCount)
    if (n != 2) {
      bad.insert({key.first, key.second[0]});
      bad.insert({key.first, key.second[1]});
    }
  for (const auto& [vertex, edges] : link) {
    if (bad.count(vertex) > 0) continue;
    // One fan: the link's edges are connected (walk them from the first).
    std::set<std::int64_t> reached{edges.front()[0]};
    for (bool grew = true; grew;) {
      grew = false;
      for (const MeshEdge& e : edges)
        if ((reached.count(e[0]) > 0) != (reached.count(e[1]) > 0)) {
          reached.insert(e[0]);
          reached.insert(e[1]);
          grew = true;
        }
    }
    std::set<std::int64_t> all;
    for (const MeshEdge& e : edges) {
      all.insert(e[0]);
      all.insert(e[1]);
    }
    if (reached.size() != all.size()) bad.insert(vertex);
  }
  return bad;
}

// The cells around each node: those around node n are around[start[n] .. start[n + 1]).
struct CellsAroundNodes {
  std::vector<std::size_t> start, around;
};

CellsAroundNodes cellsAroundNodes(const ElementBlock& tets, std::size_t numNodes) {
  const std::size_t count = tets.count();
  CellsAroundNodes a;
  a.start.assign(numNodes + 1, 0);
  for (std::size_t c = 0; c < count; ++c)
    for (int i = 0; i < 4; ++i) ++a.start[static_cast<std::size_t>(tets.element(c)[i]) + 1];
  std::partial_sum(a.start.begin(), a.start.end(), a.start.begin());
  a.around.resize(a.start.back());
  std::vector<std::size_t> fill(a.start.begin(), a.start.end() - 1);
  for (std::size_t c = 0; c < count; ++c)
    for (int i = 0; i < 4; ++i) a.around[fill[static_cast<std::size_t>(tets.element(c)[i])]++] = c;
  return a;
}

// Marks every cell of `solid` around `node`.
void markAround(std::int64_t node, int solid, const ElementBlock& tets,
                const CellsAroundNodes& cellsAround, std::vector<char>& marked) {
  const auto n = static_cast<std::size_t>(node);
  for (std::size_t k = cellsAround.start[n]; k < cellsAround.start[n + 1]; ++k)
    if (tets.entity[cellsAround.around[k]] == solid) marked[cellsAround.around[k]] = 1;
}

// Grows the marked cells where their surface is not a closed 2-manifold (cavities touching at an
// edge or a vertex, a cell hanging on by an edge): all of the solid's cells around such a vertex
// join. Returns the closed surface.
std::map<std::pair<int, Triangle>, Triangle> growToClosedSurface(
    const ElementBlock& tets, const CellsAroundNodes& cellsAround, std::size_t requested,
    std::vector<char>& marked) {
  constexpr int kGrowthPasses = 8;
  for (int pass = 0;; ++pass) {
    std::map<std::pair<int, Triangle>, Triangle> surface = cavitySurface(tets, marked);
    const auto bad = nonManifoldVertices(surface);
    if (bad.empty()) return surface;
    if (pass == kGrowthPasses)
      throw MeshingError("the cavity around " + std::to_string(requested) +
                         " cells did not become a closed manifold surface in " +
                         std::to_string(kGrowthPasses) + " passes");
    for (const auto& [solid, node] : bad) markAround(node, solid, tets, cellsAround, marked);
  }
}

// Connected cavities: marked cells of one solid joined through shared faces, by the root cell
// keyed by their union-find root.
std::map<std::size_t, std::vector<std::size_t>> connectedCavities(const ElementBlock& tets,
                                                                  const std::vector<char>& marked) {
  const std::size_t count = tets.count();
  std::vector<std::size_t> parent(count);
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&parent](std::size_t c) {
    while (parent[c] != c) c = parent[c] = parent[parent[c]];
    return c;
  };
  std::map<std::pair<int, Triangle>, std::size_t> firstCell;
  for (std::size_t c = 0; c < count; ++c) {
    if (marked[c] == 0) continue;
    const std::int64_t* v = tets.element(c);
    for (const auto& f : kOutwardFaces) {
      const auto [it, fresh] = firstCell.emplace(
          std::make_pair(tets.entity[c], sortedKey({v[f[0]], v[f[1]], v[f[2]]})), c);
      if (!fresh) parent[root(c)] = root(it->second);
    }
  }
  std::map<std::size_t, std::vector<std::size_t>> cavities;  // root -> cells
  for (std::size_t c = 0; c < count; ++c)
    if (marked[c] != 0) cavities[root(c)].push_back(c);
  return cavities;
}

// A cavity's surface as a mesh of its own nodes alone, so that a fill (and its copy to and from
// a child process, isolated) costs the cavity's size, not the model's.
struct CavityPatch {
  Mesh local;
  std::vector<std::int64_t> toWork;  // local node -> node of the mesh
  std::vector<Triangle> boundary;    // in local nodes
};

CavityPatch cavityPatch(const Mesh& mesh,
                        const std::map<std::pair<int, Triangle>, Triangle>& surface, int solid,
                        const std::set<Triangle>& own) {
  CavityPatch patch;
  std::map<std::int64_t, std::int64_t> toLocal;
  for (const auto& [key, t] : surface) {
    if (key.first != solid || own.count(key.second) == 0) continue;
    Triangle mapped{};
    for (int i = 0; i < 3; ++i) {
      const std::int64_t n = t[static_cast<std::size_t>(i)];
      auto [it, fresh] = toLocal.emplace(n, static_cast<std::int64_t>(patch.toWork.size()));
      if (fresh) {
        const auto k = static_cast<std::size_t>(n);
        patch.local.addNode(&mesh.xyz[3 * k], mesh.nodeCadDim[k], mesh.nodeCadIndex[k],
                            mesh.nodeCadParam[2 * k], mesh.nodeCadParam[2 * k + 1]);
        patch.toWork.push_back(n);
      }
      mapped[static_cast<std::size_t>(i)] = it->second;
    }
    patch.boundary.push_back(mapped);
  }
  return patch;
}

// The cells of one cavity filled again by Gmsh, their nodes (new ones added to `work`) in
// `work`'s numbering; refused unless every cell is positive and they fill the cavity's volume.
ElementBlock fillCavity(const Mesh& mesh, Mesh& work, const ElementBlock& tets,
                        const std::map<std::pair<int, Triangle>, Triangle>& surface,
                        const std::vector<std::size_t>& members, int solid,
                        LinearMeshOptions fillOptions) {
  std::set<Triangle> own;  // the cavity's faces, as keys
  double removed = 0.0, longest = 0.0;
  for (const std::size_t c : members) {
    const std::int64_t* v = tets.element(c);
    removed += simplexVolume(mesh, v);
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        longest = std::max(longest, (nodePoint(mesh, v[i]) - nodePoint(mesh, v[j])).norm());
    for (const auto& f : kOutwardFaces) own.insert(sortedKey({v[f[0]], v[f[1]], v[f[2]]}));
  }
  CavityPatch patch = cavityPatch(mesh, surface, solid, own);
  // Sizes from the surface: no cap below the cavity's longest edge.
  fillOptions.sizeField = nullptr;
  fillOptions.size = longest;
  const std::string what =
      "a cavity of " + std::to_string(members.size()) + " cells in Solid" + std::to_string(solid);
  ElementBlock cavityCells = fillTetrahedra(patch.local, patch.boundary, fillOptions, solid,
                                            {what, " (its surface is closed)"});
  const Mesh& local = patch.local;
  std::vector<std::int64_t>& toWork = patch.toWork;
  for (std::size_t n = toWork.size(); n < local.numNodes(); ++n)
    toWork.push_back(work.addNode(&local.xyz[3 * n], local.nodeCadDim[n], local.nodeCadIndex[n],
                                  local.nodeCadParam[2 * n], local.nodeCadParam[2 * n + 1]));
  for (std::int64_t& n : cavityCells.nodes) n = toWork[static_cast<std::size_t>(n)];
  double filled = 0.0;
  for (std::size_t c = 0; c < cavityCells.count(); ++c) {
    const double v = simplexVolume(work, cavityCells.element(c));
    if (!(v > 0.0))
      throw MeshingError("Gmsh's fill of " + what + " has a cell of non-positive volume");
    filled += v;
  }
  // The two sums cover one polyhedron: they differ by rounding only (a few units of the last
  // place per cell), far below this bound unless Gmsh filled something else.
  if (std::abs(filled - removed) > 1e-9 * removed * static_cast<double>(members.size() + 10))
    throw MeshingError("Gmsh's fill of " + what + " has volume " + std::to_string(filled) +
                       " where the cavity has " + std::to_string(removed));
  return cavityCells;
}

// The cells that stay, in their order, then the fills'.
void replaceMarkedCells(Mesh& work, const std::vector<char>& marked, const ElementBlock& added) {
  for (ElementBlock& b : work.blocks) {
    if (b.type != CellType::Tetrahedron || cellDimension(b.type) != 3) continue;
    ElementBlock kept;
    kept.type = b.type;
    kept.order = b.order;
    for (std::size_t c = 0; c < b.count(); ++c) {
      if (marked[c] != 0) continue;
      kept.nodes.insert(kept.nodes.end(), b.element(c), b.element(c) + 4);
      kept.entity.push_back(b.entity[c]);
    }
    kept.nodes.insert(kept.nodes.end(), added.nodes.begin(), added.nodes.end());
    kept.entity.insert(kept.entity.end(), added.entity.begin(), added.entity.end());
    b = std::move(kept);
  }
}

}  // namespace

CavityOutcome remeshCavities(Mesh& mesh, const std::vector<std::size_t>& cells,
                             const LinearMeshOptions& options) {
  const ElementBlock* found = tetrahedronBlock(mesh, "cavity remeshes");
  if (found == nullptr) throw ParameterError("cavity remeshing: the mesh has no tetrahedra");
  const ElementBlock& tets = *found;
  const std::size_t count = tets.count();
  for (const std::size_t c : cells)
    if (c >= count)
      throw ParameterError("cavity remeshing: cell " + std::to_string(c) + " of a mesh of " +
                           std::to_string(count) + " tetrahedra");
  CavityOutcome outcome;
  if (cells.empty()) return outcome;

  // The cavity: every cell of the requested cell's solid that shares a vertex with it.
  const CellsAroundNodes cellsAround = cellsAroundNodes(tets, mesh.numNodes());
  std::vector<char> marked(count, 0);
  for (const std::size_t c : cells)
    for (int i = 0; i < 4; ++i)
      markAround(tets.element(c)[i], tets.entity[c], tets, cellsAround, marked);
  const std::map<std::pair<int, Triangle>, Triangle> surface =
      growToClosedSurface(tets, cellsAround, cells.size(), marked);

  // Each cavity filled again, on a copy: a failure leaves the mesh as it was. All the fills
  // share options.timeLimit.
  Mesh work = mesh;
  ElementBlock added;
  added.type = CellType::Tetrahedron;
  const auto started = std::chrono::steady_clock::now();
  for (const auto& [rootCell, members] : connectedCavities(tets, marked)) {
    LinearMeshOptions fillOptions = options;
    if (options.timeLimit > 0.0) {
      const double spent =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      fillOptions.timeLimit = std::max(options.timeLimit - spent, 1e-3);
    }
    const ElementBlock cavityCells =
        fillCavity(mesh, work, tets, surface, members, tets.entity[rootCell], fillOptions);
    added.nodes.insert(added.nodes.end(), cavityCells.nodes.begin(), cavityCells.nodes.end());
    added.entity.insert(added.entity.end(), cavityCells.entity.begin(), cavityCells.entity.end());
    outcome.cellsRemoved += members.size();
    outcome.cellsAdded += cavityCells.count();
    ++outcome.cavities;
  }
  replaceMarkedCells(work, marked, added);
  work.checkConsistency();
  mesh = std::move(work);
  return outcome;
}

}  // namespace homesh
