// A curved mesh read without its CAD records put back on the CAD by its boundary cells' corners
// (quality/boundary_on_cad.hpp): every cell on the entity the mesher put it on, and the geometry
// measured as on the mesher's own records; bad input named.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"
#include "curving/order_elevation.hpp"
#include "linear/linear_mesher.hpp"
#include "quality/boundary_on_cad.hpp"
#include "quality/geometry_accuracy.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

Mesh curvedMesh(const CadModel& cad, double size, int order) {
  return elevateOrder(generateLinearMesh(cad, LinearMeshOptions::uniform(size)), order, &cad);
}

// `mesh` as a file from another tool gives it: no CAD record on any node, and boundary cells
// tagged by the tool's own numbering (here: a number the model does not have).
Mesh withoutCadRecords(Mesh mesh) {
  mesh.nodeCadDim.assign(mesh.numNodes(), 3);
  mesh.nodeCadIndex.assign(mesh.numNodes(), 0);
  mesh.nodeCadParam.assign(2 * mesh.numNodes(), std::numeric_limits<double>::quiet_NaN());
  for (ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) < mesh.dim) b.entity.assign(b.count(), 1000);
  return mesh;
}

std::size_t boundaryCells(const Mesh& mesh, int dim) {
  std::size_t n = 0;
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == dim && dim < mesh.dim) n += b.count();
  return n;
}

// Planar faces, a cylindrical hole (a seam, circles) and a sphere (poles, degenerated edges).
TEST(BoundaryOnCad, PutsEveryCellWhereTheMesherDidAndMeasuresTheSame) {
  for (const TopoDS_Shape& shape : {test::boxWithHole(), test::sphere(1.0)}) {
    const CadModel cad = test::toModel(shape);
    const Mesh made = curvedMesh(cad, 0.45, 3);
    const Mesh bare = withoutCadRecords(made);
    BoundaryOnCadStats stats;
    const Mesh onCad = boundaryOnCad(bare, cad, 0.0, &stats);
    EXPECT_EQ(onCad.xyz, made.xyz);  // measured where they are, not moved
    ASSERT_EQ(onCad.blocks.size(), made.blocks.size());
    for (std::size_t b = 0; b < made.blocks.size(); ++b)
      EXPECT_EQ(onCad.blocks[b].entity, made.blocks[b].entity)
          << cellShortName(made.blocks[b].type);
    EXPECT_EQ(stats.faceCells, boundaryCells(made, 2));
    EXPECT_EQ(stats.curveCells, boundaryCells(made, 1));
    EXPECT_GT(stats.curveCells, 0U);
    // The mesher puts corners on the CAD to its precision; the tolerance is far above it.
    EXPECT_LT(stats.maxCornerDistance, 1e-9 * cad.boundingDiagonal());

    const GeometryAccuracy expected = measureGeometryAccuracy(made, cad, 2);
    const GeometryAccuracy got = measureGeometryAccuracy(onCad, cad, 2);
    EXPECT_EQ(got.samples, expected.samples);
    EXPECT_EQ(got.angleSamples, expected.angleSamples);
    EXPECT_EQ(got.undefinedNormals, expected.undefinedNormals);
    // The projections start from other guesses and converge to 1e-9 of the diagonal
    // (CadModel's precision): distances agree to that, normals to that over the smallest
    // radius of curvature (1 here), in degrees.
    const double projection = 1e-9 * cad.boundingDiagonal();
    EXPECT_NEAR(got.maxDistance, expected.maxDistance, projection);
    EXPECT_NEAR(got.meanDistance, expected.meanDistance, projection);
    EXPECT_NEAR(got.maxAngleDeg, expected.maxAngleDeg, projection * 180.0 / 3.14159);
    EXPECT_EQ(got.worstAngleEntity, expected.worstAngleEntity);
  }
}

TEST(BoundaryOnCad, ACornerOffTheCadIsNamed) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  Mesh mesh = withoutCadRecords(curvedMesh(cad, 0.5, 2));
  std::int64_t corner = -1;
  for (const ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Triangle) corner = b.element(0)[0];
  ASSERT_GE(corner, 0);
  for (int c = 0; c < 3; ++c) mesh.xyz[3 * corner + c] *= 1.01;  // 0.01 out of the sphere
  try {
    boundaryOnCad(mesh, cad);
    FAIL() << "expected MeshingError";
  } catch (const MeshingError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("boundary node " + std::to_string(corner + 1) + " at ("), std::string::npos)
        << m;
    EXPECT_NE(m.find("(nearest: Face1 at distance 0.01"), std::string::npos) << m;
  }
  // A tolerance above the offset takes it (relative to the diagonal 2 sqrt(3)).
  BoundaryOnCadStats stats;
  boundaryOnCad(mesh, cad, 0.02, &stats);
  EXPECT_NEAR(stats.maxCornerDistance, 0.01, 1e-9);
}

TEST(BoundaryOnCad, AnotherShapesMeshIsRefused) {
  const CadModel sphere = test::toModel(test::sphere(1.0));
  const CadModel box = test::toModel(test::box(2.0, 2.0, 2.0));
  const Mesh mesh = withoutCadRecords(curvedMesh(box, 0.8, 2));
  try {
    boundaryOnCad(mesh, sphere);
    FAIL() << "expected MeshingError";
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("is the mesh of this shape?"), std::string::npos)
        << e.what();
  }
}

TEST(BoundaryOnCad, AMeshWithoutBoundaryCellsIsRefused) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  Mesh mesh = curvedMesh(cad, 0.6, 2);
  mesh.blocks.resize(1);  // the tetrahedra alone
  ASSERT_EQ(mesh.blocks[0].type, CellType::Tetrahedron);
  try {
    boundaryOnCad(mesh, cad);
    FAIL() << "expected ParameterError";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("no boundary cells"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace homesh
