#include "core/spatial_order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

namespace homesh {
namespace {

// A linear tetrahedral mesh of an n x n x n grid of unit cubes (six tetrahedra each) plus a
// block of boundary triangles on the face z = 0, with its nodes and tetrahedra numbered in a
// random order, as a mesh generator's numbering looks from the point of view of locality.
Mesh shuffledGrid(int n, unsigned seed) {
  Mesh mesh;
  const int m = n + 1;
  std::mt19937 rng(seed);
  std::vector<std::int64_t> id(static_cast<std::size_t>(m * m * m));
  std::iota(id.begin(), id.end(), 0);
  std::shuffle(id.begin(), id.end(), rng);
  mesh.xyz.resize(3 * id.size());
  mesh.nodeCadDim.assign(id.size(), 3);
  mesh.nodeCadIndex.resize(id.size());
  mesh.nodeCadParam.assign(2 * id.size(), std::nan(""));
  const auto grid = [&](int i, int j, int k) {
    return id[(static_cast<std::size_t>(k) * m + j) * m + i];
  };
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const auto node = static_cast<std::size_t>(grid(i, j, k));
        mesh.xyz[3 * node] = i;
        mesh.xyz[3 * node + 1] = j;
        mesh.xyz[3 * node + 2] = k;
        mesh.nodeCadIndex[node] = static_cast<std::int32_t>(node % 7);  // any per-node data
        mesh.nodeCadParam[2 * node] = 0.5 * static_cast<double>(node);
      }
  ElementBlock tets;
  tets.type = CellType::Tetrahedron;
  std::vector<std::array<std::int64_t, 4>> cells;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        // Kuhn's six tetrahedra along the cube's diagonal from (i, j, k) to (i+1, j+1, k+1).
        const int paths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
        for (const auto& path : paths) {
          int p[3] = {i, j, k};
          std::array<std::int64_t, 4> t{grid(p[0], p[1], p[2]), 0, 0, 0};
          for (int s = 0; s < 3; ++s) {
            ++p[path[s]];
            t[static_cast<std::size_t>(s) + 1] = grid(p[0], p[1], p[2]);
          }
          cells.push_back(t);
        }
      }
  std::shuffle(cells.begin(), cells.end(), rng);
  for (std::size_t e = 0; e < cells.size(); ++e) {
    tets.nodes.insert(tets.nodes.end(), cells[e].begin(), cells[e].end());
    tets.entity.push_back(static_cast<std::int32_t>(1 + e % 3));
  }
  ElementBlock bottom;
  bottom.type = CellType::Triangle;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      for (const std::int64_t v : {grid(i, j, 0), grid(i + 1, j, 0), grid(i + 1, j + 1, 0)})
        bottom.nodes.push_back(v);
      bottom.entity.push_back(5);
    }
  mesh.blocks = {tets, bottom};
  mesh.checkConsistency();
  return mesh;
}

// Mean over the tetrahedra of (largest - smallest node id): how far apart in the node arrays
// one element's data lies.
double meanIdSpread(const Mesh& mesh) {
  const ElementBlock& b = mesh.blocks[0];
  double sum = 0.0;
  for (std::size_t e = 0; e < b.count(); ++e) {
    const auto [lo, hi] = std::minmax_element(b.element(e), b.element(e) + 4);
    sum += static_cast<double>(*hi - *lo);
  }
  return sum / static_cast<double>(b.count());
}

std::array<double, 3> point(const Mesh& mesh, std::int64_t node) {
  const auto n = static_cast<std::size_t>(node);
  return {mesh.xyz[3 * n], mesh.xyz[3 * n + 1], mesh.xyz[3 * n + 2]};
}

TEST(SpatialOrder, MortonKeysInterleaveTheAxesXFirst) {
  const double low[3] = {0.0, 0.0, 0.0}, high[3] = {1.0, 1.0, 1.0};
  const double cell = 1.5 / 2097151.0;  // one and a half steps of the 21-bit grid: cell 1
  const double origin[3] = {0.0, 0.0, 0.0}, x[3] = {cell, 0.0, 0.0}, y[3] = {0.0, cell, 0.0},
               z[3] = {0.0, 0.0, cell}, corner[3] = {1.0, 1.0, 1.0}, outside[3] = {2.0, -1.0, 7.0};
  EXPECT_EQ(mortonKey(origin, low, high), 0U);
  EXPECT_EQ(mortonKey(x, low, high), 1U);
  EXPECT_EQ(mortonKey(y, low, high), 2U);
  EXPECT_EQ(mortonKey(z, low, high), 4U);
  EXPECT_EQ(mortonKey(corner, low, high), (std::uint64_t{1} << 63U) - 1U);  // all 63 bits
  // Clamped to the box: x at its top, y at its bottom, z at its top.
  EXPECT_EQ(mortonKey(outside, low, high), 0x5b6db6db6db6db6dULL);
  // A flat box (z constant, as in a 2D mesh): z contributes nothing.
  const double flatHigh[3] = {1.0, 1.0, 0.0};
  EXPECT_EQ(mortonKey(corner, low, flatHigh), 0x36db6db6db6db6dbULL);
}

TEST(SpatialOrder, RenumbersAlongTheCurveAndRestoresExactly) {
  const Mesh input = shuffledGrid(8, 11);
  Mesh mesh = input;
  const SpatialOrder order(mesh);
  order.apply(mesh);
  mesh.checkConsistency();
  ASSERT_EQ(mesh.numNodes(), input.numNodes());
  ASSERT_EQ(mesh.blocks[0].count(), input.blocks[0].count());

  // The same elements, each with its own corners in its own order and its own entity: compare
  // the elements as coordinate tuples.
  const auto tuples = [](const Mesh& m) {
    std::vector<std::vector<double>> out;
    const ElementBlock& b = m.blocks[0];
    for (std::size_t e = 0; e < b.count(); ++e) {
      std::vector<double> t{static_cast<double>(b.entity[e])};
      for (int k = 0; k < 4; ++k) {
        const auto p = point(m, b.element(e)[k]);
        t.insert(t.end(), p.begin(), p.end());
      }
      out.push_back(t);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(tuples(mesh), tuples(input));
  // The boundary block keeps its order, with its nodes renumbered.
  for (std::size_t i = 0; i < input.blocks[1].nodes.size(); ++i)
    EXPECT_EQ(point(mesh, mesh.blocks[1].nodes[i]), point(input, input.blocks[1].nodes[i]));

  // The tetrahedra follow their centroids' Morton keys.
  const double low[3] = {0.0, 0.0, 0.0}, high[3] = {8.0, 8.0, 8.0};
  std::uint64_t previous = 0;
  for (std::size_t e = 0; e < mesh.blocks[0].count(); ++e) {
    double c[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 3; ++d) c[d] += point(mesh, mesh.blocks[0].element(e)[k])[d] / 4.0;
    const std::uint64_t key = mortonKey(c, low, high);
    EXPECT_GE(key, previous) << e;
    previous = key;
  }
  // Nodes are numbered by first use: along the tetrahedra, each new node is the next number.
  std::int64_t next = 0;
  for (const std::int64_t v : mesh.blocks[0].nodes) {
    ASSERT_LE(v, next);
    if (v == next) ++next;
  }
  EXPECT_EQ(next, static_cast<std::int64_t>(mesh.numNodes()));  // every node is in a tetrahedron
  // The point of it: one element's nodes lie close together in the node arrays. On the shuffled
  // 729-node grid a tetrahedron's ids span about half the range; measured 2026-11-27: 351 before,
  // 48 after (the Z-curve's jumps between octants keep a few large).
  EXPECT_LT(meanIdSpread(mesh), meanIdSpread(input) / 4.0);

  // Per-node and per-element arrays given alongside follow the mesh.
  EXPECT_EQ(order.nodeValues(input.xyz, 3), mesh.xyz);
  EXPECT_EQ(order.nodeValues(input.nodeCadIndex, 1), mesh.nodeCadIndex);
  EXPECT_EQ(order.elementValues(input.blocks[0].entity), mesh.blocks[0].entity);
  const std::vector<double> wrongSize(5, 1.0);
  EXPECT_EQ(order.nodeValues(wrongSize, 3), wrongSize);  // left to the consumer's own check
  // The inverses map each original number to the new one.
  ASSERT_EQ(order.newNodes().size(), order.originalNodes().size());
  for (std::size_t n = 0; n < order.originalNodes().size(); ++n)
    EXPECT_EQ(order.newNodes()[static_cast<std::size_t>(order.originalNodes()[n])],
              static_cast<std::int64_t>(n));
  ASSERT_EQ(order.newElements().size(), order.originalElements().size());
  for (std::size_t e = 0; e < order.originalElements().size(); ++e)
    EXPECT_EQ(order.newElements()[order.originalElements()[e]], e);
  EXPECT_EQ(order.elementValues(wrongSize), wrongSize);

  // Coordinates and parameters changed meanwhile come back in the caller's numbering; the
  // rest is exactly the input.
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    mesh.xyz[3 * i] += 0.25;
    mesh.nodeCadParam[2 * i + 1] = mesh.xyz[3 * i + 1];
  }
  order.restore(mesh);
  EXPECT_EQ(mesh.blocks[0].nodes, input.blocks[0].nodes);
  EXPECT_EQ(mesh.blocks[0].entity, input.blocks[0].entity);
  EXPECT_EQ(mesh.blocks[1].nodes, input.blocks[1].nodes);
  EXPECT_EQ(mesh.nodeCadDim, input.nodeCadDim);
  EXPECT_EQ(mesh.nodeCadIndex, input.nodeCadIndex);
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    EXPECT_EQ(mesh.xyz[3 * i], input.xyz[3 * i] + 0.25);
    EXPECT_EQ(mesh.xyz[3 * i + 2], input.xyz[3 * i + 2]);
    EXPECT_EQ(mesh.nodeCadParam[2 * i], input.nodeCadParam[2 * i]);
    EXPECT_EQ(mesh.nodeCadParam[2 * i + 1], input.xyz[3 * i + 1]);
  }
}

// Two numberings of one mesh give the same spatial numbering: the order depends on where the
// elements are, not on the numbers they came with (no two centroids share a key here).
TEST(SpatialOrder, DoesNotDependOnTheInputNumbering) {
  Mesh a = shuffledGrid(5, 1), b = shuffledGrid(5, 2);
  ASSERT_NE(a.blocks[0].nodes, b.blocks[0].nodes);
  SpatialOrder(a).apply(a);
  SpatialOrder(b).apply(b);
  EXPECT_EQ(a.xyz, b.xyz);
  EXPECT_EQ(a.blocks[0].nodes, b.blocks[0].nodes);
}

}  // namespace
}  // namespace homesh
