// The 2D layer through the whole pipeline: NekMesh's aerofoil, T106 and NACA 0012 cases (peer
// files) and a NACA 2412 case the test writes: the columns, the first layer's height, the
// trailing edge's fan, and the raise to order 6.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "layer_case_checks.hpp"
#include "peer_data.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// NekMesh's 2d_bl_aerofoil case: a layer of thickness 0.1 on the aerofoil's two curves (Edge2,
// Edge4), 6 layers, progression 1.5, at order 4 with the optimiser.
TEST(BoundaryLayer2D, AerofoilIsValidWithSixQuadrilateralsOnEveryWallLineAndItsFirstHeight) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("2d_bl_aerofoil", 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  EXPECT_EQ(r.mesh.dim, 2);
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_TRUE(r.boundaryLayer->shrunk().empty());
  ASSERT_EQ(r.boundaryLayer->release, LayerRelease::None);  // the layer as grown: heights hold
  double worst = 0.0;
  expectQuadrilateralColumnsOnEveryWallLine(r, {2, 4}, 6, 0.1 * (1 - 1.5) / (1 - std::pow(1.5, 6)),
                                            worst);
  EXPECT_LE(worst, 0.05) << "first-layer height, worst relative deviation";
  std::ostringstream figure;
  figure << worst;
  RecordProperty("first_layer_height_worst_relative_deviation", figure.str());
}

// NekMesh's 2d_bl_t106 case at order 4 with the optimiser: a layer of thickness 0.01 + 0.05 x
// on the blade (Edge11, Edge12), whose rounded edges (radius about 0.005, with wiggles in the
// splines' curvature) lie under a layer 1 to 11 times thicker. The wall segments there are
// halved until each turns by at most 30 degrees, and the wall's high-order nodes are spaced on
// the offset at a quarter of the height; the top then stays fixed or at most slides parallel to
// the wall (heights kept), the split is certified valid, and the first layer keeps its height
// within the issue's 5 % on the whole wall, tip cells included (10.5 % at the trailing edge's
// tip before, with segments 0.04 long there turning up to 110 degrees).
TEST(BoundaryLayer2D, T106KeepsItsFirstLayerHeightAroundItsRoundedEdges) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("2d_bl_t106", 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  std::size_t quads = 0;
  for (const ElementBlock& b : r.mesh.blocks)
    if (b.type == CellType::Quadrilateral) quads += b.count();
  EXPECT_EQ(quads, 2 * r.boundaryLayer->cells);
  EXPECT_LE(r.boundaryLayer->release, LayerRelease::Parallel);
  EXPECT_GT(r.boundaryLayer->wallSplits, 0U);
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  EXPECT_LE(r.layerSplit->firstHeightCornerDeviation, 0.05);
  // The thinnest first layer is the leading edge's, 0.01 / 3 (2 layers, progression 2), within
  // the deviation the report gives.
  EXPECT_GE(r.layerSplit->firstHeightMin,
            0.01 / 3 *
                (1 - std::max(r.layerSplit->firstHeightDeviation,
                              r.layerSplit->firstHeightCornerDeviation)));
  RecordProperty("first_layer_height_worst_deviation",
                 std::to_string(r.layerSplit->firstHeightDeviation));
  RecordProperty("first_layer_height_worst_deviation_at_corners",
                 std::to_string(r.layerSplit->firstHeightCornerDeviation));
  RecordProperty("plain_columns", std::to_string(r.layerSplit->plainColumns));
}

// NekMesh's 2d_bl_naca0012 case (a layer of 0.05 on the aerofoil's curves Edge5 and Edge6, 2
// layers, progression 2) at order 4. Its trailing edge (Vertex6) is sharp: the curves' normals
// there are 163.5 degrees apart (the closed trailing edge's 16.5 degree wedge). A fan of columns
// fills that angle, each fan triangle at most 40 degrees wide and split into 2 n - 1 = 3
// triangles, so the cells on either side keep a column along their own wall's normal at the
// edge, and their first layer the height asked for, 0.05 / 3, along the wall normal at every
// wall quadrature point (with one column on the edge's bisector it fell 25 % short there, by
// the top's component along the normal 64 %). The tolerance: the component along the normal
// differs from the height along the normal line by the first layer's lean against a wall whose
// curvature is small there, well under 1 %; 5 % is the issue's bound.
TEST(BoundaryLayer2D, NacaSharpTrailingEdgeGrowsAFanAndItsCellsKeepTheFirstHeight) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("2d_bl_naca0012", 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  CornerFan fan;
  measureCornerFan(r, 6, 0.05 / 3, fan);
  EXPECT_EQ(fan.pieces, r.boundaryLayer->fanTriangles);
  EXPECT_EQ(fan.pieces, 5U);  // ceil(163.5 / 40)
  EXPECT_NEAR(fan.angle * 180.0 / M_PI, 163.5, 1.0);
  EXPECT_EQ(fan.sides, 2U);
  const double worst = fan.worstSideHeight;
  EXPECT_LE(worst, 0.05) << "first-layer height beside the trailing edge, worst deviation";
  // The nose (radius 0.0158 against the case's MinDelta of 0.1): its two wall segments, along
  // which the curves turn by more than 60 degrees, are halved before the growth, and their
  // four halves again (each still turning by more than 30), so no cell's wall meets its
  // neighbour's at a corner and the whole wall keeps its first height (5.8 % off at the nose
  // without the halving), measured by the split along the normal line.
  EXPECT_EQ(r.boundaryLayer->wallSplits, 6U);
  EXPECT_EQ(r.layerSplit->cornerCells, 0U);
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  RecordProperty("first_layer_height_worst_deviation_at_trailing_edge", std::to_string(worst));
}

// A NACA 2412 at 6 degrees in its own box, as a .mcf the test writes into a fresh folder (its
// path returned): a layer 0.03 thick on the aerofoil (Edge5, Edge6), 3 layers, progression 1.5.
std::string writeOwnNacaCase() {
  const auto dir = test::tempDir();
  std::string path = (dir / "naca2412.mcf").string();
  std::ofstream(path) << R"(<NEKTAR>
  <MESHING>
    <INFORMATION>
      <I PROPERTY="CADFile" VALUE="2412" />
      <I PROPERTY="MeshType" VALUE="2DBndLayer" />
    </INFORMATION>
    <PARAMETERS>
      <P PARAM="MinDelta" VALUE="0.04" />
      <P PARAM="MaxDelta" VALUE="1.0" />
      <P PARAM="EPS" VALUE="0.1" />
      <P PARAM="Order" VALUE="4" />
      <P PARAM="BndLayerSurfaces" VALUE="5,6" />
      <P PARAM="BndLayerThickness" VALUE="0.03" />
      <P PARAM="BndLayerLayers" VALUE="3" />
      <P PARAM="BndLayerProgression" VALUE="1.5" />
      <P PARAM="Xmin" VALUE="-1.5" />
      <P PARAM="Ymin" VALUE="-1.25" />
      <P PARAM="Xmax" VALUE="2.5" />
      <P PARAM="Ymax" VALUE="1.25" />
      <P PARAM="AOA" VALUE="6.0" />
    </PARAMETERS>
  </MESHING>
</NEKTAR>
)";
  return path;
}

// writeOwnNacaCase at order 4 with the optimiser. The same properties as the aerofoil and NACA
// 0012 peer cases: certified valid, 3 quadrilaterals on every wall line, the first layer's height,
// and the fan at the sharp trailing edge (Vertex6).
TEST(BoundaryLayer2D, OwnNacaCaseHasItsLayersItsFirstHeightAndATrailingEdgeFan) {
  constexpr double kThickness = 0.03, kProgression = 1.5;  // as writeOwnNacaCase says
  constexpr int kLayers = 3;
  const std::string path = writeOwnNacaCase();
  const MeshResult r = meshCase(path, 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.mesh.dim, 2);
  EXPECT_EQ(r.mesh.order, 4);
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_TRUE(r.boundaryLayer->shrunk().empty());
  const double first = kThickness * (1 - kProgression) / (1 - std::pow(kProgression, kLayers));
  // The top fixed or at most sliding parallel to the wall: the heights as grown, so the first
  // layer's (the top's component along the wall normal; the split's, along the normal line)
  // within the issue's 5 % on every wall line.
  EXPECT_LE(r.boundaryLayer->release, LayerRelease::Parallel);
  double worst = 0.0;
  expectQuadrilateralColumnsOnEveryWallLine(r, {5, 6}, kLayers, first, worst);
  EXPECT_LE(worst, 0.05) << "first-layer height, worst relative deviation";
  RecordProperty("first_layer_height_worst_relative_deviation", std::to_string(worst));
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  // No cell at a corner: the wall segments are halved until none turns by more than 30 degrees
  // (the nose), and the one sharp corner, the trailing edge, has its fan.
  EXPECT_EQ(r.layerSplit->cornerCells, 0U);
  // The fan: NACA MPTT's surfaces leave the trailing edge at atan(yt'(1) cos theta) either side
  // of the camber line, theta its slope there (naca_aerofoil.hpp's formulas: yt'(1) = -1.21125
  // t, tan theta = -2 M / (1 - P)), so the curves' normals there are 180 degrees less that
  // wedge apart (163.5 here), which the fan fills in ceil(angle / 40 degrees) triangles. Within
  // a degree: the method reads each curve's direction off a short chord of its B-spline at the
  // edge (curveTangent), and the splines interpolate the formula's points without its end
  // tangents (their parametrisation is even stationary there): hundredths of a degree apart.
  const double camber = std::atan(2 * 0.02 / (1 - 0.4));
  const double spread = M_PI - 2 * std::atan(1.21125 * 0.12 * std::cos(camber));
  CornerFan fan;
  measureCornerFan(r, 6, first, fan);
  EXPECT_EQ(fan.pieces, r.boundaryLayer->fanTriangles);
  EXPECT_EQ(fan.pieces, static_cast<std::size_t>(std::ceil(spread / (40.0 * M_PI / 180.0))));
  EXPECT_NEAR(fan.angle, spread, M_PI / 180.0);
  EXPECT_EQ(fan.sides, 2U);
  // The cells beside the edge keep a column along their own wall's normal there: their first
  // layer's component along the normal differs from its height by the layer's lean against a
  // wall of small curvature (well under 1 %), within the issue's 5 %.
  EXPECT_LE(fan.worstSideHeight, 0.05) << "first-layer height beside the trailing edge";
  RecordProperty("fan_angle_degrees", std::to_string(fan.angle * 180.0 / M_PI));
  RecordProperty("first_layer_height_worst_deviation_at_trailing_edge",
                 std::to_string(fan.worstSideHeight));
}

// writeOwnNacaCase at order 6: optimised at order 4, raised, optimised again (as
// AtOrderSixTheFirstLayerFollowsTheRaisedWall): certified valid, the first layer's height within
// the issue's 5 % after the raise, and the optimiser's stop rule.
TEST(BoundaryLayer2D, OwnNacaCaseAtOrderSixKeepsItsFirstHeightAfterTheRaise) {
  const MeshResult r = meshCase(writeOwnNacaCase(), 6);
  expectRaisedToOrderSixKeepingTheFirstHeight(r);
}

}  // namespace
}  // namespace homesh
