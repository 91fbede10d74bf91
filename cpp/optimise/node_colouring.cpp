#include "optimise/node_colouring.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace homesh::optimiser {

template <int D>
void NodeColouring<D>::partition(const WorkingMesh<D>& mesh,
                                 const std::vector<std::size_t>& changed) {
  parts_ = threads_;
  elementPart_.assign(mesh.totalElements, 0);
  nodePart_.assign(mesh.mesh.numNodes(), 0);
  if (parts_ == 1) return;
  std::vector<char> moves(mesh.totalElements, 0);
  for (const std::size_t g : changed) moves[g] = 1;
  std::vector<std::array<double, 3>> centroid(mesh.totalElements);
  std::vector<double> weight(mesh.totalElements, 0.0);
  for (std::size_t bi = 0; bi < mesh.blocks.size(); ++bi) {
    const Block<D>& b = mesh.blocks[bi];
    for (std::size_t e = 0; e < b.cells->count(); ++e) {
      const std::size_t g = mesh.blockOffset[bi] + e;
      const std::int64_t* v = b.cells->element(e);
      std::array<double, 3> c{0.0, 0.0, 0.0};
      for (int k = 0; k < b.nodes; ++k)
        for (int i = 0; i < 3; ++i) c[i] += mesh.mesh.xyz[3 * v[k] + i] / b.nodes;
      centroid[g] = c;
      if (moves[g] != 0) weight[g] = b.points;
    }
  }
  elementPart_ = bisectByCoordinates(centroid, weight, parts_);
  nodePart_ = nodeOwners(mesh.mesh.numNodes(), parts_, [&](std::size_t n, auto add) {
    for (std::size_t k = mesh.incidenceStart[n]; k < mesh.incidenceStart[n + 1]; ++k)
      add(elementPart_[mesh.globalIndex(mesh.incidence[k])]);
  });
  measureCutDistance(mesh);
}

template <int D>
void NodeColouring<D>::measureCutDistance(const WorkingMesh<D>& mesh) {
  cutDistance_.assign(mesh.mesh.numNodes(), kFarFromCut);
  std::vector<std::int64_t> frontier, next;
  for (std::size_t bi = 0; bi < mesh.blocks.size(); ++bi) {
    const Block<D>& b = mesh.blocks[bi];
    for (std::size_t e = 0; e < b.cells->count(); ++e) {
      const std::int64_t* v = b.cells->element(e);
      bool mixed = elementPart_[mesh.blockOffset[bi] + e] != nodePart_[v[0]];
      for (int k = 1; k < b.nodes && !mixed; ++k) mixed = nodePart_[v[k]] != nodePart_[v[0]];
      if (!mixed) continue;
      for (int k = 0; k < b.nodes; ++k)
        if (cutDistance_[v[k]] != 0) {
          cutDistance_[v[k]] = 0;
          frontier.push_back(v[k]);
        }
    }
  }
  // An element scanned once has every node at most at that layer: never scanned again (a
  // frontier node's elements are mostly another frontier node's too).
  std::vector<char> scanned(mesh.totalElements, 0);
  for (std::uint8_t layer = 1; layer < kFarFromCut && !frontier.empty(); ++layer) {
    next.clear();
    for (const std::int64_t n : frontier)
      for (std::size_t k = mesh.incidenceStart[n]; k < mesh.incidenceStart[n + 1]; ++k) {
        if (std::exchange(scanned[mesh.globalIndex(mesh.incidence[k])], 1) != 0) continue;
        const Block<D>& b = mesh.blocks[mesh.incidence[k].block];
        const std::int64_t* v = b.cells->element(mesh.incidence[k].element);
        for (int j = 0; j < b.nodes; ++j)
          if (cutDistance_[v[j]] == kFarFromCut) {
            cutDistance_[v[j]] = layer;
            next.push_back(v[j]);
          }
      }
    frontier.swap(next);
  }
}

template <int D>
void NodeColouring<D>::colour(const WorkingMesh<D>& mesh, std::vector<std::int64_t>& free) {
  const std::size_t numNodes = mesh.mesh.numNodes();
  std::vector<int> colourOf(numNodes, -1);
  colourOf_.assign(numNodes, -1);
  std::vector<std::size_t> stamp;  // stamp[c] == node + 1: colour c is taken by a neighbour
  int colours = 0;
  std::vector<std::int64_t> visit = free;  // sorted
  if (mesh.callersNodes != nullptr) {
    std::vector<char> isFree(numNodes, 0);
    for (const std::int64_t node : free) isFree[static_cast<std::size_t>(node)] = 1;
    visit.clear();
    for (const std::int64_t node : *mesh.callersNodes)
      if (isFree[static_cast<std::size_t>(node)] != 0) visit.push_back(node);
  }
  for (const std::int64_t node : visit) {
    for (std::size_t k = mesh.incidenceStart[node]; k < mesh.incidenceStart[node + 1]; ++k) {
      const Incidence& inc = mesh.incidence[k];
      const std::int64_t* v = mesh.blocks[inc.block].cells->element(inc.element);
      for (int j = 0; j < mesh.blocks[inc.block].nodes; ++j)
        if (const int c = colourOf[v[j]]; c >= 0) stamp[c] = static_cast<std::size_t>(node) + 1;
    }
    int c = 0;
    while (c < colours && stamp[c] == static_cast<std::size_t>(node) + 1) ++c;
    if (c == colours) {
      ++colours;
      stamp.push_back(0);
    }
    colourOf[node] = c;
    colourOf_[node] = c;
  }
  std::vector<std::vector<std::int64_t>> groups(colours);
  for (const std::int64_t node : free) groups[colourOf[node]].push_back(node);
  free = groupByColourAndPart(groups, colourStart_);
  colours_ = static_cast<std::size_t>(colours);
}

template <int D>
std::vector<std::int64_t> NodeColouring<D>::groupByColourAndPart(
    const std::vector<std::vector<std::int64_t>>& groups, std::vector<std::size_t>& starts) const {
  std::vector<std::int64_t> nodes;
  starts.assign(1, 0);
  std::vector<std::size_t> begin;
  for (const auto& g : groups) {
    std::vector<std::int64_t> byPart = groupByPart(
        g, parts_, [&](std::int64_t n) { return nodePart_[static_cast<std::size_t>(n)]; }, begin);
    // Each part's nodes from its interior to the cut: its thread takes them from the front,
    // a thread helping it from the back (OwnerFirstQueue), where the nodes' elements are the
    // ones the two threads share already. A colour's nodes share no element: their order
    // changes no result.
    if (parts_ > 1)
      for (std::size_t p = 0; p + 1 < begin.size(); ++p)
        std::stable_sort(byPart.begin() + static_cast<std::ptrdiff_t>(begin[p]),
                         byPart.begin() + static_cast<std::ptrdiff_t>(begin[p + 1]),
                         [&](std::int64_t a, std::int64_t b) {
                           return cutDistance_[static_cast<std::size_t>(a)] >
                                  cutDistance_[static_cast<std::size_t>(b)];
                         });
    const std::size_t base = nodes.size();
    nodes.insert(nodes.end(), byPart.begin(), byPart.end());
    for (std::size_t p = 1; p < begin.size(); ++p) starts.push_back(base + begin[p]);
  }
  return nodes;
}

template class NodeColouring<2>;
template class NodeColouring<3>;

}  // namespace homesh::optimiser
