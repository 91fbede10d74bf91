// The optimiser's split of the work (node_colouring.hpp): parts, the distance from their cut,
// the colouring of the free nodes and the owner-first loop.
#include "optimise/node_colouring.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <numeric>
#include <set>
#include <stdexcept>
#include <vector>

#include "optimise/mesh_topology.hpp"
#include "optimiser_parts.hpp"

namespace homesh {
namespace {

using optimiser::NodeColouring;
using optimiser::WorkingMesh;

// The perturbed cube's working mesh, its free nodes (those inside the domain, ascending) and
// the elements that contain one.
struct Cube {
  Mesh mesh = test::perturbedCube();
  WorkingMesh<3> working{mesh, false};
  std::vector<std::int64_t> free;
  std::vector<std::size_t> changed;
  Cube() {
    working.build();
    working.buildSamples(optimiser::EnergyRule::Collapsed);
    const std::vector<char> boundary = boundaryNodes(mesh.numNodes(), {working.blocks[0].cells});
    for (std::size_t n = 0; n < mesh.numNodes(); ++n)
      if (boundary[n] == 0) free.push_back(static_cast<std::int64_t>(n));
    for (std::size_t e = 0; e < working.totalElements; ++e) {
      const std::int64_t* v = working.blocks[0].cells->element(e);
      if (std::any_of(v, v + working.blocks[0].nodes,
                      [&](std::int64_t n) { return boundary[static_cast<std::size_t>(n)] == 0; }))
        changed.push_back(e);
    }
  }
};

TEST(NodeColouring, NoTwoNodesOfAColourShareAnElementWhateverTheParts) {
  Cube cube;
  std::vector<int> first;
  for (const int threads : {1, 3}) {
    SCOPED_TRACE(threads);
    NodeColouring<3> c(threads);
    c.partition(cube.working, cube.changed);
    std::vector<std::int64_t> free = cube.free;
    c.colour(cube.working, free);
    // The same nodes, regrouped: colour by colour, part by part.
    std::vector<std::int64_t> sorted = free;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, cube.free);
    ASSERT_GT(c.colours(), 1u);
    ASSERT_EQ(c.colourStart().size(), c.colours() * threads + 1);
    EXPECT_EQ(c.colourStart().back(), free.size());
    for (std::size_t col = 0; col < c.colours(); ++col)
      for (int p = 0; p < threads; ++p)
        for (std::size_t i = c.colourStart()[col * threads + p];
             i < c.colourStart()[col * threads + p + 1]; ++i) {
          EXPECT_EQ(c.colourOf()[free[i]], static_cast<int>(col));
          EXPECT_EQ(c.nodePart()[free[i]], p);
        }
    const optimiser::Block<3>& b = cube.working.blocks[0];
    for (std::size_t e = 0; e < b.cells->count(); ++e) {
      std::set<int> colours;
      std::size_t coloured = 0;
      for (int k = 0; k < b.nodes; ++k)
        if (const int col = c.colourOf()[b.cells->element(e)[k]]; col >= 0) {
          colours.insert(col);
          ++coloured;
        }
      EXPECT_EQ(colours.size(), coloured) << "element " << e;
    }
    // The colouring itself follows the nodes' order, not the parts.
    if (first.empty()) first = c.colourOf();
    EXPECT_EQ(c.colourOf(), first);
  }
}

// With parts: a node of an element that spans two parts is at distance 0 from the cut, and a
// node at distance d > 0 shares an element with one at d - 1; a part's nodes of a colour come
// from its interior to the cut.
TEST(NodeColouring, TheCutDistanceGrowsLayerByLayerAndOrdersEachPartsNodes) {
  Cube cube;
  const int threads = 3;
  NodeColouring<3> c(threads);
  c.partition(cube.working, cube.changed);
  const optimiser::Block<3>& b = cube.working.blocks[0];
  const auto& distance = c.cutDistance();
  ASSERT_EQ(distance.size(), cube.mesh.numNodes());
  std::vector<std::size_t> perPart(threads, 0);
  for (std::size_t e = 0; e < b.cells->count(); ++e) {
    const std::int64_t* v = b.cells->element(e);
    ASSERT_GE(c.elementPart()[e], 0);
    ASSERT_LT(c.elementPart()[e], threads);
    ++perPart[static_cast<std::size_t>(c.elementPart()[e])];
    bool mixed = c.elementPart()[e] != c.nodePart()[v[0]];
    for (int k = 1; k < b.nodes; ++k) mixed = mixed || c.nodePart()[v[k]] != c.nodePart()[v[0]];
    if (!mixed) continue;
    for (int k = 0; k < b.nodes; ++k) {
      EXPECT_EQ(distance[v[k]], 0) << e;
    }
  }
  for (const std::size_t n : perPart) EXPECT_GT(n, 0u);
  std::size_t inner = 0;
  for (std::size_t node = 0; node < cube.mesh.numNodes(); ++node) {
    const int d = distance[node];
    if (d == 0 || d == NodeColouring<3>::kFarFromCut) continue;
    ++inner;
    bool closer = false;
    for (std::size_t k = cube.working.incidenceStart[node];
         k < cube.working.incidenceStart[node + 1]; ++k) {
      const std::int64_t* v = b.cells->element(cube.working.incidence[k].element);
      for (int j = 0; j < b.nodes; ++j) closer = closer || distance[v[j]] == d - 1;
    }
    EXPECT_TRUE(closer) << node;
  }
  EXPECT_GT(inner, 0u);
  std::vector<std::int64_t> free = cube.free;
  c.colour(cube.working, free);
  for (std::size_t r = 0; r + 1 < c.colourStart().size(); ++r)
    for (std::size_t i = c.colourStart()[r] + 1; i < c.colourStart()[r + 1]; ++i)
      EXPECT_GE(distance[free[i - 1]], distance[free[i]]);
}

TEST(NodeColouring, ForEachOwnedVisitsEveryElementOnceAndRethrowsTheFirstFailure) {
  Cube cube;
  for (const bool partitioned : {false, true}) {
    NodeColouring<3> c(3);
    if (partitioned) c.partition(cube.working, cube.changed);
    std::vector<std::atomic<int>> visits(cube.changed.size());
    c.forEachOwned(cube.changed, 16, [&](std::size_t i, int thread) {
      EXPECT_GE(thread, 0);
      EXPECT_LT(thread, 3);
      ++visits[i];
    });
    for (const auto& v : visits) EXPECT_EQ(v.load(), 1);
    std::atomic<std::size_t> done{0};
    EXPECT_THROW(c.forEachOwned(cube.changed, 16,
                                [&](std::size_t i, int) {
                                  if (i == 5) throw std::runtime_error("element 5");
                                  ++done;
                                }),
                 std::runtime_error);
    EXPECT_EQ(done.load(), cube.changed.size() - 1);  // the others still ran
  }
}

}  // namespace
}  // namespace homesh
