// Linear meshes made from the sizing octree: NekMesh's peer cases (.mcf), prediction against
// the actual count, element sizes against the specification, a tight turn inside a long spline,
// EPS halving, several solids.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "pipeline/case_setup.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "sizing/sizing_parameters.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

std::string peerCase(const std::string& name) {
  return std::string(HOMESH_SHARED_DIR) + "/peer-cases/nekmesh/meshgen/" + name + ".mcf";
}

// The case's linear mesh without its boundary layer: what the sizing predicts (a layer takes the
// place of some of the predicted elements; its own tests are pipeline/test_boundary_layer.cpp).
MeshResult meshCase(const std::string& name, int order = 1) {
  CaseSetup setup = setupCase(peerCase(name));
  setup.options.order = order;
  setup.options.boundaryLayer.reset();
  return runMeshPipeline(setup.source, setup.options);
}

const ElementBlock& boundaryBlock(const Mesh& mesh) {
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == mesh.dim - 1) return b;
  throw Error("no boundary block");
}

// Fraction of the boundary edges (of triangles on CAD faces in 3D, lines on curves in 2D)
// whose length / delta(midpoint) lies in [0.5, 1.5].
double fractionOfEdgesWithinSpec(const Mesh& mesh, const SizingOctree& octree) {
  const ElementBlock& b = boundaryBlock(mesh);
  const int nv = cellNumVertices(b.type);
  std::size_t good = 0, total = 0;
  for (std::size_t e = 0; e < b.count(); ++e) {
    const std::int64_t* n = b.element(e);
    for (int k = 0; k < (nv == 2 ? 1 : 3); ++k) {
      const Eigen::Vector3d p = test::nodePoint(mesh, n[k]);
      const Eigen::Vector3d q = test::nodePoint(mesh, n[(k + 1) % nv]);
      const double ratio = (p - q).norm() / octree.delta(0.5 * (p + q));
      good += (ratio >= 0.5 && ratio <= 1.5) ? 1 : 0;
      ++total;
    }
  }
  return double(good) / double(total);
}

class PeerCase : public ::testing::TestWithParam<const char*> {};

TEST_P(PeerCase, PredictionWithinTenPercentAndSizesFollowTheSpecification) {
  const MeshResult r = meshCase(GetParam());
  ASSERT_TRUE(r.sizing.has_value());
  const double predicted = r.sizing->prediction.elements;
  const auto actual = static_cast<double>(r.mesh.numElements());
  RecordProperty("predicted", std::to_string(predicted));
  RecordProperty("actual", std::to_string(actual));
  // The prediction's promised accuracy (10 %). Measured 0.986 .. 1.055; Gmsh's 3D element count
  // moves by up to 2 % when the CAD's scale and the sizes change by 1e-12 relative (2D: not at
  // all), so the margin is at least twice the largest move (bench/tolerance_sensitivity).
  EXPECT_NEAR(predicted / actual, 1.0, 0.10) << predicted << " predicted, " << actual << " made";
  EXPECT_GE(fractionOfEdgesWithinSpec(r.mesh, *r.sizing->octree), 0.90);  // measured 1.00
  // Every boundary node keeps its CAD entity.
  const ElementBlock& b = boundaryBlock(r.mesh);
  for (const std::int64_t n : b.nodes) {
    ASSERT_LE(r.mesh.nodeCadDim[n], r.mesh.dim - 1);
    ASSERT_GT(r.mesh.nodeCadIndex[n], 0);
  }
}

INSTANTIATE_TEST_SUITE_P(NekMeshMeshgen, PeerCase,
                         ::testing::Values("3d_sphere", "3d_bl_cyl", "2d_bl_aerofoil", "2d_bl_t106",
                                           "2d_bl_naca0012"));

// T106's blade is one spline per side whose trailing edge turns through 180 degrees within a
// radius of about 0.005 on a curve 1.5 long: 40 samples evenly spaced in its parameter found
// none of that turn, and the mesh there had edges 0.09 long (the octree's size there 0.24).
// Halving every sample interval along which the tangent turns further than the size rule
// allows finds it: the linear mesh's edges at the edge are within twice the curvature size
// (the largest curvature on the CAD by dense sampling; twice: between two samples the
// curvature can peak above what both see, by at most the turn they allow, 0.5 rad at EPS 1).
TEST(SizingPipeline, T106TrailingEdgeGetsItsCurvatureSize) {
  const MeshResult r = meshCase("2d_bl_t106");
  ASSERT_TRUE(r.sizing.has_value());
  const CadModel& cad = *r.cad;
  const int blade = 12;  // Edge12: the pressure side and the trailing edge
  const ParameterRange range = cad.edgeRange(blade);
  double kMax = 0.0;
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
  for (int i = 0; i <= 200000; ++i) {
    const CurveDerivatives c =
        cad.evaluateCurve(blade, range.first + (range.last - range.first) * i / 200000.0);
    const double k = c.d1.cross(c.d2).norm() / std::pow(c.d1.norm(), 3);
    if (k > kMax) {
      kMax = k;
      tip = c.point;
    }
  }
  ASSERT_GT(kMax, 100.0);                                          // radius under 0.01
  ASSERT_NEAR(tip.x(), 0.853, 0.01);                               // at the trailing edge
  const double size = std::max(0.01, chordSize(1.0 / kMax, 1.0));  // MinDelta 0.01, EPS 1
  EXPECT_LE(r.sizing->octree->delta(tip), 2.0 * size);
  const ElementBlock& b = boundaryBlock(r.mesh);
  std::size_t near = 0;
  for (std::size_t e = 0; e < b.count(); ++e) {
    const Eigen::Vector3d p = test::nodePoint(r.mesh, b.element(e)[0]);
    const Eigen::Vector3d q = test::nodePoint(r.mesh, b.element(e)[1]);
    if ((0.5 * (p + q) - tip).norm() > 0.02) continue;
    ++near;
    EXPECT_LE((p - q).norm(), 2.0 * size) << "edge at " << (0.5 * (p + q)).transpose();
  }
  EXPECT_GE(near, 2U);
}

TEST(SizingPipeline, HalvingEpsRefinesTheSphereAsTheChordFormulaPredicts) {
  // Boundary triangles on the sphere's (curved) faces: their number scales with 1/delta^2, and
  // delta = 2 R sqrt(eps (2 - eps)) there (R = 0.25 m; both sizes lie within [MinDelta, MaxDelta]).
  const auto sphereTriangles = [](double eps) {
    CaseSetup setup = setupCase(peerCase("3d_sphere"));
    setup.options.order = 1;
    setup.options.sizing->eps = eps;
    const MeshResult r = runMeshPipeline(setup.source, setup.options);
    const CadModel& cad = *r.cad;
    const ElementBlock& b = boundaryBlock(r.mesh);
    std::size_t count = 0;
    for (std::size_t e = 0; e < b.count(); ++e) count += cad.isPlanar(b.entity[e]) ? 0 : 1;
    return static_cast<double>(count);
  };
  const double coarse = sphereTriangles(0.02), fine = sphereTriangles(0.01);
  const double expected = std::pow(chordSize(0.25, 0.02) / chordSize(0.25, 0.01), 2.0);  // 1.99
  EXPECT_GT(chordSize(0.25, 0.01), 0.04);  // above MinDelta: the formula, not the clamp, decides
  // The 1 / delta^2 law holds up to the mesh's discretisation (15 %). Measured 0.881 of it;
  // the surface mesh did not change under 1e-12 perturbations of the CAD's scale.
  EXPECT_NEAR(fine / coarse, expected, 0.15 * expected) << coarse << " -> " << fine;
}

TEST(SizingPipeline, SeveralSolidsWithAnInternalFace) {
  // Two boxes sharing a face (general fuse keeps both solids and the shared face once).
  const TopoDS_Shape twoBoxes = test::twoBoxes();
  const CadModel cad = test::toModel(twoBoxes);
  ASSERT_EQ(cad.numSolids(), 2);
  SizingParameters p;
  p.minDelta = 0.1;
  p.maxDelta = 0.2;
  const SizingResult s = runSizing(cad, p);
  // The octree's classification of sub-cells (1 %): measured 2.006, unchanged when the boxes
  // are scaled by 1 +- 1e-12.
  EXPECT_NEAR(s.prediction.domainMeasure, 2.0, 0.02);
  MeshingOptions options;
  options.order = 1;
  options.sizing = p;
  const MeshResult r = runMeshPipeline(CadSource::brepText(test::brepText(twoBoxes)), options);
  const auto actual = static_cast<double>(r.mesh.numElements());
  // Promised 10 %; measured 0.964 .. 0.972 over 1e-12 perturbations of the boxes' size.
  EXPECT_NEAR(r.sizing->prediction.elements / actual, 1.0, 0.10);
  // Tetrahedra in both solids.
  std::vector<int> perSolid(3, 0);
  for (const std::int32_t s2 : r.mesh.blocks[0].entity) ++perSolid[s2];
  EXPECT_GT(perSolid[1], 0);
  EXPECT_GT(perSolid[2], 0);
}

TEST(SizingPipeline, McfSetupReadsTheCaseInMetres) {
  const CaseSetup s = setupCase(peerCase("3d_sphere"));
  EXPECT_TRUE(s.fromMcf);
  EXPECT_EQ(s.options.order, 4);
  ASSERT_TRUE(s.options.sizing.has_value());
  // Parsed decimals are the correctly rounded literals: equal (DOUBLE_EQ's 4 ulps are slack).
  EXPECT_DOUBLE_EQ(s.options.sizing->minDelta, 0.04);
  EXPECT_DOUBLE_EQ(s.options.sizing->maxDelta, 0.2);
  EXPECT_DOUBLE_EQ(s.options.sizing->eps, 0.02);
  EXPECT_DOUBLE_EQ(s.source.scale, 0.001);
  // NekMesh's sizes are kept as NekMesh computes them: no bound of ours on top.
  EXPECT_EQ(s.options.sizing->thinWall, 0.0);
  EXPECT_EQ(s.options.sizing->narrowFace, 0.0);
  const CadModel cad = s.source.load();
  // OCCT's optimal box finds the sphere's extremes to its precision (1e-7 mm, 1e-10 m here).
  EXPECT_NEAR(cad.boundingDiagonal(), std::sqrt(16.0 + 4.0 + 0.75 * 0.75), 1e-6);
  // SurfaceOptimiser is NekMesh's and not ours: reported, not silently ignored.
  ASSERT_FALSE(s.notices.empty());
  EXPECT_NE(s.notices[0].find("SurfaceOptimiser"), std::string::npos);
  const CaseSetup naca = setupCase(peerCase("2d_bl_naca0012"));
  EXPECT_EQ(naca.source.kind, CadSource::Kind::Naca);
  EXPECT_EQ(naca.source.naca.digits, "0012");
  EXPECT_DOUBLE_EQ(naca.source.naca.aoaDegrees, 15.0);
}

TEST(SizingPipeline, AutomaticSizingWithoutParameters) {
  MeshingOptions options;
  options.order = 1;
  const MeshResult r =
      runMeshPipeline(CadSource::brepText(test::brepText(test::sphere(1.0))), options);
  ASSERT_TRUE(r.sizing.has_value());
  EXPECT_NEAR(r.sizing->octree->parameters().maxDelta, r.cad->boundingDiagonal() / 20.0, 1e-12);
  // Measured 0.9998 (0.997 .. 1.001 over 1e-12 perturbations of the CAD): 15 % is slack.
  EXPECT_NEAR(r.sizing->prediction.elements / double(r.mesh.numElements()), 1.0, 0.15);
  MeshingOptions both = options;
  both.size = 0.3;
  both.sizing = SizingParameters{};
  EXPECT_THROW(runMeshPipeline(CadSource::brepText(test::brepText(test::sphere(1.0))), both),
               ParameterError);
}

TEST(SizingPipeline, RefusesSizesTooSmallForTheModel) {
  SizingParameters p;
  p.minDelta = 1e-4;
  p.maxDelta = 1e-4;
  const CadModel cad = test::toModel(test::box(1.0, 1.0, 1.0));
  try {
    runSizing(cad, p);
    FAIL();
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace homesh
