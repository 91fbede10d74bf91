// The 3D layer through the whole pipeline: NekMesh's 3d_bl_cyl (peer files) and a box with a
// cylindrical hole made in the test, certified valid with their layers, the first layer's height,
// the split's nodes on the CAD, the files read back, and the raise to order 6; a cube in a box
// and a cylinder on a plate (sharp convex and concave edges), a block on a stilt and the issue's
// blunt wing.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <Geom_BSplineCurve.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Ax2.hxx>
#include <gp_Dir.hxx>
#include <gp_Pnt.hxx>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "boundary_layer/boundary_layer.hpp"
#include "boundary_layer/layer_split.hpp"
#include "layer_case_checks.hpp"
#include "optimise/optimiser.hpp"
#include "peer_data.hpp"
#include "pipeline/case_setup.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// NekMesh's 3d_bl_cyl case: a cylinder (faces 1 and 8) in a box, thickness 0.04, 6 layers,
// progression 1.5, at order 2 with the optimiser (as docs/boundary-layers.md's example runs it).
// The meshing runs once for the suite, and only where the peer files are (SetUp skips each test
// otherwise).
class CylinderCase : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (test::havePeerFiles()) result_ = new MeshResult(meshPeerCase("3d_bl_cyl", 2));
  }
  static void TearDownTestSuite() {
    delete result_;
    result_ = nullptr;
  }
  void SetUp() override {
    HOMESH_REQUIRE_PEER_FILES();
    ASSERT_NE(result_, nullptr);
  }
  static MeshResult* result_;
};
MeshResult* CylinderCase::result_ = nullptr;

TEST_F(CylinderCase, IsCertifiedValidWithTheRequestedLayersInEveryWallColumn) {
  expectValidWithLayersInEveryWallColumn(*result_, {1, 8}, 6);
}

TEST_F(CylinderCase, SplitNodesLieOnTheCadAndTheReportSaysSo) {
  // The side nodes' move onto the end planes: measured 0.27 % of the layer's height at order 2
  // (rounding alone before the first level's shift).
  expectSplitNodesOnTheCad(*result_, "3d_bl_cyl.mcf", 6, 0.01);
}

TEST_F(CylinderCase, NektarAndGmshFilesCarryThePrismsAndReadBack) {
  expectNektarAndGmshFilesReadBack(*result_, "cyl");
}

// The order-4 cylinder, without the optimiser (the geometry as split; the optimiser is not the
// point), written as Nektar++ XML and read back.
TEST(BoundaryLayer, NektarXmlOfTheSplitLayerReadsBackEveryStoredNodeExactly) {
  HOMESH_REQUIRE_PEER_FILES();
  CaseSetup setup = setupCase(test::peerFile("meshgen/3d_bl_cyl.mcf"));
  setup.options.order = 4;
  setup.options.optimiseIterations = 0;
  setup.options.repairRounds = 0;
  const MeshResult r = runMeshPipeline(setup.source, setup.options);
  ASSERT_EQ(r.mesh.order, 4);
  expectNektarXmlStoresEveryNodeExactly(r, "cyl4");
}

// The first layer's height, measured along the wall's normal at the wall triangles' quadrature
// points, against thickness x (1 - r) / (1 - r^n): within the 5 % everywhere, on the
// acceptance's path (order 4, the optimiser on). This coarse case leaves one tetrahedron on the
// layer's top invalid with the layer fixed, so the optimiser lets the top slide parallel to the
// wall around it, and the split sets each column's levels from the grown height (measured:
// 4.1 %, against 9.7 % with the levels alone and 13 % with the top moving freely). The
// report's own figure (LayerSplitStats) is checked against this independent one.
constexpr double kEndBand = 0.05;
TEST(BoundaryLayer, FirstLayerHeightAlongTheWallNormalIsWithinFivePercent) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("3d_bl_cyl", 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  const double expected = 0.04 * (1 - 1.5) / (1 - std::pow(1.5, 6));
  double worst = 0.0, worstNearEnds = 0.0;
  std::size_t measured = 0;
  forEachFirstLayerHeight(r, {1, 8}, [&](const Eigen::Vector3d& bottom, double height) {
    const double dev = std::fabs(height / expected - 1);
    const bool nearEnd = bottom.z() < kEndBand || bottom.z() > 0.5 - kEndBand;
    (nearEnd ? worstNearEnds : worst) = std::max(nearEnd ? worstNearEnds : worst, dev);
    ++measured;
  });
  EXPECT_GT(measured, 0U);
  EXPECT_LE(worst, 0.05) << "worst relative deviation of the first-layer height";
  RecordProperty("first_layer_height_worst_relative_deviation", std::to_string(worst));
  EXPECT_LE(worstNearEnds, 0.05) << "near the end planes";
  RecordProperty("first_layer_height_worst_near_the_ends", std::to_string(worstNearEnds));
  // The report measures the same at the same points (with its own normals and its own search):
  // equal to what rounding and the searches' tolerance (1e-12 in reference coordinates) leave.
  EXPECT_NEAR(r.layerSplit->firstHeightDeviation, std::max(worst, worstNearEnds), 1e-9);
  EXPECT_EQ(r.layerSplit->firstHeightOffNormal, 0U);
  EXPECT_EQ(r.layerSplit->cornerCells, 0U);  // the cylinder's wall has no sharp corner
  EXPECT_LE(r.layerSplit->firstHeightMin, expected * (1 + 0.05));
  EXPECT_GE(r.layerSplit->firstHeightMin, expected * (1 - 0.05));
}

// Above order 4 the pipeline optimises at order 4 and raises the order after; the layer's inner
// nodes are then placed straight between the raised wall and the top again, which the split's
// levels assume, and the raise keeps the top's edges on the layer's sides (the cylinder's end
// faces) as the low order shaped them, parallel to the wall. Without the first the cylinder's
// first layer at order 6 was 47 % off its height; without the second 16 %, where the raise had
// placed those edges afresh, straight across the end faces: the top sagged to 0.018 above the
// wall where the layer is 0.04 thick. With both, 0.00 % (the levels are set per column, and the
// columns now have the height grown); 0.05 is what the 2D cases hold.
TEST(BoundaryLayer, AtOrderSixTheFirstLayerFollowsTheRaisedWall) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("3d_bl_cyl", 6);
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_GT(r.layerSplit->firstHeightMeasured, 0U);
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  RecordProperty("first_layer_height_worst_deviation",
                 std::to_string(r.layerSplit->firstHeightDeviation));
  // The order-6 optimiser's first sweep after the raise lifts the worst element from 0.24 to
  // 0.29; the second lowers it to 0.27 while it lowers the energy elsewhere, and it climbs back
  // from there (0.35 after 37 sweeps). The stall rule used to stop at the fourth sweep, the worst
  // still rising, because three sweeps had not beaten the first's. "stalled" now also needs the
  // worst to have stopped rising within the window: the pipeline's stall of 1e-3 over 3 sweeps
  // (pipelineOptimiserOptions in mesh_pipeline.cpp).
  ASSERT_TRUE(r.optimiser.has_value());
  expectStalledOnlyOnceTheWorstStoppedRising(*r.optimiser);
  EXPECT_GT(r.optimiser->worstAfter, r.optimiser->worstBefore);
}

// Siblings of the peer cases on shapes the tests make themselves, so that the boundary layer
// stays covered where NekMesh's files are not: the same properties, with bounds that follow from
// the method (or the 5 % on the first layer's height), not from the peer cases.

// A 1.0 x 0.8 x 0.4 box with a vertical cylindrical hole of radius 0.15 through it, off its
// centre (OCCT's cylinder: one periodic wall face with a seam), the layer on the hole's wall:
// 0.05 thick (the hole's wall is 0.25 from the box's sides, more than the 2.5 thicknesses the
// growth keeps clear: nothing shrinks), 4 layers, progression 1.3, the octree's sizes (MinDelta
// 0.03, MaxDelta 0.12, EPS 0.1: some 70 wall triangles, 1,400 elements), the optimiser as
// meshCase runs it. Meshed once per order for the tests that share it.
constexpr double kHoleHeight = 0.4, kHoleThickness = 0.05, kHoleProgression = 1.3;
constexpr int kHoleLayers = 4;

struct HoleCase {
  MeshResult result;
  std::set<int> walls;  // the curved faces: the hole's wall
};

const HoleCase& holeInABox(int order) {
  static std::map<int, std::unique_ptr<HoleCase>> meshed;
  std::unique_ptr<HoleCase>& slot = meshed[order];
  if (slot) return *slot;
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(1.0, 0.8, kHoleHeight).Shape();
  const TopoDS_Shape drill =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0.45, 0.4, -0.1), gp_Dir(0, 0, 1)), 0.15,
                               kHoleHeight + 0.2)
          .Shape();
  const std::string brep = test::brepText(BRepAlgoAPI_Cut(box, drill).Shape());
  const CadModel cad = CadModel::fromBrepText(brep);
  std::set<int> walls;
  for (int f = 1; f <= cad.numFaces(); ++f)
    if (!cad.isPlanar(f)) walls.insert(f);
  MeshingOptions options;
  options.order = order;
  options.optimiseIterations = 100;
  options.threads = 2;
  SizingParameters sizes;
  sizes.minDelta = 0.03;
  sizes.maxDelta = 0.12;
  sizes.eps = 0.1;
  options.sizing = sizes;
  BoundaryLayerParameters layer;
  layer.faces.assign(walls.begin(), walls.end());
  layer.thickness = "0.05";
  layer.layers = kHoleLayers;
  layer.progression = kHoleProgression;
  options.boundaryLayer = layer;
  slot = std::make_unique<HoleCase>(
      HoleCase{runMeshPipeline(CadSource::brepText(brep, "hole in a box"), options), walls});
  return *slot;
}

TEST(BoundaryLayerOnAHole, IsCertifiedValidWithTheRequestedLayersInEveryWallColumn) {
  const HoleCase& c = holeInABox(2);
  ASSERT_FALSE(c.walls.empty());
  for (const int f : c.walls) EXPECT_FALSE(c.result.cad->isPlanar(f)) << "Face" << f;
  expectValidWithLayersInEveryWallColumn(c.result, c.walls, kHoleLayers);
}

TEST(BoundaryLayerOnAHole, SplitNodesLieOnTheCadAndTheReportSaysSo) {
  // The side nodes' move onto the end planes: the first level's shift, at most its share z_1 =
  // 0.16 of the height, times the sine of the wall normal's lean off the plane, the order-2
  // wall's normal error (the geometry stage finds 1.5 degrees on this wall): below 0.5 %.
  expectSplitNodesOnTheCad(holeInABox(2).result, "hole in a box", kHoleLayers, 0.01);
}

TEST(BoundaryLayerOnAHole, NektarAndGmshFilesCarryThePrismsAndReadBack) {
  expectNektarAndGmshFilesReadBack(holeInABox(2).result, "hole");
}

TEST(BoundaryLayerOnAHole, NektarXmlOfTheSplitLayerReadsBackEveryStoredNodeExactly) {
  const MeshResult& r = holeInABox(4).result;
  ASSERT_EQ(r.mesh.order, 4);
  expectNektarXmlStoresEveryNodeExactly(r, "hole4");
}

// As FirstLayerHeightAlongTheWallNormalIsWithinFivePercent: at order 4 with the optimiser, the
// first layer's height along the wall normal against thickness x (1 - r) / (1 - r^n) within the
// issue's 5 % (the method's aim: the split sets each column's first level at z_1 times the
// height grown, and nothing here is shrunk), and the report's own figure equal to this
// independent one (the same points, its own normals and search: rounding and the searches'
// 1e-12 in reference coordinates).
TEST(BoundaryLayerOnAHole, FirstLayerHeightAlongTheWallNormalIsWithinFivePercentAtOrderFour) {
  const HoleCase& c = holeInABox(4);
  const MeshResult& r = c.result;
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_TRUE(r.boundaryLayer->shrunk().empty());
  EXPECT_FALSE(r.boundaryLayer->faces.empty());
  for (const LayerShrink& face : r.boundaryLayer->faces) EXPECT_EQ(face.fullHeight(), 1.0);
  const double expected =
      kHoleThickness * (1 - kHoleProgression) / (1 - std::pow(kHoleProgression, kHoleLayers));
  double worst = 0.0;
  std::size_t measured = 0;
  forEachFirstLayerHeight(r, c.walls, [&](const Eigen::Vector3d&, double height) {
    worst = std::max(worst, std::fabs(height / expected - 1));
    ++measured;
  });
  EXPECT_GT(measured, 0U);
  EXPECT_LE(worst, 0.05) << "worst relative deviation of the first-layer height";
  RecordProperty("first_layer_height_worst_relative_deviation", std::to_string(worst));
  EXPECT_NEAR(r.layerSplit->firstHeightDeviation, worst, 1e-9);
  EXPECT_EQ(r.layerSplit->cornerCells, 0U);  // a cylinder's wall has no sharp corner
  EXPECT_GE(r.layerSplit->firstHeightMin, expected * (1 - 0.05));
  EXPECT_LE(r.layerSplit->firstHeightMax, expected * (1 + 0.05));
}

// As AtOrderSixTheFirstLayerFollowsTheRaisedWall: above order 4 the pipeline optimises at order
// 4 and raises the order after (kContinuationOrder); the split's levels then follow the raised
// wall, so the first layer keeps its height within the 5 % (the report's measure, along
// the wall normal), and the mesh is certified valid. The optimiser's stop rule holds for any
// run: "stalled" only once the worst element stopped rising over the stall window (3 sweeps,
// by 1e-3: pipelineOptimiserOptions in mesh_pipeline.cpp).
TEST(BoundaryLayerOnAHole, AtOrderSixTheFirstLayerFollowsTheRaisedWall) {
  const MeshResult& r = holeInABox(6).result;
  expectRaisedToOrderSixKeepingTheFirstHeight(r);
}

// The faces of `domain` whose middle (the point at the middle of their parameter box: a planar
// face's rectangle, a spline face's mid-span) satisfies `inside`.
std::vector<int> facesWithMiddle(const TopoDS_Shape& domain,
                                 const std::function<bool(const Eigen::Vector3d&)>& inside) {
  const CadModel cad = test::toModel(domain);
  std::vector<int> faces;
  for (int f = 1; f <= cad.numFaces(); ++f) {
    const SurfaceBounds b = cad.faceBounds(f);
    if (inside(cad.evaluateSurface(f, 0.5 * (b.uMin + b.uMax), 0.5 * (b.vMin + b.vMax)).point))
      faces.push_back(f);
  }
  return faces;
}

// `domain` meshed at `order` with the layer (`thickness`, `layers`, `progression`) on `faces` and
// the optimiser (20 sweeps, `threads`).
MeshResult meshWithLayer(const TopoDS_Shape& domain, const std::vector<int>& faces,
                         const std::string& thickness, int layers, double progression, int order,
                         int threads) {
  BoundaryLayerParameters p;
  p.faces = faces;
  p.thickness = thickness;
  p.layers = layers;
  p.progression = progression;
  MeshingOptions options;
  options.order = order;
  options.optimiseIterations = 20;
  options.threads = threads;
  options.boundaryLayer = p;
  return runMeshPipeline(CadSource::brepText(test::brepText(domain)), options);
}

// `r` certified valid with every column of every layer face at full height.
void expectValidWithEveryColumnAtFullHeight(const MeshResult& r) {
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  for (const LayerShrink& face : r.boundaryLayer->faces) EXPECT_EQ(face.fullHeight(), 1.0);
}

// A unit cube in a box of side 4 with the layer on the cube's six faces (0.1, 3 layers,
// progression 1.5, order 4, optimised): at its sharp convex edges and corners the columns lean
// between the faces and are lengthened (by sqrt 2 on an edge, sqrt 3 at a corner) so that their
// tops lie at the thickness from each face. Every column at full height, the first layer's
// height on the flat walls exact to rounding (the tops are the faces' planes offset by it), the
// split certified valid.
TEST(BoundaryLayerOnACube, EdgesAndCornersKeepTheFirstLayerHeightOnEveryFace) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-1.5, -1.5, -1.5), 4.0, 4.0, 4.0).Shape();
  const TopoDS_Shape domain = BRepAlgoAPI_Cut(box, BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape());
  const std::vector<int> faces = facesWithMiddle(domain, [](const Eigen::Vector3d& c) {
    return c.minCoeff() > -0.5 && c.maxCoeff() < 1.5;  // the cube's
  });
  ASSERT_EQ(faces.size(), 6U);
  const MeshResult r = meshWithLayer(domain, faces, "0.1", 3, 1.5, 4, 1);
  ASSERT_TRUE(r.boundaryLayer.has_value() && r.layerSplit.has_value());
  ASSERT_EQ(r.boundaryLayer->faces.size(), 6U);
  expectValidWithEveryColumnAtFullHeight(r);
  // Lengthened where they lean (none shorter than the thickness), the longest on the cube's
  // corner diagonals.
  EXPECT_FALSE(r.boundaryLayer->lengthened.empty());
  EXPECT_NEAR(r.boundaryLayer->thicknessMax, 0.1 * std::sqrt(3.0), 1e-9);
  EXPECT_GT(r.boundaryLayer->thicknessMin, 0.1 - 1e-9);
  const double first = 0.1 * (1.5 - 1.0) / (std::pow(1.5, 3) - 1.0);
  EXPECT_LT(r.layerSplit->firstHeightDeviation, 1e-9);  // rounding in the Newton measure
  EXPECT_GT(r.layerSplit->cornerCells, 0U);
  EXPECT_GT(r.layerSplit->firstHeightMin, 0.95 * first);  // 29 % short before the lengthening
  // The cells at the edges and corners too: their tops are the faces' planes offset by the
  // thickness, between a leaning column and an upright one (7.2 % too high when the blend
  // interpolated the columns' directions and lengths apart).
  EXPECT_LT(r.layerSplit->firstHeightCornerDeviation, 1e-9);
  EXPECT_EQ(r.layerSplit->plainColumns, 0U);
}

// A cylinder (radius 0.5, height 1.5) standing on the floor of an 8 x 6 x 3 box, the layer (0.05,
// 4 layers, progression 1.3) on the floor, the cylinder's side and its top, order 4, optimised:
// a concave junction all round the cylinder's foot and a convex edge round its top. The
// optimiser has to let the layer's top move around invalid elements there, and the tops above
// the junction move freely; the split puts each such column's first level back at the first
// layer's height from both walls. The first layer within the 5 % on the walls and in the
// cells at the junction and the edge (23.7 % there before).
TEST(BoundaryLayerAtAJunction, CylinderOnAPlateKeepsTheFirstLayerHeightAtItsFootAndTop) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(8.0, 6.0, 3.0).Shape();
  const TopoDS_Shape cylinder =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(3, 3, 0), gp_Dir(0, 0, 1)), 0.5, 1.5).Shape();
  const TopoDS_Shape domain = BRepAlgoAPI_Cut(box, cylinder);
  const std::vector<int> faces = facesWithMiddle(domain, [](const Eigen::Vector3d& c) {
    return c.z() < 1e-9 || (std::abs(c.x() - 3.0) < 0.6 && std::abs(c.y() - 3.0) < 0.6 &&
                            c.z() < 1.6);  // the floor, the cylinder's side and top
  });
  ASSERT_EQ(faces.size(), 3U);
  const MeshResult r = meshWithLayer(domain, faces, "0.05", 4, 1.3, 4, 2);
  ASSERT_TRUE(r.boundaryLayer.has_value() && r.layerSplit.has_value());
  expectValidWithEveryColumnAtFullHeight(r);
  EXPECT_FALSE(r.boundaryLayer->lengthened.empty());
  EXPECT_GT(r.layerSplit->cornerCells, 0U);
  EXPECT_LT(r.layerSplit->firstHeightDeviation, 0.05);
  EXPECT_LT(r.layerSplit->firstHeightCornerDeviation, 0.05);
  RecordProperty("release", layerReleaseName(r.boundaryLayer->release));
  RecordProperty("first_layer_height_worst_deviation_at_corners",
                 std::to_string(r.layerSplit->firstHeightCornerDeviation));
}

// A NACA 0012 section with its trailing edge open (0.25 % of the chord: the x^4 coefficient
// -0.1015), chord `c`, leading edge at (x0, 0, z): one B-spline from the upper trailing edge round
// the nose to the lower one (41 cosine-spaced stations a side) and the segment closing it.
TopoDS_Wire bluntNaca0012(double c, double x0, double z) {
  const auto yt = [](double x) {
    return 0.6 * (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x -
                  0.1015 * x * x * x * x);
  };
  constexpr int kStations = 40;
  std::vector<gp_Pnt> points;
  for (int i = kStations; i >= 0; --i) {
    const double x = 0.5 * (1.0 - std::cos(M_PI * i / kStations));
    points.emplace_back(x0 + c * x, c * yt(x), z);
  }
  for (int i = 1; i <= kStations; ++i) {
    const double x = 0.5 * (1.0 - std::cos(M_PI * i / kStations));
    points.emplace_back(x0 + c * x, -c * yt(x), z);
  }
  Handle(TColgp_HArray1OfPnt) array = new TColgp_HArray1OfPnt(1, static_cast<int>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i)
    array->SetValue(static_cast<int>(i) + 1, points[i]);
  GeomAPI_Interpolate spline(array, false, 1e-9);
  spline.Perform();
  BRepBuilderAPI_MakeWire wire(BRepBuilderAPI_MakeEdge(spline.Curve()).Edge(),
                               BRepBuilderAPI_MakeEdge(points.back(), points.front()).Edge());
  return wire.Wire();
}

// The wing: NACA 0012 sections lofted from the root (chord 1, on the box's symmetry face
// z = 0) to a flat tip (chord 0.5, z = 4), leading edge swept 30 degrees, the trailing edge blunt
// (a face 0.25 % of the chord tall); the layer (0.02, 6 layers, 1.5) on every wing face: the
// suction and pressure sides, the trailing-edge face and the tip. The columns along the thin
// trailing-edge face and at the tip's corners lean far from the faces' normals, and the wall
// triangles there are slivers; before the growth scaled a prism's corners by the wall triangle's
// own area (not its corner angle), every height there read as a fold and no layer grew.
// Order 2, optimised; the box smaller than the (7 x 5 x 6 chords) to keep the test short.
TEST(BoundaryLayerOnAWing, BluntTrailingEdgeGrowsAndIsCertifiedValid) {
  BRepOffsetAPI_ThruSections loft(true, false);
  loft.AddWire(bluntNaca0012(1.0, 0.0, 0.0));
  loft.AddWire(bluntNaca0012(0.5, 4.0 * std::tan(M_PI / 6.0), 4.0));
  loft.Build();
  ASSERT_TRUE(loft.IsDone());
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-2.0, -2.5, 0.0), 7.0, 5.0, 6.0).Shape();
  const TopoDS_Shape domain = BRepAlgoAPI_Cut(box, loft.Shape());
  const std::vector<int> faces = facesWithMiddle(domain, [](const Eigen::Vector3d& c) {
    const bool onWing = c.x() > -0.01 && c.x() < 2.9 && std::fabs(c.y()) < 0.1;
    return onWing && c.z() > 1e-6 && c.z() < 4.0 + 1e-6;
  });
  ASSERT_EQ(faces.size(), 3U);  // the sides (one spline face), the trailing-edge face, the tip
  const MeshResult r = meshWithLayer(domain, faces, "0.02", 6, 1.5, 2, 2);
  ASSERT_TRUE(r.boundaryLayer.has_value() && r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  std::size_t columns = 0, full = 0;
  for (const LayerShrink& face : r.boundaryLayer->faces) {
    columns += face.columns;
    full += face.columns - face.nodes;
  }
  EXPECT_GT(columns, 500U);
  // The share (the larger box grows every column to full height).
  EXPECT_GE(static_cast<double>(full), 0.95 * static_cast<double>(columns));
  EXPECT_GT(r.layerSplit->prisms, 500U);  // macro prisms, each split into 6
}

// A body on a stilt, as an Ahmed body stands in a wind tunnel: a block (0.6 x 0.4 x 0.2) held
// 0.048 above the floor of a box by a cylinder of radius 0.02, the layer (0.01, 4 layers,
// progression 1.5) on the block's faces, order 2, optimised. The layer's side lies on the stilt,
// which is only a few elements tall: its nodes, the seam's included, make room as the columns
// climb down it. With the seam's nodes held, the triangles beside them folded and the columns
// round the stilt were shrunk to 0.7 of the thickness (88 of the bottom face's nodes graded).
TEST(BoundaryLayerBesideAStilt, TheLayerClimbsTheStiltAtFullHeight) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-1.0, -1.0, 0.0), 2.6, 2.4, 1.0).Shape();
  const TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(0.0, -0.2, 0.048), 0.6, 0.4, 0.2).Shape();
  const TopoDS_Shape stilt =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0.3, 0.0, 0.0), gp_Dir(0, 0, 1)), 0.015, 0.05).Shape();
  const TopoDS_Shape domain = BRepAlgoAPI_Cut(BRepAlgoAPI_Cut(box, block), stilt);
  const std::vector<int> faces = facesWithMiddle(domain, [](const Eigen::Vector3d& c) {
    return c.z() > 0.047 && c.z() < 0.3 && c.x() > -0.01 && c.x() < 0.61;  // the block's
  });
  ASSERT_EQ(faces.size(), 6U);
  const MeshResult r = meshWithLayer(domain, faces, "0.01", 4, 1.5, 2, 2);
  ASSERT_TRUE(r.boundaryLayer.has_value() && r.layerSplit.has_value());
  ASSERT_EQ(r.boundaryLayer->faces.size(), 6U);
  expectValidWithEveryColumnAtFullHeight(r);
  EXPECT_LT(r.layerSplit->firstHeightDeviation, 0.05);
}

}  // namespace
}  // namespace homesh
