// Recognising another tool's boundary layer (layer_stacks.hpp): Gmsh's prisms extruded from a
// sphere's surface mesh (gmsh_layered.hpp) found as stacks and agglomerated into one macro
// prism each; prisms that are no such layer left alone, with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

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

}  // namespace
}  // namespace homesh
