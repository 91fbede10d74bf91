// The split of a macro layer on hand-made meshes (layer_split.hpp): the first layer's height as
// measured where the wall normal meets the top, and a fan at a convex corner split into
// conforming sub-triangles.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "boundary_layer/layer_cells.hpp"
#include "boundary_layer/layer_split.hpp"
#include "element/reference_element.hpp"
#include "layer_case_checks.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {
namespace {

// A 2D macro layer that fans out: four order-4 quadrilaterals on an annulus of inner radius
// R = 0.1 and thickness H = 1 (ten times R), each spanning 1 rad, whose lines across the layer
// lean: node (xi, zeta) at angle theta0 + xi + s zeta, s = 0.08. Split in two layers of half
// the height, the first layer's top is the circle of radius R + H/2, so its height along the
// wall normal is H/2 everywhere; the top point at the wall point's own reference coordinate is
// 0.04 rad to the side (inside the cell from the first quadrature point, xi = 0.047, on), and
// its component along the normal is (R + H/2) cos 0.04 - R, 4.8e-4 short. The map's degree-5
// remainder on five equispaced nodes, |d^5 x / d xi^5| max|prod (xi - xi_i)| / 5! <= 0.6 * 0.0046
// / 120 = 2.3e-5 (2e-8 across the layer), bounds the error of the heights: 1e-4 holds them and
// tells them from the component.
TEST(BoundaryLayerSplit, TheFirstHeightIsMeasuredWhereTheWallNormalMeetsTheLayersTop) {
  constexpr double kR = 0.1, kH = 1.0, kDTheta = 1.0, kLean = 0.08;
  constexpr int kCells = 4, kOrder = 4;
  Mesh macro;
  macro.dim = 2;
  macro.order = kOrder;
  const ReferenceElement& ref = ReferenceElement::get(CellType::Quadrilateral, kOrder);
  ElementBlock quads;
  quads.type = CellType::Quadrilateral;
  quads.order = kOrder;
  std::map<std::pair<long long, long long>, std::int64_t> ids;  // shared nodes by position
  for (int c = 0; c < kCells; ++c) {
    for (int i = 0; i < ref.numNodes(); ++i) {
      const double xi = ref.nodes()(i, 0), zeta = ref.nodes()(i, 1);
      const double theta = (c + xi) * kDTheta + zeta * kLean;
      const double r = kR + zeta * kH;
      const double p[3] = {r * std::cos(theta), r * std::sin(theta), 0.0};
      const auto key = std::make_pair(std::llround(p[0] * 1e9), std::llround(p[1] * 1e9));
      auto [it, added] = ids.try_emplace(key, 0);
      if (added) it->second = macro.addNode(p, 2, 1, std::nan(""), std::nan(""));
      quads.nodes.push_back(it->second);
    }
    quads.entity.push_back(1);
  }
  macro.blocks.push_back(quads);
  macro.checkConsistency();
  LayerSplitStats stats;
  splitBoundaryLayer(macro, {0.0, 0.5, 1.0}, nullptr, &stats);
  ASSERT_GT(stats.firstHeightMeasured, 0U);
  EXPECT_EQ(stats.firstHeightOffNormal, 0U);
  EXPECT_NEAR(stats.firstHeightMin, kH / 2, 1e-4);
  EXPECT_NEAR(stats.firstHeightMax, kH / 2, 1e-4);
}

// A hand-made macro layer around a convex corner, at order 2: walls from A = (-1, 0) to the
// corner C = (0, 0) (layer above, normal +y) and from C down to B = (0, -1) (layer to the right,
// normal +x), each with one quadrilateral of height H = 0.5, and between their columns at C a fan
// of three straight triangles, 30 degrees each. Split in two layers (z = 0, 1/3, 1): each fan
// triangle becomes 2 n - 1 = 3 triangles, sub-maps of an affine map (so straight, their edge
// nodes at the midpoints, to rounding), the nodes on the columns shared with the quadrilaterals
// and the neighbouring fan triangles (no two nodes at one point), every column's first level at
// z_1 H from C; keepColumnsPlain names a fan piece's macro columns by their tops.
TEST(BoundaryLayerSplit, AFanAtAConvexCornerSplitsIntoConformingSubTriangles) {
  constexpr double kH = 0.5;
  constexpr int kOrder = 2;
  Mesh macro;
  macro.dim = 2;
  macro.order = kOrder;
  std::map<std::pair<long long, long long>, std::int64_t> ids;
  const auto node = [&](const Eigen::Vector2d& x) {
    const auto key = std::make_pair(std::llround(x.x() * 1e9), std::llround(x.y() * 1e9));
    auto [it, added] = ids.try_emplace(key, 0);
    const double p[3] = {x.x(), x.y(), 0.0};
    if (added) it->second = macro.addNode(p, 2, 1, std::nan(""), std::nan(""));
    return it->second;
  };
  ElementBlock quads, tris;
  quads.type = CellType::Quadrilateral;
  tris.type = CellType::Triangle;
  quads.order = tris.order = kOrder;
  const ReferenceElement& quadRef = ReferenceElement::get(CellType::Quadrilateral, kOrder);
  const ReferenceElement& triRef = ReferenceElement::get(CellType::Triangle, kOrder);
  const auto addQuad = [&](std::array<Eigen::Vector2d, 4> c) {  // wall 0, 1; tops 3, 2
    for (int i = 0; i < quadRef.numNodes(); ++i) {
      const double u = quadRef.nodes()(i, 0), w = quadRef.nodes()(i, 1);
      quads.nodes.push_back(
          node((1 - u) * (1 - w) * c[0] + u * (1 - w) * c[1] + u * w * c[2] + (1 - u) * w * c[3]));
    }
    quads.entity.push_back(1);
  };
  const Eigen::Vector2d a(-1, 0), c(0, 0), b(0, -1);
  addQuad({a, c, Eigen::Vector2d(0, kH), Eigen::Vector2d(-1, kH)});
  addQuad({c, b, Eigen::Vector2d(kH, -1), Eigen::Vector2d(kH, 0)});
  std::vector<Eigen::Vector2d> tops;
  for (int j = 0; j <= 3; ++j) {
    const double angle = j * M_PI / 6;  // 0 (+x) .. 90 degrees (+y)
    tops.emplace_back(kH * std::cos(angle), kH * std::sin(angle));
  }
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < triRef.numNodes(); ++i) {
      const double u = triRef.nodes()(i, 0), w = triRef.nodes()(i, 1);
      tris.nodes.push_back(node(c + u * (tops[j] - c) + w * (tops[j + 1] - c)));
    }
    tris.entity.push_back(1);
  }
  macro.blocks = {tris, quads};
  macro.checkConsistency();
  const std::vector<char> fans = layerFanTriangles(macro, macro.blocks[0]);
  EXPECT_EQ(std::count(fans.begin(), fans.end(), 1), 3);
  LayerSplitStats stats;
  const Mesh split = splitBoundaryLayer(macro, {0.0, 1.0 / 3, 1.0}, nullptr, &stats);
  EXPECT_EQ(stats.fanTriangles, 3U);
  ASSERT_EQ(split.blocks.size(), 2U);
  EXPECT_EQ(split.blocks[0].count(), 9U);
  EXPECT_EQ(split.blocks[1].count(), 4U);
  std::set<std::pair<long long, long long>> places;
  for (std::size_t i = 0; i < split.numNodes(); ++i) {
    const Eigen::Vector3d x = point(split, static_cast<std::int64_t>(i));
    EXPECT_TRUE(places.emplace(std::llround(x.x() * 1e9), std::llround(x.y() * 1e9)).second)
        << "two nodes at " << x.transpose();
  }
  // Straight sub-triangles: positive area, edge nodes at the midpoints (rounding: 1e-12).
  const ElementBlock& pieces = split.blocks[0];
  for (std::size_t e = 0; e < pieces.count(); ++e) {
    const std::int64_t* v = pieces.element(e);
    const Eigen::Vector3d p0 = point(split, v[0]), p1 = point(split, v[1]), p2 = point(split, v[2]);
    EXPECT_GT((p1 - p0).cross(p2 - p0).z(), 0.0);
    EXPECT_LT((point(split, v[3]) - (p0 + p1) / 2).norm(), 1e-12);
    EXPECT_LT((point(split, v[4]) - (p1 + p2) / 2).norm(), 1e-12);
    EXPECT_LT((point(split, v[5]) - (p2 + p0) / 2).norm(), 1e-12);
  }
  for (const Eigen::Vector2d& t : tops) {
    const Eigen::Vector2d first = c + (t - c) / 3;
    EXPECT_EQ(places.count({std::llround(first.x() * 1e9), std::llround(first.y() * 1e9)}), 1U)
        << "no node at the first level of the column to " << t.transpose();
  }
  EXPECT_EQ(evaluateQuality(split, 1).invalid, 0U);
  // Split element 4 is the second fan triangle's second piece: its columns end at tops 1, 2.
  LayerHeights heights;
  keepColumnsPlain(macro, 2, 4, heights);
  const std::set<std::int64_t> expected{node(tops[1]), node(tops[2])};
  EXPECT_EQ(heights.plain, expected);
}

}  // namespace
}  // namespace homesh
