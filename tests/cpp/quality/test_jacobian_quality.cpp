// Sampled scaled Jacobian: exact for straight elements, detects a fold, 2D orientation.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "element/reference_element.hpp"
#include "quality/jacobian_quality.hpp"

namespace homesh {
namespace {

// One straight tetrahedron of order p on the reference vertices scaled and sheared.
Mesh straightTet(int p) {
  Mesh mesh;
  mesh.dim = 3;
  mesh.order = p;
  const ReferenceElement& ref = ReferenceElement::get(CellType::Tetrahedron, p);
  Eigen::Matrix3d a;
  a << 2.0, 0.3, 0.1, 0.0, 1.5, -0.2, 0.0, 0.0, 0.7;
  ElementBlock block;
  block.type = CellType::Tetrahedron;
  block.order = p;
  for (int n = 0; n < ref.numNodes(); ++n) {
    const Eigen::Vector3d x = a * ref.nodes().row(n).transpose() + Eigen::Vector3d(1, 2, 3);
    block.nodes.push_back(mesh.addNode(x.data(), 3, 1, NAN, NAN));
  }
  block.entity.push_back(1);
  mesh.blocks.push_back(block);
  return mesh;
}

TEST(JacobianQuality, StraightElementsScoreOne) {
  for (int p = 1; p <= 10; ++p) {
    const QualitySummary q = evaluateQuality(straightTet(p));
    ASSERT_EQ(q.scaledJacobian.size(), 1u);
    EXPECT_NEAR(q.scaledJacobian[0], 1.0, 1e-9) << "order " << p;
    EXPECT_EQ(q.invalid, 0u);
  }
}

TEST(JacobianQuality, MovingAnEdgeNodeCurvesAndThenFoldsTheElement) {
  // Order 2: node 4 is the midpoint of edge (0, 1). Pulling it towards the opposite edge makes
  // J vary (0 < q < 1); pulling it past the element makes J negative at vertex 0.
  Mesh mesh = straightTet(2);
  const std::int64_t mid = mesh.blocks[0].nodes[4];
  const Eigen::Vector3d start(mesh.xyz[3 * mid], mesh.xyz[3 * mid + 1], mesh.xyz[3 * mid + 2]);
  const Eigen::Vector3d inward(0.0, 0.5, 0.3);
  for (int c = 0; c < 3; ++c) mesh.xyz[3 * mid + c] = start[c] + 0.1 * inward[c];
  const QualitySummary curved = evaluateQuality(mesh);
  EXPECT_GT(curved.min, 0.0);
  EXPECT_LT(curved.min, 0.999);
  for (int c = 0; c < 3; ++c) mesh.xyz[3 * mid + c] = start[c] + 3.0 * inward[c];
  const QualitySummary folded = evaluateQuality(mesh);
  EXPECT_LT(folded.min, 0.0);
  EXPECT_EQ(folded.invalid, 1u);
  EXPECT_EQ(folded.byType.at(CellType::Tetrahedron).invalid, 1u);
}

TEST(JacobianQuality, PlanarTrianglesAreSignedAgainstThePlaneNormal) {
  Mesh mesh;
  mesh.dim = 2;
  mesh.order = 1;
  const double pts[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  ElementBlock tris;
  tris.type = CellType::Triangle;
  for (const auto& p : pts) tris.nodes.push_back(mesh.addNode(p, 2, 1, 0, 0));
  tris.nodes.insert(tris.nodes.end(), {0, 2, 1});  // the same triangle, clockwise
  tris.entity = {1, 1};
  mesh.blocks.push_back(tris);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_NEAR(q.scaledJacobian[0], 1.0, 1e-12);
  EXPECT_EQ(q.scaledJacobian[1], -1.0);
  EXPECT_EQ(q.invalid, 1u);
  mesh.planeNormal = {0.0, 0.0, -1.0};
  EXPECT_EQ(evaluateQuality(mesh).scaledJacobian[0], -1.0);
}

TEST(JacobianQuality, EmptyMeshIsAnError) {
  Mesh mesh;
  EXPECT_THROW(evaluateQuality(mesh), Error);
}

}  // namespace
}  // namespace homesh
