// Recognising another tool's boundary layer (layer_stacks.hpp): Gmsh's prisms extruded from a
// sphere's surface mesh (gmsh_layered.hpp) found as stacks and agglomerated into one macro
// prism each; prisms that are no such layer left alone, with the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "boundary_layer/layer_split.hpp"
#include "boundary_layer/layer_stacks.hpp"
#include "cad/cad_model.hpp"
#include "gmsh_layered.hpp"
#include "io/mesh_readers.hpp"
#include "linear/cad_classification.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

using test::nodePoint;

// The sphere's layer at Gmsh's size 0.25: 232 wall triangles, 5 layers of heights 0.01 * 1.3^k.
TEST(LayerStacks, GmshsExtrudedLayerBecomesOneMacroPrismPerColumnOfPrisms) {
  const auto dir = test::tempDir();
  const std::string msh = (dir / "sphere.msh").string(), step = (dir / "sphere.step").string();
  const test::GmshLayer layer;
  test::writeGmshLayeredSphere(msh, step, layer);
  const CadModel cad = CadModel::fromFile(step);
  const Mesh onCad = classifyOnCad(readMesh(msh), cad);
  std::size_t givenPrisms = 0;
  for (const ElementBlock& b : onCad.blocks)
    givenPrisms += b.type == CellType::Prism ? b.count() : 0;
  std::string why;
  const std::optional<LayerStacks> s = recogniseLayerStacks(onCad, why);
  ASSERT_TRUE(s) << why;
  const LayerStacksRecord& r = s->record;
  EXPECT_EQ(r.layers, layer.layers);
  EXPECT_EQ(r.stacks * static_cast<std::size_t>(layer.layers), givenPrisms);
  EXPECT_EQ(r.walls, std::set<int>{7}) << "the sphere is the cut box's face 7";
  EXPECT_EQ(r.sidesMerged, 0U) << "a closed wall has no sides";
  // Gmsh's levels: the cumulative heights over their sum. Its columns are straight along the
  // normal, so each column's fractions are these to rounding.
  double total = 0.0;
  for (int k = 0; k < layer.layers; ++k) total += layer.firstHeight * std::pow(layer.ratio, k);
  ASSERT_EQ(r.levels.size(), static_cast<std::size_t>(layer.layers) + 1);
  double sum = 0.0;
  for (int k = 1; k <= layer.layers; ++k) {
    sum += layer.firstHeight * std::pow(layer.ratio, k - 1);
    EXPECT_NEAR(r.levels[static_cast<std::size_t>(k)], sum / total, 1e-12);
  }
  EXPECT_LT(r.levelSpread, 1e-12);
  EXPECT_NEAR(r.firstHeightMin, layer.firstHeight, 1e-12);
  EXPECT_NEAR(r.firstHeightMax, layer.firstHeight, 1e-12);

  // The macro mesh: the layer's inner nodes gone (4 per column), every macro prism standing on
  // its wall triangle with its top at the layer's full height, and valid as a straight cell.
  EXPECT_EQ(s->macro.numNodes(), onCad.numNodes() - 4 * r.columns);
  ASSERT_EQ(s->firstHeights.size(), s->macro.numNodes());
  std::size_t walls = 0;
  for (const ElementBlock& b : s->macro.blocks) {
    if (b.type != CellType::Prism) continue;
    for (std::size_t e = 0; e < b.count(); ++e)
      for (int k = 0; k < 3; ++k) {
        const std::int64_t w = b.element(e)[k], t = b.element(e)[k + 3];
        EXPECT_NEAR(nodePoint(s->macro, w).norm(), 0.5, 1e-9);
        EXPECT_NEAR((nodePoint(s->macro, t) - nodePoint(s->macro, w)).norm(), total, 1e-9);
        EXPECT_NEAR(s->firstHeights[static_cast<std::size_t>(w)], layer.firstHeight, 1e-12);
      }
  }
  for (const double h : s->firstHeights) walls += std::isnan(h) ? 0 : 1;
  EXPECT_EQ(walls, r.columns);
  const QualitySummary q = evaluateQuality(s->macro, 2);
  EXPECT_EQ(q.invalid + q.undecided, 0U);
}

// Prisms that are no boundary layer are left as they are, and the reason says why: a mesh of
// one column of prisms from the bottom of a box to its top spans the domain.
TEST(LayerStacks, PrismsFromWallToWallAreNoLayer) {
  Mesh mesh;
  mesh.dim = 3;
  for (int z = 0; z <= 3; ++z)
    for (const auto& [x, y] : std::vector<std::pair<double, double>>{{0, 0}, {1, 0}, {0, 1}})
      mesh.xyz.insert(mesh.xyz.end(), {x, y, z / 3.0});
  const std::size_t n = mesh.xyz.size() / 3;
  mesh.nodeCadDim.assign(n, 2);
  mesh.nodeCadIndex.assign(n, 1);
  mesh.nodeCadParam.assign(2 * n, 0.0);
  ElementBlock prisms{CellType::Prism, 1, {}, {}};
  for (std::int64_t k = 0; k < 3; ++k) {
    for (std::int64_t v = 0; v < 6; ++v) prisms.nodes.push_back(3 * k + v);
    prisms.entity.push_back(1);
  }
  ElementBlock tris{CellType::Triangle, 1, {0, 2, 1, 9, 10, 11}, {1, 2}};
  mesh.blocks = {prisms, tris};
  std::string why;
  EXPECT_FALSE(recogniseLayerStacks(mesh, why));
  EXPECT_NE(why.find("spans the domain"), std::string::npos) << why;

  // With no prisms at all there is nothing to say.
  mesh.blocks = {tris};
  EXPECT_FALSE(recogniseLayerStacks(mesh, why));
  EXPECT_TRUE(why.empty()) << why;
}

// A stack may stand on a prism's top triangle (corners 3, 4, 5 on the wall, as a file may list
// them): the macro prism then takes the top's corners 3, 5, 4 as its wall and stays positive.
// The nodes of a column of cells on the polygon `corners` in the plane z = 0: its corners at each
// of `levels`, then `apex`; all inside the domain (the test gives the cells).
Mesh columnNodes(const std::vector<std::pair<double, double>>& corners,
                 const std::array<double, 3>& apex,
                 const std::vector<double>& levels = {0.0, 0.1, 0.3}) {
  Mesh mesh;
  mesh.dim = 3;
  for (const double z : levels)
    for (const auto& [x, y] : corners) mesh.xyz.insert(mesh.xyz.end(), {x, y, z});
  mesh.xyz.insert(mesh.xyz.end(), apex.begin(), apex.end());
  const std::size_t n = mesh.numNodes();
  mesh.nodeCadDim.assign(n, 3);
  mesh.nodeCadIndex.assign(n, 1);
  mesh.nodeCadParam.assign(2 * n, std::nan(""));
  return mesh;
}

// One column of two prisms on the triangle (0,0,0) (1,0,0) (0,1,0), levels at 0.1 and 0.3, a
// tetrahedron on top; the first prism listed upside down.
TEST(LayerStacks, AStackOnAPrismsTopTriangleMakesAPositiveMacroPrism) {
  Mesh mesh = columnNodes({{0, 0}, {1, 0}, {0, 1}}, {0.2, 0.2, 1.0});  // node 9: the apex
  const std::size_t n = mesh.numNodes();
  // Positive both: (3, 5, 4, 0, 2, 1) has its top triangle (0, 2, 1) on the wall.
  ElementBlock prisms{CellType::Prism, 1, {3, 5, 4, 0, 2, 1, 3, 4, 5, 6, 7, 8}, {1, 1}};
  ElementBlock tets{CellType::Tetrahedron, 1, {6, 7, 8, 9}, {1}};
  ElementBlock wall{CellType::Triangle, 1, {0, 2, 1}, {5}};
  mesh.blocks = {prisms, tets, wall};
  ASSERT_EQ(evaluateQuality(mesh, 1).invalid, 0U) << "the test's own cells must be positive";
  std::string why;
  const std::optional<LayerStacks> s = recogniseLayerStacks(mesh, why);
  ASSERT_TRUE(s) << why;
  EXPECT_EQ(s->record.stacks, 1U);
  EXPECT_EQ(s->record.layers, 2);
  EXPECT_EQ(s->record.walls, std::set<int>{5});
  ASSERT_EQ(s->record.levels.size(), 3U);
  EXPECT_NEAR(s->record.levels[1], 1.0 / 3.0, 1e-15);
  EXPECT_EQ(s->macro.numNodes(), n - 3);  // the middle level's nodes go
  const QualitySummary q = evaluateQuality(s->macro, 1);
  EXPECT_EQ(q.invalid + q.undecided, 0U);
  for (const ElementBlock& b : s->macro.blocks)
    if (b.type == CellType::Prism)
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(nodePoint(s->macro, b.element(0)[k]).z(), 0.0, 0.0);
        EXPECT_NEAR(nodePoint(s->macro, b.element(0)[k + 3]).z(), 0.3, 1e-15);
      }

  // Stacks of different heights are no layer the split can keep: a second column of one prism
  // beside it is refused with the counts.
  Mesh uneven = mesh;
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{{1, 1}})
    for (const double z : {0.0, 0.1}) uneven.xyz.insert(uneven.xyz.end(), {x, y, z});
  const std::size_t m = uneven.xyz.size() / 3;
  uneven.nodeCadDim.assign(m, 3);
  uneven.nodeCadIndex.assign(m, 1);
  uneven.nodeCadParam.assign(2 * m, std::nan(""));
  // Beside the first column: wall triangle (1,0,0) (1,1,0) (0,1,0), one prism up to 0.1.
  uneven.blocks[0].nodes.insert(uneven.blocks[0].nodes.end(), {1, 10, 2, 4, 11, 5});
  uneven.blocks[0].entity.push_back(1);
  uneven.blocks[2].nodes.insert(uneven.blocks[2].nodes.end(), {1, 2, 10});
  uneven.blocks[2].entity.push_back(5);
  EXPECT_FALSE(recogniseLayerStacks(uneven, why));
  EXPECT_NE(why.find("have 2 and 1 layers"), std::string::npos) << why;
}

// A column of two hexahedra on a boundary quadrilateral, a pyramid on its top: one macro
// hexahedron, positive, marked as layer cells, whichever of its six faces the first hexahedron
// has on the wall (its vertices relabelled so that the wall is that face: the recogniser's
// climbs must then order the macro cell's wall and top right). The same column reaching the
// boundary at its top is no stack: the hexahedra stay as given, with no reason to give.
TEST(LayerStacks, AColumnOfHexahedraOnAnyFaceMakesOnePositiveMacroHexahedron) {
  Mesh mesh = columnNodes({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {0.5, 0.5, 0.8});  // node 12: apex
  const std::size_t n = mesh.numNodes();
  // Each face of a positive hexahedron ordered so that its normal points into the cell, and the
  // opposite face's vertices above its own.
  const std::vector<std::pair<std::array<int, 4>, std::array<int, 4>>> faces{
      {{0, 1, 2, 3}, {4, 5, 6, 7}}, {{4, 7, 6, 5}, {0, 3, 2, 1}}, {{0, 4, 5, 1}, {3, 7, 6, 2}},
      {{3, 2, 6, 7}, {0, 1, 5, 4}}, {{0, 3, 7, 4}, {1, 2, 6, 5}}, {{1, 5, 6, 2}, {0, 4, 7, 3}}};
  for (const auto& [wallFace, topFace] : faces) {
    std::vector<std::int64_t> first(8);
    for (std::size_t k = 0; k < 4; ++k) {
      first[static_cast<std::size_t>(wallFace[k])] = static_cast<std::int64_t>(k);
      first[static_cast<std::size_t>(topFace[k])] = static_cast<std::int64_t>(k + 4);
    }
    ElementBlock hexahedra{CellType::Hexahedron, 1, first, {1, 1}};
    hexahedra.nodes.insert(hexahedra.nodes.end(), {4, 5, 6, 7, 8, 9, 10, 11});
    ElementBlock pyramids{CellType::Pyramid, 1, {8, 9, 10, 11, 12}, {1}};
    ElementBlock wall{CellType::Quadrilateral, 1, {0, 3, 2, 1}, {5}};
    mesh.blocks = {hexahedra, pyramids, wall};
    ASSERT_EQ(evaluateQuality(mesh, 1).invalid, 0U) << "the test's own cells must be positive";
    std::string why;
    const std::optional<LayerStacks> s = recogniseLayerStacks(mesh, why);
    ASSERT_TRUE(s) << why;
    EXPECT_EQ(s->record.stacks, 1U);
    EXPECT_EQ(s->record.hexStacks, 1U);
    EXPECT_EQ(s->record.layers, 2);
    EXPECT_EQ(s->record.columns, 4U);
    EXPECT_EQ(s->record.walls, std::set<int>{5});
    EXPECT_EQ(s->macro.numNodes(), n - 4);  // the middle level's nodes go
    const QualitySummary q = evaluateQuality(s->macro, 1);
    EXPECT_EQ(q.invalid + q.undecided, 0U);
    ASSERT_EQ(s->macro.blocks[0].type, CellType::Hexahedron);
    EXPECT_TRUE(s->macro.blocks[0].layerCells);
    ASSERT_EQ(s->macro.blocks[0].count(), 1U);
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d w = nodePoint(s->macro, s->macro.blocks[0].element(0)[k]);
      const Eigen::Vector3d t = nodePoint(s->macro, s->macro.blocks[0].element(0)[k + 4]);
      EXPECT_EQ(w.z(), 0.0);
      EXPECT_EQ(t.z(), 0.3);
      EXPECT_EQ(w.x(), t.x());  // each top above its wall vertex
      EXPECT_EQ(w.y(), t.y());
    }
  }
  Mesh spanning = mesh;
  spanning.blocks = {mesh.blocks[0], mesh.blocks[2],
                     ElementBlock{CellType::Quadrilateral, 1, {8, 9, 10, 11}, {6}}};
  std::string why;
  EXPECT_FALSE(recogniseLayerStacks(spanning, why));
  EXPECT_TRUE(why.empty()) << why;
}

// Three prism layers whose columns climb differently (levels 0, 0.1, 0.3, 0.6, but 0.4 for the
// third in the second column): the split, from the straight macro prism, puts every given node
// back where it was, each column at its own levels (the mean levels would put that node at 0.33).
TEST(LayerStacks, TheSplitKeepsEachColumnsOwnLevels) {
  Mesh mesh = columnNodes({{0, 0}, {1, 0}, {0, 1}}, {0.2, 0.2, 1.2}, {0.0, 0.1, 0.3, 0.6});
  mesh.xyz[3 * 7 + 2] = 0.4;  // node 7: (1, 0) at the third level
  ElementBlock prisms{
      CellType::Prism, 1, {0, 1, 2, 3, 4, 5, 3, 4, 5, 6, 7, 8, 6, 7, 8, 9, 10, 11}, {1, 1, 1}};
  ElementBlock tets{CellType::Tetrahedron, 1, {9, 10, 11, 12}, {1}};
  ElementBlock wall{CellType::Triangle, 1, {0, 2, 1}, {5}};
  mesh.blocks = {prisms, tets, wall};
  ASSERT_EQ(evaluateQuality(mesh, 1).invalid, 0U) << "the test's own cells must be positive";
  std::string why;
  std::optional<LayerStacks> s = recogniseLayerStacks(mesh, why);
  ASSERT_TRUE(s) << why;
  EXPECT_GT(s->record.levelSpread, 0.05);
  std::vector<double> grown = s->firstHeights;
  for (double& h : grown) h /= s->record.levels[1];
  const LayerHeights heights{grown, {}, {}, s->givenLevels};
  const Mesh split = splitBoundaryLayer(s->macro, s->record.levels, nullptr, nullptr, &heights);
  for (std::size_t i = 0; i < 12; ++i) {
    const Eigen::Vector3d given = nodePoint(mesh, static_cast<std::int64_t>(i));
    double nearest = 1.0;
    for (std::size_t j = 0; j < split.numNodes(); ++j)
      nearest = std::min(nearest, (nodePoint(split, static_cast<std::int64_t>(j)) - given).norm());
    EXPECT_LT(nearest, 1e-14) << "given node " << i << " at " << given.transpose();
  }
}

}  // namespace
}  // namespace homesh
