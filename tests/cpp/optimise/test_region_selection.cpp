// Which nodes the optimiser moves (region_selection.hpp): the region grown around poor, seeded
// and invalid elements, the free nodes and their locked directions, the energy's summing order
// and the focused passes' nodes.
#include "optimise/region_selection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "optimise/mesh_topology.hpp"
#include "optimiser_parts.hpp"

namespace homesh {
namespace {

using optimiser::CadSliding;
using optimiser::FreeNodes;
using optimiser::WorkingMesh;

struct Cube {
  Mesh mesh = test::perturbedCube();
  WorkingMesh<3> working{mesh, false};
  std::vector<double> scaled;      // made up per test: every element 0.9 to start
  std::vector<Validity> validity;  // every element valid to start
  Cube() {
    working.build();
    working.buildSamples(optimiser::EnergyRule::Collapsed);
    scaled.assign(working.totalElements, 0.9);
    validity.assign(working.totalElements, Validity::Valid);
  }
  const ElementBlock& tets() const { return *working.blocks[0].cells; }
  bool shareANode(std::size_t a, std::size_t b) const {
    const std::int64_t* va = tets().element(a);
    const std::int64_t* vb = tets().element(b);
    const int n = tets().nodesPerElement();
    return std::any_of(va, va + n,
                       [&](std::int64_t x) { return std::find(vb, vb + n, x) != vb + n; });
  }
  // Not const: the sliding model is built over the working mesh, which it may change.
  // NOLINTNEXTLINE(readability-make-member-function-const)
  FreeNodes<3> choose(const OptimiserOptions& options) {
    CadSliding<3> sliding(working, nullptr);
    return optimiser::chooseFreeNodes(working, scaled, validity, sliding, options);
  }
};

std::vector<std::size_t> members(const std::vector<char>& in) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < in.size(); ++i)
    if (in[i] != 0) out.push_back(i);
  return out;
}

TEST(RegionSelection, TheRegionIsTheSeededPoorAndInvalidElementsAndLayersAroundThem) {
  Cube cube;
  OptimiserOptions options;
  EXPECT_EQ(members(optimiser::region(cube.working, cube.scaled, cube.validity, options)).size(),
            cube.working.totalElements);  // no threshold, no seed: every element
  const std::size_t seeded = 3, poor = 40, invalid = 77;
  options.regionSeed.assign(cube.working.totalElements, 0);
  options.regionSeed[seeded] = 1;
  options.regionThreshold = 0.5;
  cube.scaled[poor] = 0.4;
  cube.validity[invalid] = Validity::Undecided;
  options.regionLayers = 0;
  EXPECT_EQ(members(optimiser::region(cube.working, cube.scaled, cube.validity, options)),
            (std::vector<std::size_t>{seeded, poor, invalid}));
  // One layer: every element sharing a node with one of them.
  options.regionLayers = 1;
  const std::vector<char> grown =
      optimiser::region(cube.working, cube.scaled, cube.validity, options);
  for (std::size_t e = 0; e < cube.working.totalElements; ++e) {
    const bool expected =
        cube.shareANode(e, seeded) || cube.shareANode(e, poor) || cube.shareANode(e, invalid);
    EXPECT_EQ(grown[e] != 0, expected) << e;
  }
  options.regionSeed.pop_back();
  EXPECT_THROW(optimiser::region(cube.working, cube.scaled, cube.validity, options),
               ParameterError);
}

TEST(RegionSelection, FreeNodesAreInsideTheDomainInTheRegionAndNotFixed) {
  Cube cube;
  OptimiserOptions options;
  const std::vector<char> boundary = boundaryNodes(cube.mesh.numNodes(), {&cube.tets()}, true);
  const FreeNodes<3> all = cube.choose(options);
  std::vector<std::int64_t> inside;
  for (std::size_t n = 0; n < cube.mesh.numNodes(); ++n)
    if (boundary[n] == 0) inside.push_back(static_cast<std::int64_t>(n));
  EXPECT_EQ(all.nodes, inside);
  EXPECT_EQ(all.regionElements, cube.working.totalElements);
  EXPECT_TRUE(all.lockedNormal.empty());
  // The elements with a free node, ascending.
  std::vector<std::size_t> changed;
  for (std::size_t e = 0; e < cube.working.totalElements; ++e) {
    const std::int64_t* v = cube.tets().element(e);
    if (std::any_of(v, v + cube.tets().nodesPerElement(),
                    [&](std::int64_t n) { return boundary[static_cast<std::size_t>(n)] == 0; }))
      changed.push_back(e);
  }
  EXPECT_EQ(all.changed, changed);

  // Fixed nodes stay; in a region, only nodes of its elements move.
  options.fixedNodes.assign(cube.mesh.numNodes(), 0);
  options.fixedNodes[static_cast<std::size_t>(inside.front())] = 1;
  options.regionSeed.assign(cube.working.totalElements, 0);
  options.regionSeed[10] = 1;
  options.regionLayers = 0;
  const FreeNodes<3> some = cube.choose(options);
  EXPECT_EQ(some.regionElements, 1u);
  const std::int64_t* v = cube.tets().element(10);
  for (const std::int64_t n : some.nodes) {
    EXPECT_NE(n, inside.front());
    EXPECT_NE(std::find(v, v + cube.tets().nodesPerElement(), n),
              v + cube.tets().nodesPerElement());
  }
  options.fixedNodes.pop_back();
  EXPECT_THROW(cube.choose(options), ParameterError);
}

TEST(RegionSelection, LockedDirectionsAreUnitVectorsInTheFrame) {
  Cube cube;
  OptimiserOptions options;
  options.normalLocked.assign(3 * cube.mesh.numNodes(), std::nan(""));
  options.normalLocked[0] = 3.0;  // node 0: (3, 4, 0)
  options.normalLocked[1] = 4.0;
  options.normalLocked[2] = 0.0;
  options.normalLocked[3] = options.normalLocked[4] = options.normalLocked[5] = 0.0;  // zero
  const FreeNodes<3> free = cube.choose(options);
  ASSERT_EQ(free.lockedNormal.size(), cube.mesh.numNodes());
  EXPECT_TRUE(free.lockedNormal[0].isApprox(Eigen::Vector3d(0.6, 0.8, 0.0), 1e-15));
  EXPECT_FALSE(free.lockedNormal[1].allFinite());  // no direction: moves freely
  EXPECT_FALSE(free.lockedNormal[2].allFinite());
  options.normalLocked.resize(6);
  EXPECT_THROW(cube.choose(options), ParameterError);
}

TEST(RegionSelection, TheEnergyIsSummedInTheCallersElementOrder) {
  const std::vector<std::size_t> changed{1, 4, 6, 7};
  EXPECT_EQ(optimiser::energyOrder(changed, 8, nullptr), (std::vector<std::size_t>{0, 1, 2, 3}));
  // The caller's element i is element callers[i] here: 7, 1 and 6 (positions 3, 0, 2) then 4.
  const std::vector<std::size_t> callers{0, 7, 2, 1, 3, 5, 6, 4};
  EXPECT_EQ(optimiser::energyOrder(changed, 8, &callers), (std::vector<std::size_t>{3, 0, 2, 1}));
}

TEST(RegionSelection, FocusedPassesTakeTheColouredNodesOfTheElementsNearTheWorst) {
  Cube cube;
  const std::size_t worst = 12, near = 50, far = 51;
  cube.scaled[worst] = 0.30;
  cube.scaled[near] = 0.34;  // within 0.05 of the worst
  cube.scaled[far] = 0.36;
  // Colours made up: node n has colour n % 4, except the first node of each element, uncoloured.
  std::vector<int> colourOf(cube.mesh.numNodes());
  for (std::size_t n = 0; n < colourOf.size(); ++n) colourOf[n] = static_cast<int>(n % 4);
  for (const std::size_t e : {worst, near, far}) colourOf[cube.tets().element(e)[0]] = -1;
  const auto groups = optimiser::focusGroups(cube.working, cube.scaled, colourOf, 4, 0.05);
  ASSERT_EQ(groups.size(), 4u);
  std::set<std::int64_t> expected, found;
  for (const std::size_t e : {worst, near})
    for (int k = 0; k < cube.tets().nodesPerElement(); ++k)
      if (colourOf[cube.tets().element(e)[k]] >= 0) expected.insert(cube.tets().element(e)[k]);
  std::size_t count = 0;
  for (std::size_t c = 0; c < groups.size(); ++c)
    for (const std::int64_t n : groups[c]) {
      EXPECT_EQ(colourOf[n], static_cast<int>(c));
      found.insert(n);
      ++count;
    }
  EXPECT_EQ(count, found.size());  // no node twice
  EXPECT_EQ(found, expected);
}

}  // namespace
}  // namespace homesh
