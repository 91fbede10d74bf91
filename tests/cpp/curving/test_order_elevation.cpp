// Order elevation: node counts, shared nodes, boundary nodes on the CAD, straight interiors.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "boundary_layer/layer_blend.hpp"
#include "core/error.hpp"
#include "curving/order_elevation.hpp"
#include "element/reference_element.hpp"
#include "gmsh_hybrid_box.hpp"
#include "io/mesh_readers.hpp"
#include "linear/linear_mesher.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

using test::nodePoint;

struct Topology {
  std::size_t vertices = 0, edges = 0, faces = 0, cells = 0;
};

Topology tetTopology(const Mesh& linear) {
  std::set<std::array<std::int64_t, 2>> edges;
  std::set<std::array<std::int64_t, 3>> faces;
  const ElementBlock& tets = linear.blocks[0];
  for (std::size_t e = 0; e < tets.count(); ++e) {
    const std::int64_t* t = tets.element(e);
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) edges.insert({std::min(t[a], t[b]), std::max(t[a], t[b])});
    for (int skip = 0; skip < 4; ++skip) {
      std::array<std::int64_t, 3> f{};
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (k != skip) f[n++] = t[k];
      std::sort(f.begin(), f.end());
      faces.insert(f);
    }
  }
  return {linear.numNodes(), edges.size(), faces.size(), tets.count()};
}

// Where node n of tetrahedron t sits on the straight-sided element through its vertices.
Eigen::Vector3d straightPosition(const Mesh& mesh, const std::int64_t* t,
                                 const ReferenceElement& ref, int n) {
  const Eigen::Vector3d x0 = nodePoint(mesh, t[0]);
  Eigen::Matrix3d a;
  for (int k = 0; k < 3; ++k) a.col(k) = nodePoint(mesh, t[k + 1]) - x0;
  return x0 + a * ref.nodes().row(n).transpose();
}

class SphereOrders : public ::testing::TestWithParam<int> {};

TEST_P(SphereOrders, NodesAreSharedAndBoundaryNodesLieOnTheSphere) {
  const int order = GetParam();
  const double radius = 1.0;
  const CadModel cad = test::toModel(test::sphere(radius));
  const Mesh linear = generateLinearMesh(cad, LinearMeshOptions::uniform(0.45));
  const Mesh mesh = elevateOrder(linear, order, &cad);
  ASSERT_EQ(mesh.order, order);

  // Shared nodes: exactly one node per lattice point of each vertex, edge, face and cell.
  const Topology topo = tetTopology(linear);
  const std::size_t p = order;
  const std::size_t expected = topo.vertices + (p - 1) * topo.edges +
                               (p - 1) * (p - 2) / 2 * topo.faces +
                               (p - 1) * (p - 2) * (p - 3) / 6 * topo.cells;
  EXPECT_EQ(mesh.numNodes(), expected);

  std::size_t onSphere = 0;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    const double r = nodePoint(mesh, i).norm();
    if (mesh.nodeCadDim[i] <= 2) {
      ++onSphere;
      // Boundary nodes are S(u, v) of OCCT's sphere (the projection only chooses (u, v)):
      // |x| = 1 to rounding, ~1e-15.
      EXPECT_NEAR(r, radius, 1e-9) << "node " << i;
      // Parameters reproduce the node.
      if (mesh.nodeCadDim[i] == 2) {
        const auto s = cad.evaluateSurface(mesh.nodeCadIndex[i], mesh.nodeCadParam[2 * i],
                                           mesh.nodeCadParam[2 * i + 1]);
        EXPECT_NEAR((s.point - nodePoint(mesh, i)).norm(), 0.0, 1e-9);
      }
    }
  }
  // Nodes inside the solid stay where the straight-sided element puts them (the same affine
  // combination of the vertices, computed twice: ~1e-15).
  const ElementBlock& tets = mesh.blocks[0];
  const ReferenceElement& ref = ReferenceElement::get(CellType::Tetrahedron, order);
  std::size_t interior = 0;
  for (std::size_t e = 0; e < tets.count(); ++e) {
    const std::int64_t* t = tets.element(e);
    for (int n = 0; n < ref.numNodes(); ++n) {
      if (mesh.nodeCadDim[t[n]] != 3) continue;
      ++interior;
      EXPECT_NEAR((nodePoint(mesh, t[n]) - straightPosition(mesh, t, ref, n)).norm(), 0.0, 1e-12);
    }
  }
  if (order >= 2) {
    EXPECT_GT(interior, 0u);
  }
  // Every node of every boundary triangle is on the sphere.
  std::size_t boundaryNodes = 0;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Triangle) continue;
    EXPECT_EQ(b.nodesPerElement(), (order + 1) * (order + 2) / 2);
    for (const std::int64_t id : b.nodes) {
      EXPECT_LE(mesh.nodeCadDim[id], 2);
      ++boundaryNodes;
    }
  }
  EXPECT_GT(boundaryNodes, 0u);
  EXPECT_GT(onSphere, 0u);
}

INSTANTIATE_TEST_SUITE_P(Orders1To6, SphereOrders, ::testing::Range(1, 7));

TEST(OrderElevation, WithoutCadTheElementsStayStraight) {
  const CadModel cad = test::toModel(test::boxWithHole());
  const Mesh linear = generateLinearMesh(cad, LinearMeshOptions::uniform(0.8));
  const Mesh mesh = elevateOrder(linear, 5, nullptr);
  const ElementBlock& tets = mesh.blocks[0];
  const ReferenceElement& ref = ReferenceElement::get(CellType::Tetrahedron, 5);
  for (std::size_t e = 0; e < tets.count(); ++e) {
    const std::int64_t* t = tets.element(e);
    for (int n = 0; n < ref.numNodes(); ++n)
      EXPECT_NEAR((nodePoint(mesh, t[n]) - straightPosition(mesh, t, ref, n)).norm(), 0.0, 1e-12);
  }
  const QualitySummary q = evaluateQuality(mesh);
  // The certified bound sits below 1 by the proven rounding margin only: 2e-9 for these
  // order-5 tetrahedra (test_jacobian_quality.cpp lists the margins by shape and order).
  EXPECT_NEAR(q.scaled.min, 1.0, 1e-7);
  EXPECT_EQ(q.invalid, 0u);
}

TEST(OrderElevation, CurvedCylinderKeepsValidElements) {
  const double r = 1.0;
  const CadModel cad = test::toModel(test::cylinder(r, 2.0));
  const Mesh mesh = elevateOrder(generateLinearMesh(cad, LinearMeshOptions::uniform(0.4)), 4, &cad);
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    if (mesh.nodeCadDim[i] != 1) continue;
    const Eigen::Vector3d x = nodePoint(mesh, i);
    const double radial = std::hypot(x.x(), x.y());
    // Nodes on curves: the two circles (radius r) or the seam (radius r too); points of the
    // curves themselves, so exact to rounding.
    EXPECT_NEAR(radial, r, 1e-9);
    const auto c = cad.evaluateCurve(mesh.nodeCadIndex[i], mesh.nodeCadParam[2 * i]);
    EXPECT_NEAR((c.point - x).norm(), 0.0, 1e-9);
  }
  EXPECT_EQ(evaluateQuality(mesh).invalid, 0u);
}

// A unit hexahedron at [0,1]^3 and two prisms filling [1,2]x[0,1]x[0,1] (its base square cut
// along a diagonal), sharing the quadrilateral face x = 1, with their boundary quadrilaterals
// and triangles.
Mesh hexAndPrisms() {
  Mesh mesh;
  const double pts[12][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1},
                             {1, 1, 1}, {0, 1, 1}, {2, 0, 0}, {2, 1, 0}, {2, 0, 1}, {2, 1, 1}};
  for (const auto& x : pts) mesh.addNode(x, 3, 1, std::nan(""), std::nan(""));
  ElementBlock hex{CellType::Hexahedron, 1, {0, 1, 2, 3, 4, 5, 6, 7}, {1}};
  // Bottom triangles counter-clockwise seen from +z, then their tops.
  ElementBlock prisms{CellType::Prism, 1, {1, 8, 9, 5, 10, 11, 1, 9, 2, 5, 11, 6}, {1, 1}};
  ElementBlock quads{CellType::Quadrilateral, 1, {0, 3, 2, 1, 8, 10, 11, 9}, {1, 1}};
  ElementBlock tris{CellType::Triangle, 1, {1, 9, 8, 5, 10, 11}, {1, 1}};
  mesh.blocks = {hex, prisms, quads, tris};
  mesh.checkConsistency();
  return mesh;
}

TEST(OrderElevation, HexahedraPrismsAndQuadrilateralsShareTheirNodes) {
  const Mesh linear = hexAndPrisms();
  const int p = 3;
  const Mesh mesh = elevateOrder(linear, p, nullptr);
  ASSERT_EQ(mesh.blocks.size(), 4u);
  EXPECT_EQ(mesh.blocks[0].nodesPerElement(), 64);  // (P + 1)^3
  EXPECT_EQ(mesh.blocks[1].nodesPerElement(), 40);  // (P + 1)(P + 1)(P + 2) / 2
  // Every node of the straight-sided cells sits on the lattice of spacing 1/P of the box, and
  // no two nodes coincide: shared edges and faces (the quadrilateral at x = 1, the prisms'
  // diagonal face) gave one node per point. Coordinates are sums of at most 8 products of
  // small integers / 27, so 1e-12 covers their rounding.
  std::set<std::array<long, 3>> seen;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    std::array<long, 3> cell{};
    for (int c = 0; c < 3; ++c) {
      const double scaled = mesh.xyz[3 * i + c] * p;
      cell[c] = std::lround(scaled);
      EXPECT_NEAR(scaled, static_cast<double>(cell[c]), 1e-12) << "node " << i;
    }
    EXPECT_TRUE(seen.insert(cell).second) << "node " << i << " is a duplicate";
  }
  // The hexahedron's lattice and the prisms' together: all (2P+1) x (P+1) x (P+1) points of
  // the box's lattice (the prisms' lattice points are exactly those of their square).
  EXPECT_EQ(mesh.numNodes(), static_cast<std::size_t>((2 * p + 1) * (p + 1) * (p + 1)));
  std::size_t onSharedFace = 0;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i)
    if (std::abs(mesh.xyz[3 * i] - 1.0) < 1e-12) ++onSharedFace;
  EXPECT_EQ(onSharedFace, static_cast<std::size_t>((p + 1) * (p + 1)));
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid + q.undecided, 0u);
  // Straight-sided unit cells (rounding margin of the certified bound: see above).
  EXPECT_NEAR(q.scaled.min, 1.0, 1e-7);
}

// The entities of test::cylinder(1, 1) (axis z, from z = 0 to 1), found by where they are.
// OpenCASCADE's cylinder closes its circles and its lateral face at angle 0, where its two
// vertices are: a mesh has nodes there, and the seam line between them is a mesh edge.
struct CylinderEntities {
  int lateral = 0, bottom = 0, top = 0;  // faces
  int lower = 0, upper = 0, seam = 0;    // curves: the circles at z = 0 and 1, the seam
  int seamVertex[2] = {0, 0};            // at (1, 0, 0) and (1, 0, 1)
  bool found() const {
    return lateral > 0 && bottom > 0 && top > 0 && lower > 0 && upper > 0 && seam > 0 &&
           seamVertex[0] > 0 && seamVertex[1] > 0;
  }
};

CylinderEntities cylinderEntities(const CadModel& cad) {
  const auto faceThrough = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    for (int f = 1; f <= cad.numFaces(); ++f)
      if (cad.projectOnSurface(f, a).distance < 1e-9 && cad.projectOnSurface(f, b).distance < 1e-9)
        return f;
    return 0;
  };
  const auto curveThrough = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    for (int c = 1; c <= cad.numEdges(); ++c)
      if (cad.projectOnCurve(c, a).distance < 1e-9 && cad.projectOnCurve(c, b).distance < 1e-9)
        return c;
    return 0;
  };
  const auto vertexAt = [&](const Eigen::Vector3d& x) {
    for (int v = 1; v <= cad.numVertices(); ++v)
      if ((cad.vertexPoint(v) - x).norm() < 1e-9) return v;
    return 0;
  };
  CylinderEntities c;
  c.lateral = faceThrough({1, 0, 0.5}, {0, 1, 0.5});
  c.bottom = faceThrough({0, 0, 0}, {0.5, 0, 0});
  c.top = faceThrough({0, 0, 1}, {0.5, 0, 1});
  c.lower = curveThrough({0, 1, 0}, {-1, 0, 0});
  c.upper = curveThrough({0, 1, 1}, {-1, 0, 1});
  c.seam = curveThrough({1, 0, 0.25}, {1, 0, 0.75});
  c.seamVertex[0] = vertexAt({1, 0, 0});
  c.seamVertex[1] = vertexAt({1, 0, 1});
  return c;
}

// Eight prisms around the axis of a cylinder (radius 1, height 1), their outer quadrilaterals on
// its lateral face, their end triangles on its end faces, the arcs on its two circles: elevation
// must put every new node of the lateral face on the cylinder, evenly in its (angle, height)
// parameters, and keep the prisms valid.
TEST(OrderElevation, PrismsAroundACylinderAxisCurveOntoItsLateralFace) {
  const CadModel cad = test::toModel(test::cylinder(1.0, 1.0));
  const CylinderEntities c = cylinderEntities(cad);
  ASSERT_TRUE(c.found());
  const int lateral = c.lateral, bottom = c.bottom, top = c.top;
  const int lower = c.lower, upper = c.upper, seam = c.seam;
  const int* seamVertex = c.seamVertex;

  const int n = 8;
  const double nan = std::nan("");
  Mesh linear;
  for (int level = 0; level < 2; ++level) {
    const double z = level;
    const double centre[3] = {0.0, 0.0, z};
    linear.addNode(centre, 2, level == 0 ? bottom : top, nan, nan);
    for (int i = 0; i < n; ++i) {
      const double a = i * 2.0 * M_PI / n;
      const double x[3] = {std::cos(a), std::sin(a), z};
      if (i == 0) {
        linear.addNode(x, 0, seamVertex[level], nan, nan);
      } else {
        linear.addNode(x, 1, level == 0 ? lower : upper, nan, nan);
      }
    }
  }
  const auto ring = [&](int level, int i) -> std::int64_t { return level * (n + 1) + 1 + i % n; };
  ElementBlock prisms{CellType::Prism, 1, {}, {}}, quads{CellType::Quadrilateral, 1, {}, {}};
  ElementBlock tris{CellType::Triangle, 1, {}, {}}, lines{CellType::Line, 1, {}, {}};
  for (int i = 0; i < n; ++i) {
    prisms.nodes.insert(prisms.nodes.end(),
                        {0, ring(0, i), ring(0, i + 1), n + 1, ring(1, i), ring(1, i + 1)});
    prisms.entity.push_back(1);
    quads.nodes.insert(quads.nodes.end(), {ring(0, i), ring(0, i + 1), ring(1, i + 1), ring(1, i)});
    quads.entity.push_back(lateral);
    tris.nodes.insert(tris.nodes.end(), {0, ring(0, i + 1), ring(0, i)});
    tris.entity.push_back(bottom);
    tris.nodes.insert(tris.nodes.end(), {n + 1, ring(1, i), ring(1, i + 1)});
    tris.entity.push_back(top);
    for (int level = 0; level < 2; ++level) {
      lines.nodes.insert(lines.nodes.end(), {ring(level, i), ring(level, i + 1)});
      lines.entity.push_back(level == 0 ? lower : upper);
    }
  }
  lines.nodes.insert(lines.nodes.end(), {ring(0, 0), ring(1, 0)});
  lines.entity.push_back(seam);
  linear.blocks = {prisms, quads, tris, lines};
  linear.checkConsistency();

  const int p = 4;
  const Mesh mesh = elevateOrder(linear, p, &cad);
  std::size_t onLateral = 0;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    const Eigen::Vector3d x = nodePoint(mesh, i);
    if (mesh.nodeCadDim[i] == 2 && mesh.nodeCadIndex[i] == lateral) {
      ++onLateral;
      // Projected onto the cylinder, or placed on it from (u, v): a point of the surface, to
      // the rounding of its evaluation (|x| <= 1.5).
      EXPECT_NEAR(std::hypot(x.x(), x.y()), 1.0, 1e-9) << "node " << i;
      EXPECT_GT(x.z(), 0.0);
      EXPECT_LT(x.z(), 1.0);
      // Edges spaced in arc length and quadrilateral interiors interpolated in (u, v) =
      // (angle, height): every node on the lattice of angle 2 pi / (n P) and height 1 / P
      // (closest-point projection of the straight quadrilateral's nodes would bunch the
      // angles towards the corners). Rounding of atan2 and the evaluation: 1e-9.
      const double angle = std::atan2(x.y(), x.x()) * n * p / (2.0 * M_PI);
      EXPECT_NEAR(angle, std::round(angle), 1e-9) << "node " << i;
      EXPECT_NEAR(x.z() * p, std::round(x.z() * p), 1e-9) << "node " << i;
    }
    if (mesh.nodeCadDim[i] == 1) {
      EXPECT_NEAR(std::hypot(x.x(), x.y()), 1.0, 1e-9) << "node " << i;
    }
  }
  // The lateral face's new nodes: inside each quadrilateral (P-1)^2, on its vertical edges
  // P-1 each but the seam's (on the seam curve).
  EXPECT_EQ(onLateral, static_cast<std::size_t>(n * (p - 1) * (p - 1) + (n - 1) * (p - 1)));
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid + q.undecided, 0u);
  EXPECT_GT(q.scaled.min, 0.0);
}

// A macro boundary layer inside the same cylinder: 16 prisms grown 0.2 inwards from its lateral
// face (the wall), their sides on its end faces. At order 4 the layer's top is placed parallel to
// the wall (blendLayerInteriors): the top's edges on the end faces are arcs of radius 0.8.
// Raising the order to 6 must keep them so (the order-4 map at the new nodes, projected onto the
// face), not place them afresh between their ends: a chord of that 45-degree arc comes to 0.739
// at its middle, and the first layer split there would be thin by as much. The order-4
// interpolant of the arc (its nodes equally spaced in angle, as the wall's) is within 1.9e-6 of
// the radius (computed), so 1e-5.
TEST(OrderElevation, RaisingALayerKeepsItsTopEdgesOnTheSideFacesParallelToTheWall) {
  const CadModel cad = test::toModel(test::cylinder(1.0, 1.0));
  const CylinderEntities c = cylinderEntities(cad);
  ASSERT_TRUE(c.found());
  const int n = 8;
  const double height = 0.2, nan = std::nan("");
  Mesh linear;
  linear.dim = 3;
  for (int level = 0; level < 2; ++level)  // wall nodes W(level, i), then tops T(level, i)
    for (int i = 0; i < n; ++i) {
      const double a = i * 2.0 * M_PI / n;
      const double x[3] = {std::cos(a), std::sin(a), double(level)};
      if (i == 0) {
        linear.addNode(x, 0, c.seamVertex[level], nan, nan);
      } else {
        linear.addNode(x, 1, level == 0 ? c.lower : c.upper, nan, nan);
      }
    }
  for (int level = 0; level < 2; ++level)
    for (int i = 0; i < n; ++i) {
      const double a = i * 2.0 * M_PI / n, r = 1.0 - height;
      const double x[3] = {r * std::cos(a), r * std::sin(a), double(level)};
      linear.addNode(x, 2, level == 0 ? c.bottom : c.top, nan, nan);
    }
  const auto wall = [&](int level, int i) -> std::int64_t { return level * n + i % n; };
  const auto topOf = [&](std::int64_t w) { return w + std::int64_t{2} * n; };
  ElementBlock prisms{CellType::Prism, 1, {}, {}}, tris{CellType::Triangle, 1, {}, {}};
  ElementBlock quads{CellType::Quadrilateral, 1, {}, {}}, lines{CellType::Line, 1, {}, {}};
  for (int i = 0; i < n; ++i) {
    // Two wall triangles per panel, ordered so that the prism's map has a positive Jacobian
    // (the wall's normal 0-1-2 points inwards, to the top).
    for (const std::array<std::int64_t, 3>& w :
         {std::array<std::int64_t, 3>{wall(0, i), wall(1, i + 1), wall(0, i + 1)},
          std::array<std::int64_t, 3>{wall(0, i), wall(1, i), wall(1, i + 1)}}) {
      prisms.nodes.insert(prisms.nodes.end(),
                          {w[0], w[1], w[2], topOf(w[0]), topOf(w[1]), topOf(w[2])});
      prisms.entity.push_back(1);
      tris.nodes.insert(tris.nodes.end(), w.begin(), w.end());
      tris.entity.push_back(c.lateral);
    }
    for (int level = 0; level < 2; ++level) {
      const std::int64_t a = wall(level, i), b = wall(level, i + 1);
      quads.nodes.insert(quads.nodes.end(), {a, b, topOf(b), topOf(a)});
      quads.entity.push_back(level == 0 ? c.bottom : c.top);
      lines.nodes.insert(lines.nodes.end(), {a, b});
      lines.entity.push_back(level == 0 ? c.lower : c.upper);
    }
  }
  lines.nodes.insert(lines.nodes.end(), {wall(0, 0), wall(1, 0)});
  lines.entity.push_back(c.seam);
  linear.blocks = {prisms, tris, quads, lines};
  linear.checkConsistency();

  Mesh low = elevateOrder(linear, 4, &cad, nullptr, /*layer=*/true);
  blendLayerInteriors(low, &cad);
  const int p = 6;
  const Mesh raised = changeOrder(low, p, &cad, nullptr, /*layer=*/true);
  const ReferenceElement& ref = ReferenceElement::get(CellType::Prism, p);
  std::set<std::int64_t> onTopEdges;
  for (const ElementBlock& b : raised.blocks) {
    if (b.type != CellType::Prism) continue;
    for (std::size_t e = 0; e < b.count(); ++e)
      for (int r = 0; r < ref.numNodes(); ++r) {
        const auto& l = ref.lattice()[static_cast<std::size_t>(r)];
        const bool topEdge = l[2] == p && (l[0] == 0 || l[1] == 0 || l[0] + l[1] == p);
        const std::int64_t id = b.element(e)[r];
        if (topEdge && raised.nodeCadDim[id] == 2) onTopEdges.insert(id);
      }
  }
  // The top's edges on the two end faces: n each, P - 1 new nodes and the two vertices (the
  // tops, on the face) each, the vertices shared: 2 n P.
  EXPECT_EQ(onTopEdges.size(), static_cast<std::size_t>(2 * n * p));
  for (const std::int64_t id : onTopEdges) {
    const Eigen::Vector3d x = nodePoint(raised, id);
    EXPECT_NEAR(std::hypot(x.x(), x.y()), 1.0 - height, 1e-5) << "node " << id;
    EXPECT_NEAR(x.z(), std::round(x.z()), 1e-12) << "node " << id;  // on its end face
  }
  const QualitySummary q = evaluateQuality(raised);
  EXPECT_EQ(q.invalid + q.undecided, 0u);
}

// Pyramids raised with the tetrahedra beside them: a Gmsh hybrid mesh of the unit box at order
// 1 raised to 2, 3, 4 and 6 makes Gmsh's own order-P mesh, element by element and node by node
// in Gmsh's order (its triangle faces shared with the tetrahedra, its base quadrilaterals on the
// box, its inside from its own rational map), with as many nodes, and every element valid.
TEST(OrderElevation, PyramidsShareTheirNodesAsGmshsOwnHighOrderMesh) {
  const auto dir = test::tempDir();
  std::vector<std::pair<int, std::string>> files;
  for (const int p : {1, 2, 3, 4, 6})
    files.emplace_back(p, (dir / ("hybrid" + std::to_string(p) + ".msh")).string());
  test::writeGmshHybridBox(files);
  const Mesh linear = readMesh(files[0].second);
  for (const auto& [p, path] : std::vector(files.begin() + 1, files.end())) {
    const Mesh gmshMesh = readMesh(path);
    const Mesh raised = changeOrder(linear, p, nullptr);
    ASSERT_EQ(raised.numNodes(), gmshMesh.numNodes()) << "order " << p;
    int pyramids = 0;
    for (const ElementBlock& ours : raised.blocks) {
      if (cellDimension(ours.type) != 3) continue;
      pyramids += ours.type == CellType::Pyramid ? 1 : 0;
      const ElementBlock* theirs = nullptr;
      for (const ElementBlock& b : gmshMesh.blocks)
        if (b.type == ours.type) theirs = &b;
      ASSERT_NE(theirs, nullptr);
      ASSERT_EQ(ours.count(), theirs->count());
      // The same straight elements (the box's faces are flat), nodes at multiples of 1 / p
      // along straight segments: equal to rounding (1e-15); 1e-12 is slack, a wrong node is
      // 1e-2 away.
      for (std::size_t e = 0; e < ours.count(); ++e)
        for (int n = 0; n < ours.nodesPerElement(); ++n)
          for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(raised.xyz[3 * static_cast<std::size_t>(ours.element(e)[n]) + c],
                        gmshMesh.xyz[3 * static_cast<std::size_t>(theirs->element(e)[n]) + c],
                        1e-12)
                << cellShortName(ours.type) << " " << e << " node " << n << " order " << p;
    }
    EXPECT_EQ(pyramids, 1);
    const QualitySummary q = evaluateQuality(raised);
    EXPECT_EQ(q.invalid + q.undecided, 0U) << "order " << p;
  }
}

TEST(OrderElevation, RejectsBadOrders) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  const Mesh linear = generateLinearMesh(cad, LinearMeshOptions::uniform(0.5));
  EXPECT_THROW(elevateOrder(linear, 0, &cad), ParameterError);
  EXPECT_THROW(elevateOrder(linear, 11, &cad), ParameterError);
  const Mesh quadratic = elevateOrder(linear, 2, &cad);
  EXPECT_THROW(elevateOrder(quadratic, 3, &cad), ParameterError);
}

}  // namespace
}  // namespace homesh
