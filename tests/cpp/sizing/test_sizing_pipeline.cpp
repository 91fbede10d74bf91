// Linear meshes made from the sizing octree: .mcf cases (NekMesh's peer cases where they are
// here, and cases the tests write themselves), prediction against the actual count, element
// sizes against the specification, a tight turn inside a long spline, EPS halving, several
// solids.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <gp_Pln.hxx>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "peer_data.hpp"
#include "pipeline/case_setup.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "sizing/sizing_parameters.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

std::string peerCase(const std::string& name) {
  return test::peerFile("meshgen/" + name + ".mcf");
}

// ---- Cases the tests write: CAD made with OCCT and written as STEP, which OCCT writes in
// millimetres and a .mcf reads in metres (x 0.001), and .mcf text with the tests' own values.

using Keys = std::vector<std::pair<std::string, std::string>>;

// A .mcf with the given INFORMATION properties, PARAMETERS and BOOLPARAMETERS.
std::string writeMcf(const std::filesystem::path& path, const Keys& information,
                     const Keys& parameters, const std::vector<std::string>& flags = {}) {
  std::ofstream out(path);
  out << "<NEKTAR>\n<MESHING>\n<INFORMATION>\n";
  for (const auto& [key, value] : information)
    out << "  <I PROPERTY=\"" << key << "\" VALUE=\"" << value << "\" />\n";
  out << "</INFORMATION>\n<PARAMETERS>\n";
  for (const auto& [key, value] : parameters)
    out << "  <P PARAM=\"" << key << "\" VALUE=\"" << value << "\" />\n";
  out << "</PARAMETERS>\n<BOOLPARAMETERS>\n";
  for (const std::string& flag : flags) out << "  <P VALUE=\"" << flag << "\" />\n";
  out << "</BOOLPARAMETERS>\n</MESHING>\n</NEKTAR>\n";
  if (!out) throw Error("cannot write " + path.string());
  return path.string();
}

// The sphere case in metres: 3D, MinDelta 0.03, MaxDelta 0.2, EPS 0.01 (the sphere's chord
// size 0.0705 lies between them), order 3, and a NekMesh option HOMesh does not use. (With
// MaxDelta 0.25 the box is only 3 elements thick and the prediction falls to 0.93 of the
// count: the 10 % holds where the domain is several elements thick.)
std::string writeSphereCase(const std::filesystem::path& dir) {
  test::writeStep(test::hemisphereInBox(250.0), dir / "hemisphere.step");  // mm
  return writeMcf(dir / "hemisphere.mcf", {{"CADFile", "hemisphere.step"}, {"MeshType", "3D"}},
                  {{"MinDelta", "0.03"}, {"MaxDelta", "0.2"}, {"EPS", "0.01"}, {"Order", "3"}},
                  {"SurfaceOptimiser"});
}

// A channel 1 x 0.6 x 0.3 m with a cylinder of radius 0.1 m across it (along z), its wall asked
// for a boundary layer; MaxDelta 0.06, 5 elements across the channel's depth.
std::string writeCylinderCase(const std::filesystem::path& dir) {
  const TopoDS_Shape channel = BRepPrimAPI_MakeBox(1000.0, 600.0, 300.0).Shape();
  const TopoDS_Shape rod =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(300, 300, -100), gp_Dir(0, 0, 1)), 100.0, 500.0)
          .Shape();
  const std::filesystem::path step = dir / "channel.step";
  test::writeStep(BRepAlgoAPI_Cut(channel, rod).Shape(), step);
  int wall = 0;  // the cylinder's face, in the numbering of the STEP as read back
  const CadModel cad = CadModel::fromFile(step.string());
  for (int f = 1; f <= cad.numFaces(); ++f)
    if (!cad.isPlanar(f)) wall = f;
  return writeMcf(dir / "channel.mcf", {{"CADFile", "channel.step"}, {"MeshType", "3DBndLayer"}},
                  {{"MinDelta", "0.02"},
                   {"MaxDelta", "0.06"},
                   {"EPS", "0.05"},
                   {"Order", "2"},
                   {"BndLayerSurfaces", std::to_string(wall)},
                   {"BndLayerThickness", "0.01"},
                   {"BndLayerLayers", "3"}});
}

// A NACA 4412 at 5 degrees in [-1, 2.5] x [-1.5, 1.5], built by the reader from CADFile "4412".
std::string writeNacaCase(const std::filesystem::path& dir) {
  return writeMcf(dir / "naca.mcf", {{"CADFile", "4412"}, {"MeshType", "2D"}},
                  {{"MinDelta", "0.01"},
                   {"MaxDelta", "0.4"},
                   {"EPS", "0.05"},
                   {"Order", "2"},
                   {"Xmin", "-1.0"},
                   {"Ymin", "-1.5"},
                   {"Xmax", "2.5"},
                   {"Ymax", "1.5"},
                   {"AOA", "5.0"}});
}

// A slender blade 0.75 long and 0.1 thick: one interpolating B-spline through the half ellipse
// (0.75 cos t, 0.05 sin t), t in [-pi/2, pi/2], turning through 180 degrees at its tip within the
// ellipse's end radius 0.05^2 / 0.75 = 0.0033 on a curve 1.5 long, closed by the segment x = 0.
// Its points are even in t, hence dense at the tip, and OCCT parametrises by chord length: the
// turn takes about 2 % of the parameter range.
TopoDS_Shape blade(double unit) {
  const int n = 81;
  Handle(TColgp_HArray1OfPnt) points = new TColgp_HArray1OfPnt(1, n);
  for (int i = 1; i <= n; ++i) {
    const double t = M_PI * (double(i - 1) / double(n - 1) - 0.5);
    points->SetValue(i, gp_Pnt(0.75 * unit * std::cos(t), 0.05 * unit * std::sin(t), 0.0));
  }
  // Rounded ends of the parameters: the first and last points are exactly (0, -+0.05).
  points->SetValue(1, gp_Pnt(0.0, -0.05 * unit, 0.0));
  points->SetValue(n, gp_Pnt(0.0, 0.05 * unit, 0.0));
  GeomAPI_Interpolate interpolate(points, false, Precision::Confusion());
  interpolate.Perform();
  const TopoDS_Edge side = BRepBuilderAPI_MakeEdge(interpolate.Curve()).Edge();
  const TopoDS_Edge back = BRepBuilderAPI_MakeEdge(points->Value(n), points->Value(1)).Edge();
  return BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakeWire(side, back).Wire(), true).Face();
}

// A 2D case: the plate [-0.5, 1.5] x [-0.5, 0.5] m with the blade cut out; EPS 1 and MinDelta
// 0.005, so that the blade's tip gets its curvature size 2 x 0.0033 rather than the clamp.
std::string writeBladeCase(const std::filesystem::path& dir) {
  const TopoDS_Face plate =
      BRepBuilderAPI_MakeFace(gp_Pln(gp::XOY()), -500.0, 1500.0, -500.0, 500.0).Face();
  test::writeStep(BRepAlgoAPI_Cut(plate, blade(1000.0)).Shape(), dir / "blade.step");
  return writeMcf(dir / "blade.mcf", {{"CADFile", "blade.step"}, {"MeshType", "2D"}},
                  {{"MinDelta", "0.005"}, {"MaxDelta", "0.2"}, {"EPS", "1.0"}, {"Order", "2"}});
}

std::string writeMadeCase(const std::string& name, const std::filesystem::path& dir) {
  if (name == "hemisphere") return writeSphereCase(dir);
  if (name == "channel") return writeCylinderCase(dir);
  if (name == "naca4412") return writeNacaCase(dir);
  if (name == "blade") return writeBladeCase(dir);
  throw Error("no made case " + name);
}

// The case's linear mesh without its boundary layer: what the sizing predicts (a layer takes the
// place of some of the predicted elements; its own tests are under boundary_layer/).
MeshResult meshCase(const std::string& mcf, int order = 1) {
  CaseSetup setup = setupCase(mcf);
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

// Prediction and sizes of a case's linear mesh (properties of the sizing, for any case).
void checkPredictionAndSizes(const MeshResult& r) {
  ASSERT_TRUE(r.sizing.has_value());
  const double predicted = r.sizing->prediction.elements;
  const auto actual = static_cast<double>(r.mesh.numElements());
  ::testing::Test::RecordProperty("predicted", std::to_string(predicted));
  ::testing::Test::RecordProperty("actual", std::to_string(actual));
  // The prediction's promised accuracy (15 %): the 3D model is within 0.899 .. 1.096 of the made
  // count on its 36 calibration shapes and 0.958 .. 1.085 on the twelve of bench/prediction_shapes
  // it was not fitted on; NekMesh's 3D cases, also not fitted on, are its largest misses (3d_bl_cyl
  // 1.115, 3d_sphere 1.067; the 2D cases 1.010 .. 1.035). Gmsh's 3D element count moves by up to
  // 2 % when the CAD's scale and the sizes change by 1e-12 relative (2D: not at all; 1 or 2
  // threads: not at all): 11.5 % plus twice that move (bench/tolerance_sensitivity).
  EXPECT_NEAR(predicted / actual, 1.0, 0.15) << predicted << " predicted, " << actual << " made";
  EXPECT_GE(fractionOfEdgesWithinSpec(r.mesh, *r.sizing->octree), 0.90);  // measured 1.00
  // Every boundary node keeps its CAD entity.
  const ElementBlock& b = boundaryBlock(r.mesh);
  for (const std::int64_t n : b.nodes) {
    ASSERT_LE(r.mesh.nodeCadDim[n], r.mesh.dim - 1);
    ASSERT_GT(r.mesh.nodeCadIndex[n], 0);
  }
}

class PeerCase : public ::testing::TestWithParam<const char*> {};

TEST_P(PeerCase, PredictionWithinFifteenPercentAndSizesFollowTheSpecification) {
  HOMESH_REQUIRE_PEER_FILES();
  checkPredictionAndSizes(meshCase(peerCase(GetParam())));
}

INSTANTIATE_TEST_SUITE_P(NekMeshMeshgen, PeerCase,
                         ::testing::Values("3d_sphere", "3d_bl_cyl", "2d_bl_aerofoil", "2d_bl_t106",
                                           "2d_bl_naca0012"));

// The same on cases of the same kinds that the test writes: a sphere in a box, a cylinder with
// a boundary-layer wall (3D), a NACA domain and a plate with a slender blade (2D).
class MadeCase : public ::testing::TestWithParam<const char*> {};

TEST_P(MadeCase, PredictionWithinFifteenPercentAndSizesFollowTheSpecification) {
  checkPredictionAndSizes(meshCase(writeMadeCase(GetParam(), test::tempDir())));
}

INSTANTIATE_TEST_SUITE_P(Written, MadeCase,
                         ::testing::Values("hemisphere", "channel", "naca4412", "blade"));

// Checks that the edge's tightest turn (by dense sampling) has its curvature size in the octree
// and in the mesh (EPS 1), and returns that turn's point.
Eigen::Vector3d checkTightTurn(const MeshResult& r, int edge, double minDelta) {
  const CadModel& cad = *r.cad;
  const ParameterRange range = cad.edgeRange(edge);
  double kMax = 0.0;
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
  for (int i = 0; i <= 200000; ++i) {
    const CurveDerivatives c =
        cad.evaluateCurve(edge, range.first + (range.last - range.first) * i / 200000.0);
    const double k = c.d1.cross(c.d2).norm() / std::pow(c.d1.norm(), 3);
    if (k > kMax) {
      kMax = k;
      tip = c.point;
    }
  }
  EXPECT_GT(kMax, 100.0);                                              // radius under 0.01
  const double size = std::max(minDelta, chordSize(1.0 / kMax, 1.0));  // EPS 1
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
  return tip;
}

// T106's blade is one spline per side whose trailing edge turns through 180 degrees within a
// radius of about 0.005 on a curve 1.5 long: 40 samples evenly spaced in its parameter found
// none of that turn, and the mesh there had edges 0.09 long (the octree's size there 0.24).
// Halving every sample interval along which the tangent turns further than the size rule
// allows finds it: the linear mesh's edges at the edge are within twice the curvature size
// (the largest curvature on the CAD by dense sampling; twice: between two samples the
// curvature can peak above what both see, by at most the turn they allow, 0.5 rad at EPS 1).
TEST(SizingPipeline, T106TrailingEdgeGetsItsCurvatureSize) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshCase(peerCase("2d_bl_t106"));
  ASSERT_TRUE(r.sizing.has_value());
  // Edge12: the pressure side and the trailing edge; MinDelta 0.01.
  const Eigen::Vector3d tip = checkTightTurn(r, 12, 0.01);
  EXPECT_NEAR(tip.x(), 0.853, 0.01);  // at the trailing edge
}

// The same on the made blade: one spline 1.5 long turning at its tip within a radius of 0.0033.
TEST(SizingPipeline, TightTurnInsideALongSplineGetsItsCurvatureSize) {
  const MeshResult r = meshCase(writeBladeCase(test::tempDir()));
  ASSERT_TRUE(r.sizing.has_value());
  int spline = 0;  // the edge whose middle is near the tip (the plate's and the back's are not)
  for (int e = 1; e <= r.cad->numEdges(); ++e) {
    const ParameterRange range = r.cad->edgeRange(e);
    const Eigen::Vector3d m = r.cad->evaluateCurve(e, 0.5 * (range.first + range.last)).point;
    if (std::abs(m.y()) < 0.1 && m.x() > 0.1 && m.x() < 1.0) spline = e;
  }
  ASSERT_GT(spline, 0);
  const Eigen::Vector3d tip = checkTightTurn(r, spline, 0.005);
  // The ellipse's tip (0.75, 0); the spline interpolates it (it is one of the points).
  EXPECT_NEAR(tip.x(), 0.75, 0.01);
  EXPECT_NEAR(tip.y(), 0.0, 0.01);
}

// Boundary triangles on the sphere's (curved) faces: their number scales with 1/delta^2, and
// delta = 2 R sqrt(eps (2 - eps)) there.
double sphereTriangles(const std::string& mcf, double eps) {
  CaseSetup setup = setupCase(mcf);
  setup.options.order = 1;
  setup.options.sizing->eps = eps;
  const MeshResult r = runMeshPipeline(setup.source, setup.options);
  const CadModel& cad = *r.cad;
  const ElementBlock& b = boundaryBlock(r.mesh);
  std::size_t count = 0;
  for (std::size_t e = 0; e < b.count(); ++e) count += cad.isPlanar(b.entity[e]) ? 0 : 1;
  return static_cast<double>(count);
}

TEST(SizingPipeline, HalvingEpsRefinesTheSphereAsTheChordFormulaPredicts) {
  HOMESH_REQUIRE_PEER_FILES();
  // R = 0.25 m; both sizes lie within [MinDelta, MaxDelta] = [0.04, 0.2].
  const std::string mcf = peerCase("3d_sphere");
  const double coarse = sphereTriangles(mcf, 0.02), fine = sphereTriangles(mcf, 0.01);
  const double expected = std::pow(chordSize(0.25, 0.02) / chordSize(0.25, 0.01), 2.0);  // 1.99
  EXPECT_GT(chordSize(0.25, 0.01), 0.04);  // above MinDelta: the formula, not the clamp, decides
  // The 1 / delta^2 law holds up to the mesh's discretisation (15 %). Measured 0.881 of it;
  // the surface mesh did not change under 1e-12 perturbations of the CAD's scale.
  EXPECT_NEAR(fine / coarse, expected, 0.15 * expected) << coarse << " -> " << fine;
}

// The same on the made hemisphere (R = 0.25 m, an exact sphere), EPS 0.01 and 0.005.
TEST(SizingPipeline, HalvingEpsRefinesAMadeSphereAsTheChordFormulaPredicts) {
  const std::string mcf = writeSphereCase(test::tempDir());
  const double coarse = sphereTriangles(mcf, 0.01), fine = sphereTriangles(mcf, 0.005);
  const double expected = std::pow(chordSize(0.25, 0.01) / chordSize(0.25, 0.005), 2.0);  // 1.99
  // Both sizes within [MinDelta, MaxDelta] = [0.03, 0.2]: the formula, not the clamp, decides.
  EXPECT_GT(chordSize(0.25, 0.005), 0.03);
  EXPECT_LT(chordSize(0.25, 0.01), 0.2);
  // The 1 / delta^2 law up to the mesh's discretisation (15 %, as above). Measured 0.984 of it
  // (190 -> 373 triangles), unchanged when the CAD's scale and the sizes move by 1e-12.
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
  // The promised 15 % (checkPredictionAndSizes says why); measured 1.108 (no calibration shape
  // has several solids: the faces between them count twice in the boundary term and bound the
  // core on both sides).
  EXPECT_NEAR(r.sizing->prediction.elements / actual, 1.0, 0.15);
  // Tetrahedra in both solids.
  std::vector<int> perSolid(3, 0);
  for (const std::int32_t s2 : r.mesh.blocks[0].entity) ++perSolid[s2];
  EXPECT_GT(perSolid[1], 0);
  EXPECT_GT(perSolid[2], 0);
}

TEST(SizingPipeline, McfSetupReadsTheCaseInMetres) {
  HOMESH_REQUIRE_PEER_FILES();
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

// The same on a case the test writes: its STEP in millimetres (OCCT's unit), its values its own.
TEST(SizingPipeline, McfSetupReadsAWrittenCaseInMetres) {
  const auto dir = test::tempDir();
  const CaseSetup s = setupCase(writeSphereCase(dir));
  EXPECT_TRUE(s.fromMcf);
  EXPECT_EQ(s.options.order, 3);
  EXPECT_EQ(s.options.expectedDimension, 3);
  EXPECT_FALSE(s.options.boundaryLayer.has_value());
  ASSERT_TRUE(s.options.sizing.has_value());
  // Parsed decimals are the correctly rounded literals: exact.
  EXPECT_EQ(s.options.sizing->minDelta, 0.03);
  EXPECT_EQ(s.options.sizing->maxDelta, 0.2);
  EXPECT_EQ(s.options.sizing->eps, 0.01);
  EXPECT_EQ(s.source.scale, 0.001);
  EXPECT_EQ(s.options.sizing->thinWall, 0.0);
  EXPECT_EQ(s.options.sizing->narrowFace, 0.0);
  const CadModel cad = s.source.load();
  // The box 4 x 2 x 0.75 m; OCCT's optimal box to its precision (1e-7 mm, 1e-10 m here).
  EXPECT_NEAR(cad.boundingDiagonal(), std::sqrt(16.0 + 4.0 + 0.75 * 0.75), 1e-6);
  ASSERT_FALSE(s.notices.empty());
  EXPECT_NE(s.notices[0].find("SurfaceOptimiser"), std::string::npos);
  // A boundary-layer case: its keys, read as the layer's parameters.
  const CaseSetup channel = setupCase(writeCylinderCase(dir));
  ASSERT_TRUE(channel.options.boundaryLayer.has_value());
  EXPECT_EQ(channel.options.boundaryLayer->faces.size(), 1u);
  EXPECT_EQ(channel.options.boundaryLayer->thickness, "0.01");
  EXPECT_EQ(channel.options.boundaryLayer->layers, 3);
  // A NACA case: the domain is built, not read, so no unit change.
  const CaseSetup naca = setupCase(writeNacaCase(dir));
  EXPECT_EQ(naca.source.kind, CadSource::Kind::Naca);
  EXPECT_EQ(naca.source.naca.digits, "4412");
  EXPECT_EQ(naca.source.naca.aoaDegrees, 5.0);
  EXPECT_EQ(naca.source.naca.xmin, -1.0);
  EXPECT_EQ(naca.source.naca.ymax, 1.5);
  EXPECT_EQ(naca.options.expectedDimension, 2);
}

TEST(SizingPipeline, AutomaticSizingWithoutParameters) {
  MeshingOptions options;
  options.order = 1;
  const MeshResult r =
      runMeshPipeline(CadSource::brepText(test::brepText(test::sphere(1.0))), options);
  ASSERT_TRUE(r.sizing.has_value());
  EXPECT_NEAR(r.sizing->octree->parameters().maxDelta, r.cad->boundingDiagonal() / 20.0, 1e-12);
  // The promised 15 % (checkPredictionAndSizes says why); this sphere is one of the calibration
  // shapes of bench/prediction_shapes (fitted / made 0.979).
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
