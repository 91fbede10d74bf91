// The "boundary_fit" stage (pipeline/boundary_fidelity.hpp) on a mesh the pipeline made without
// it: the boundary follows the CAD's normal closer, and no element breaks the stage's promise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "pipeline/boundary_fidelity.hpp"
#include "pipeline/mesh_pipeline.hpp"

namespace homesh {
namespace {

// The sphere in a box at size 0.8, order 5, optimised, with the fidelity term and the stage off,
// made once for the tests below.
const MeshResult& sphereInABoxOrder5() {
  static const MeshResult made = [] {
    MeshingOptions options;
    options.order = 5;
    options.size = 0.8;
    options.optimiseIterations = 100;
    options.threads = 2;
    options.fidelityWeight = 0.0;  // neither the term nor the stage
    return runMeshPipeline(
        CadSource::file(std::string(HOMESH_SOURCE_DIR) + "/examples/sphere_box.step"), options);
  }();
  return made;
}

// The sphere in a box at size 0.8, order 5, optimised, with the fidelity term and this stage off:
// its boundary is the raise's placement (the final optimiser keeps its input), 0.146 degrees off
// the sphere's normal at most. The stage alone took it to 0.0086 degrees and the largest distance
// from 9.5e-5 to 2.4e-6 (2026-12-01), the worst element 0.4356 -> 0.4441. The test asks for the
// issue's factor 4, the promise for every element (none newly not proven valid, none more than
// 0.1 %, the certified measure's own resolution, below the lower of its value and the worst
// before), and every node still on the CAD (the geometry's distance not larger).
TEST(BoundaryFit, FollowsTheSphereBetweenItsNodesAndKeepsEveryElement) {
  const MeshResult& made = sphereInABoxOrder5();
  ASSERT_FALSE(made.boundaryFit.has_value());
  ASSERT_TRUE(made.geometry.has_value());
  ASSERT_EQ(made.quality.invalid + made.quality.undecided, 0U);
  Mesh mesh = made.mesh;
  QualitySummary quality = made.quality;
  const BoundaryFitRecord record = fitBoundaryFidelity(mesh, quality, *made.cad, 2);
  const GeometryAccuracy after = measureGeometryAccuracy(mesh, *made.cad, 2);
  std::printf(
      "boundary fit: %zu of %zu triangles in %zu tiers, %zu nodes frozen; angle %.4g -> %.4g deg, "
      "distance %.3g -> %.3g, worst %.4f -> %.4f\n",
      record.fitted, record.triangles, record.tiers, record.frozenNodes, made.geometry->maxAngleDeg,
      after.maxAngleDeg, made.geometry->maxDistance, after.maxDistance, made.quality.scaled.min,
      quality.scaled.min);
  EXPECT_GT(record.fitted, 0U);
  EXPECT_LT(after.maxAngleDeg, made.geometry->maxAngleDeg / 4.0);
  EXPECT_LE(after.maxDistance, made.geometry->maxDistance);
  // The promise, element by element, on a fresh measure of the whole mesh.
  const QualitySummary measured = evaluateQuality(mesh, 2);
  EXPECT_EQ(measured.invalid + measured.undecided, 0U);
  for (std::size_t e = 0; e < measured.scaledJacobian.size(); ++e)
    EXPECT_GE(measured.scaledJacobian[e],
              0.999 * std::min(made.quality.scaledJacobian[e], made.quality.scaled.min))
        << "element " << e;
}

// `stop` is asked between tiers: true before the first leaves the mesh as it was, true after the
// first keeps that tier (the sphere's boundary takes several), and the record says so.
TEST(BoundaryFit, StopsBetweenTiersKeepingWhatWasCertified) {
  const MeshResult& made = sphereInABoxOrder5();
  ASSERT_EQ(made.quality.invalid + made.quality.undecided, 0U);
  Mesh mesh = made.mesh;
  QualitySummary quality = made.quality;
  BoundaryFitRecord record = fitBoundaryFidelity(mesh, quality, *made.cad, 2, [] { return true; });
  EXPECT_TRUE(record.stopped);
  EXPECT_EQ(record.tiers, 0U);
  EXPECT_EQ(record.fitted, 0U);
  EXPECT_EQ(mesh.xyz, made.mesh.xyz);
  int asked = 0;
  record = fitBoundaryFidelity(mesh, quality, *made.cad, 2, [&] { return ++asked > 1; });
  EXPECT_TRUE(record.stopped);
  EXPECT_EQ(record.tiers, 1U);
  EXPECT_GT(record.fitted, 0U);
  EXPECT_NE(mesh.xyz, made.mesh.xyz);
  // What the stage returns is certified: a fresh measure agrees with it element by element.
  const QualitySummary measured = evaluateQuality(mesh, 2);
  EXPECT_EQ(measured.scaledJacobian, quality.scaledJacobian);
  EXPECT_EQ(measured.invalid + measured.undecided, 0U);
}

// A linear mesh, and a mesh without CAD-face triangles of order 2 or more, are left alone.
TEST(BoundaryFit, LeavesALinearMeshAlone) {
  MeshingOptions options;
  options.order = 1;
  options.size = 0.8;
  const MeshResult made = runMeshPipeline(
      CadSource::file(std::string(HOMESH_SOURCE_DIR) + "/examples/sphere_box.step"), options);
  EXPECT_FALSE(made.boundaryFit.has_value());
  Mesh mesh = made.mesh;
  QualitySummary quality = made.quality;
  const BoundaryFitRecord record = fitBoundaryFidelity(mesh, quality, *made.cad, 1);
  EXPECT_EQ(record.fitted, 0U);
  EXPECT_EQ(mesh.xyz, made.mesh.xyz);
}

}  // namespace
}  // namespace homesh
