// The "boundary_fit" stage (pipeline/boundary_fidelity.hpp) on a mesh the pipeline made without
// it: the boundary follows the CAD's normal closer, and no element breaks the stage's promise.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <gp_Ax2.hxx>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "curving/face_fidelity_fit.hpp"
#include "pipeline/boundary_fidelity.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// The sphere in a box at size 0.8 and order `order`, optimised, with the fidelity term and the
// stage off, made once per order for the tests below.
const MeshResult& sphereInABox(int order) {
  static std::map<int, MeshResult> made;
  auto it = made.find(order);
  if (it == made.end()) {
    MeshingOptions options;
    options.order = order;
    options.size = 0.8;
    options.optimiseIterations = 100;
    options.threads = 2;
    options.fidelityWeight = 0.0;  // neither the term nor the stage
    it = made.emplace(order, runMeshPipeline(CadSource::file(std::string(HOMESH_SOURCE_DIR) +
                                                             "/examples/sphere_box.step"),
                                             options))
             .first;
  }
  return it->second;
}

// The sphere in a box at size 0.8, order 5, optimised, with the fidelity term and this stage off:
// its boundary is the raise's placement (the final optimiser keeps its input), 0.146 degrees off
// the sphere's normal at most. The stage alone took it to 0.0086 degrees and the largest distance
// from 9.5e-5 to 2.4e-6 (2026-12-01), the worst element 0.4356 -> 0.4441. The test asks for the
// issue's factor 4, the promise for every element (none newly not proven valid, none more than
// 0.1 %, the certified measure's own resolution, below the lower of its value and the worst
// before), and every node still on the CAD (the geometry's distance not larger). After the
// tiers, vertex patches moved 5 corners (2026-12-02), each dragging the volume's nodes around it.
TEST(BoundaryFit, FollowsTheSphereBetweenItsNodesAndKeepsEveryElement) {
  const MeshResult& made = sphereInABox(5);
  ASSERT_FALSE(made.boundaryFit.has_value());
  ASSERT_TRUE(made.geometry.has_value());
  ASSERT_EQ(made.quality.invalid + made.quality.undecided, 0U);
  Mesh mesh = made.mesh;
  QualitySummary quality = made.quality;
  const BoundaryFitRecord record = fitBoundaryFidelity(mesh, quality, *made.cad, 2);
  const GeometryAccuracy after = measureGeometryAccuracy(mesh, *made.cad, 2);
  std::printf(
      "boundary fit: %zu of %zu triangles in %zu tiers, %zu nodes frozen, %zu vertex patches; "
      "angle %.4g -> %.4g deg, distance %.3g -> %.3g, worst %.4f -> %.4f\n",
      record.fitted, record.triangles, record.tiers, record.frozenNodes, record.verticesMoved,
      made.geometry->maxAngleDeg, after.maxAngleDeg, made.geometry->maxDistance, after.maxDistance,
      made.quality.scaled.min, quality.scaled.min);
  EXPECT_GT(record.fitted, 0U);
  EXPECT_GT(record.verticesMoved, 0U);  // the promise below holds for the vertex patches too
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
  const MeshResult& made = sphereInABox(5);
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

// A box with two holes, a boundary layer on the narrower one's wall: the layer's nodes stay, and
// its wall, whose angles are the mesh's largest (radius 0.08 against 0.15 at one size), does not
// end the stage before the other hole is fitted (it did when every layer node counted as frozen
// by the certification: the wall was "held" from the start and the stage stopped at once).
TEST(BoundaryFit, FitsTheFacesBesideABoundaryLayersWallAndLeavesTheWall) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(1.0, 0.8, 0.3).Shape();
  const auto drill = [](double x, double radius) {
    return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, 0.4, -0.1), gp_Dir(0, 0, 1)), radius, 0.5)
        .Shape();
  };
  const TopoDS_Shape holed =
      BRepAlgoAPI_Cut(BRepAlgoAPI_Cut(box, drill(0.25, 0.08)).Shape(), drill(0.65, 0.15)).Shape();
  const std::string brep = test::brepText(holed);
  const CadModel cad = CadModel::fromBrepText(brep);
  BoundaryLayerParameters layer;
  for (int f = 1; f <= cad.numFaces(); ++f) {
    if (cad.isPlanar(f)) continue;
    const SurfaceBounds b = cad.faceBounds(f);
    const PrincipalCurvatures k =
        cad.curvature(f, 0.5 * (b.uMin + b.uMax), 0.5 * (b.vMin + b.vMax));
    if (std::abs(k.kMax) > 10.0) layer.faces.push_back(f);  // 1 / 0.08, not 1 / 0.15
  }
  ASSERT_FALSE(layer.faces.empty());
  layer.thickness = "0.03";
  layer.layers = 3;
  layer.progression = 1.3;
  MeshingOptions options;
  options.order = 2;
  options.size = 0.1;
  options.optimiseIterations = 20;
  options.threads = 2;
  options.fidelityWeight = 0.0;  // neither the term nor the stage
  options.boundaryLayer = layer;
  const MeshResult made = runMeshPipeline(CadSource::brepText(brep, "two holes"), options);
  ASSERT_TRUE(made.boundaryLayer.has_value());
  ASSERT_EQ(made.quality.invalid + made.quality.undecided, 0U);
  std::vector<char> layerNodes(made.mesh.numNodes(), 0);
  for (const ElementBlock& b : made.mesh.blocks)
    if (b.type == CellType::Prism)
      for (const std::int64_t node : b.nodes) layerNodes[static_cast<std::size_t>(node)] = 1;
  // Over the triangles on curved faces, on the wall or off it: the largest of their largest
  // squared sines, and their sum.
  struct Sines {
    double largest = 0.0, sum = 0.0;
  };
  const auto sines = [&](const Mesh& mesh, bool onWall) {
    Mesh copy = mesh;  // the fitter holds a mesh it may move
    BoundaryFitter fitter(copy, *made.cad);
    const std::vector<double> each = fitter.largestSines();
    const std::vector<char> wall = fitter.touching(layerNodes);
    Sines out;
    for (std::size_t t = 0; t < each.size(); ++t) {
      if ((wall[t] != 0) != onWall || !std::isfinite(each[t])) continue;
      out.largest = std::max(out.largest, each[t]);
      out.sum += each[t];
    }
    return out;
  };
  const Sines wallBefore = sines(made.mesh, true), freeBefore = sines(made.mesh, false);
  ASSERT_GT(wallBefore.largest, freeBefore.largest);  // the case's point
  Mesh mesh = made.mesh;
  QualitySummary quality = made.quality;
  const BoundaryFitRecord record = fitBoundaryFidelity(mesh, quality, *made.cad, 2);
  const Sines wallAfter = sines(mesh, true), freeAfter = sines(mesh, false);
  std::printf(
      "beside a layer: %zu of %zu triangles fitted in %zu tiers; largest squared sine on "
      "the wall %.3g; off it %.3g -> %.3g, their sum %.3g -> %.3g\n",
      record.fitted, record.triangles, record.tiers, wallBefore.largest, freeBefore.largest,
      freeAfter.largest, freeBefore.sum, freeAfter.sum);
  EXPECT_GT(record.fitted, 0U);
  EXPECT_LT(freeAfter.sum, freeBefore.sum);
  EXPECT_EQ(wallAfter.sum, wallBefore.sum);
  for (std::size_t node = 0; node < mesh.numNodes(); ++node) {
    if (layerNodes[node] == 0) continue;
    for (int c = 0; c < 3; ++c) ASSERT_EQ(mesh.xyz[3 * node + c], made.mesh.xyz[3 * node + c]);
  }
  const QualitySummary measured = evaluateQuality(mesh, 2);
  EXPECT_EQ(measured.invalid + measured.undecided, 0U);
}

// Vertex patches (BoundaryFitter::fitVertices) on the unit sphere at order 2, where the
// optimiser's sliding left edges spanning up to 87 degrees of arc and only the corners can
// shorten them (the optimiser had stretched one from at most 68): some are kept, their vertices
// stay on the sphere (to rounding: the chart's point), and no patch raises the largest angle the
// report measures (each is checked at the report's own points, the corners included, where the
// fit's rule has none), so neither does the mesh's, the patches sharing no triangle. The patches
// are not certified here: the stage does that (BoundaryFit.FollowsTheSphere... above).
TEST(BoundaryFit, VertexPatchesMoveCornersOnTheFaceWithoutRaisingTheLargestAngle) {
  const MeshResult& made = sphereInABox(2);
  ASSERT_TRUE(made.geometry.has_value());
  Mesh mesh = made.mesh;
  BoundaryFitter fitter(mesh, *made.cad);
  const std::vector<std::int64_t> vertices = fitter.starVertices();
  ASSERT_FALSE(vertices.empty());
  std::vector<char> blocked(fitter.triangles(), 0);
  std::vector<std::int64_t> chosen;
  for (const std::int64_t v : vertices) {
    const std::vector<std::size_t> star = fitter.starOf(v);
    ASSERT_GE(star.size(), 3U) << "vertex " << v;
    if (std::any_of(star.begin(), star.end(), [&](std::size_t t) { return blocked[t] != 0; }))
      continue;
    chosen.push_back(v);
    for (const std::size_t t : star) blocked[t] = 1;
  }
  const std::vector<std::vector<std::int64_t>> moved = fitter.fitVertices(chosen);
  ASSERT_EQ(moved.size(), chosen.size());
  std::size_t kept = 0;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    if (moved[i].empty()) continue;
    ++kept;
    const auto v = static_cast<std::size_t>(chosen[i]);
    EXPECT_NE(std::find(moved[i].begin(), moved[i].end(), chosen[i]), moved[i].end());
    const double radius = std::hypot(mesh.xyz[3 * v], mesh.xyz[3 * v + 1], mesh.xyz[3 * v + 2]);
    EXPECT_NEAR(radius, 1.0, 1e-9) << "vertex " << v;
  }
  const GeometryAccuracy after = measureGeometryAccuracy(mesh, *made.cad, 2);
  std::printf("vertex patches: %zu of %zu kept; largest angle %.4g -> %.4g deg\n", kept,
              chosen.size(), made.geometry->maxAngleDeg, after.maxAngleDeg);
  EXPECT_GT(kept, 0U);
  EXPECT_NE(mesh.xyz, made.mesh.xyz);
  EXPECT_LE(after.maxAngleDeg, made.geometry->maxAngleDeg * (1.0 + 1e-9));
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
