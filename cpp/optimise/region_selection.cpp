#include "optimise/region_selection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "core/error.hpp"
#include "optimise/mesh_topology.hpp"

namespace homesh::optimiser {

template <int D>
std::vector<char> region(const WorkingMesh<D>& mesh, const std::vector<double>& scaled,
                         const std::vector<Validity>& validity, const OptimiserOptions& options) {
  const std::size_t total = mesh.totalElements;
  std::vector<char> in(total, 1);
  const std::vector<char>& seed = options.regionSeed;
  if (!options.regionThreshold && seed.empty()) return in;
  if (!seed.empty() && seed.size() != total)
    throw ParameterError("the optimiser's region seed has " + std::to_string(seed.size()) +
                         " entries for " + std::to_string(total) + " elements");
  for (std::size_t i = 0; i < total; ++i)
    in[i] = (!seed.empty() && seed[i] != 0) ||
                    (options.regionThreshold && scaled[i] < *options.regionThreshold) ||
                    validity[i] != Validity::Valid
                ? 1
                : 0;
  for (int layer = 0; layer < options.regionLayers; ++layer) {
    std::vector<char> grown = in;
    for (std::size_t node = 0; node + 1 < mesh.incidenceStart.size(); ++node) {
      bool any = false;
      for (std::size_t k = mesh.incidenceStart[node]; k < mesh.incidenceStart[node + 1] && !any;
           ++k)
        any = in[mesh.globalIndex(mesh.incidence[k])] != 0;
      if (!any) continue;
      for (std::size_t k = mesh.incidenceStart[node]; k < mesh.incidenceStart[node + 1]; ++k)
        grown[mesh.globalIndex(mesh.incidence[k])] = 1;
    }
    in.swap(grown);
  }
  return in;
}

namespace {

// Per node (in the frame) the unit direction options.normalLocked gives it, NaN where none.
template <int D>
std::vector<Eigen::Matrix<double, D, 1>> lockedNormals(const WorkingMesh<D>& mesh,
                                                       const OptimiserOptions& options) {
  using Vec = Eigen::Matrix<double, D, 1>;
  const std::size_t numNodes = mesh.mesh.numNodes();
  if (options.normalLocked.size() != 3 * numNodes)
    throw ParameterError("the optimiser's locked normals have " +
                         std::to_string(options.normalLocked.size()) + " entries for " +
                         std::to_string(numNodes) + " nodes (3 each)");
  std::vector<Vec> locked(numNodes, Vec::Constant(std::nan("")));
  for (std::size_t node = 0; node < numNodes; ++node) {
    const Eigen::Vector3d n(&options.normalLocked[3 * node]);
    const Vec local = mesh.frame * n;
    if (n.allFinite() && local.norm() > 0.0) locked[node] = local.normalized();
  }
  return locked;
}

}  // namespace

template <int D>
FreeNodes<D> chooseFreeNodes(const WorkingMesh<D>& mesh, const std::vector<double>& scaled,
                             const std::vector<Validity>& validity, CadSliding<D>& sliding,
                             const OptimiserOptions& options) {
  const std::size_t numNodes = mesh.mesh.numNodes();
  FreeNodes<D> out;
  std::vector<const ElementBlock*> cells;
  for (const Block<D>& b : mesh.blocks) cells.push_back(b.cells);
  std::vector<char> boundary = boundaryNodes(numNodes, cells, !options.freeInterfaces);
  // Nodes of lower-dimensional cells (boundary faces and curves a file names) stay too, unless
  // they are inside the domain and interfaces are free.
  if (!options.freeInterfaces)
    for (const ElementBlock& lower : mesh.mesh.blocks)
      if (cellDimension(lower.type) < D)
        for (const std::int64_t id : lower.nodes) boundary[id] = 1;
  const std::vector<char> in = region(mesh, scaled, validity, options);
  out.regionElements =
      static_cast<std::size_t>(std::count(in.begin(), in.end(), static_cast<char>(1)));
  sliding.choose(boundary, options.threads);
  if (!options.fixedNodes.empty()) {
    if (options.fixedNodes.size() != numNodes)
      throw ParameterError("the optimiser's fixed-node mask has " +
                           std::to_string(options.fixedNodes.size()) + " entries for " +
                           std::to_string(numNodes) + " nodes");
    for (std::size_t node = 0; node < numNodes; ++node)
      if (options.fixedNodes[node] != 0) boundary[node] = 1;
  }
  if (!options.normalLocked.empty()) out.lockedNormal = lockedNormals(mesh, options);
  std::vector<char> touched(mesh.totalElements, 0);  // the element contains a free node
  for (std::size_t node = 0; node < numNodes; ++node) {
    if (boundary[node] != 0 || mesh.incidenceStart[node] == mesh.incidenceStart[node + 1]) continue;
    bool inRegion = false;
    for (std::size_t k = mesh.incidenceStart[node]; k < mesh.incidenceStart[node + 1]; ++k)
      inRegion = inRegion || in[mesh.globalIndex(mesh.incidence[k])] != 0;
    if (!inRegion) continue;
    out.nodes.push_back(static_cast<std::int64_t>(node));
    for (std::size_t k = mesh.incidenceStart[node]; k < mesh.incidenceStart[node + 1]; ++k)
      touched[mesh.globalIndex(mesh.incidence[k])] = 1;
  }
  for (std::size_t i = 0; i < mesh.totalElements; ++i)
    if (touched[i] != 0) out.changed.push_back(i);
  return out;
}

std::vector<std::size_t> energyOrder(const std::vector<std::size_t>& changed,
                                     std::size_t totalElements,
                                     const std::vector<std::size_t>* callersElements) {
  std::vector<std::size_t> order(changed.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (callersElements == nullptr) return order;
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> position(totalElements, kNone);  // in changed
  for (std::size_t i = 0; i < changed.size(); ++i) position[changed[i]] = i;
  order.clear();
  for (const std::size_t g : *callersElements)
    if (position[g] != kNone) order.push_back(position[g]);
  return order;
}

template <int D>
std::vector<std::vector<std::int64_t>> focusGroups(const WorkingMesh<D>& mesh,
                                                   const std::vector<double>& scaled,
                                                   const std::vector<int>& colourOf,
                                                   std::size_t colours, double margin) {
  const double worst = *std::min_element(scaled.begin(), scaled.end());
  std::vector<std::vector<std::int64_t>> groups(colours);
  std::vector<char> seen(mesh.mesh.numNodes(), 0);
  for (std::size_t bi = 0; bi < mesh.blocks.size(); ++bi) {
    const Block<D>& b = mesh.blocks[bi];
    for (std::size_t e = 0; e < b.cells->count(); ++e) {
      if (!(scaled[mesh.blockOffset[bi] + e] < worst + margin)) continue;
      const std::int64_t* v = b.cells->element(e);
      for (int k = 0; k < b.nodes; ++k)
        if (colourOf[v[k]] >= 0 && seen[v[k]] == 0) {
          seen[v[k]] = 1;
          groups[colourOf[v[k]]].push_back(v[k]);
        }
    }
  }
  return groups;
}

template std::vector<char> region<2>(const WorkingMesh<2>&, const std::vector<double>&,
                                     const std::vector<Validity>&, const OptimiserOptions&);
template FreeNodes<2> chooseFreeNodes<2>(const WorkingMesh<2>&, const std::vector<double>&,
                                         const std::vector<Validity>&, CadSliding<2>&,
                                         const OptimiserOptions&);
template std::vector<std::vector<std::int64_t>> focusGroups<2>(const WorkingMesh<2>&,
                                                               const std::vector<double>&,
                                                               const std::vector<int>&, std::size_t,
                                                               double);
template std::vector<char> region<3>(const WorkingMesh<3>&, const std::vector<double>&,
                                     const std::vector<Validity>&, const OptimiserOptions&);
template FreeNodes<3> chooseFreeNodes<3>(const WorkingMesh<3>&, const std::vector<double>&,
                                         const std::vector<Validity>&, CadSliding<3>&,
                                         const OptimiserOptions&);
template std::vector<std::vector<std::int64_t>> focusGroups<3>(const WorkingMesh<3>&,
                                                               const std::vector<double>&,
                                                               const std::vector<int>&, std::size_t,
                                                               double);

}  // namespace homesh::optimiser
