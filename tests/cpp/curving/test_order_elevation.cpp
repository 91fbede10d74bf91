// Order elevation: node counts, shared nodes, boundary nodes on the CAD, straight interiors.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>

#include "core/error.hpp"
#include "curving/order_elevation.hpp"
#include "element/reference_element.hpp"
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
