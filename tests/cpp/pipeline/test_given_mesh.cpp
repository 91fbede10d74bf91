// Curving a hybrid linear mesh another tool made (issue 47): Gmsh's sphere in a box with a
// boundary layer of 5 prism layers extruded from the sphere, pyramids on the box's recombined
// faces and tetrahedra between (gmsh_layered.hpp), given to curveMeshOnCad with the CAD it
// meshes. The layer is recognised, curved as one macro prism per column and split back into the
// given layers.
#include <gtest/gtest.h>

#include <BRepPrimAPI_MakeBox.hxx>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "boundary_layer/layer_stacks.hpp"
#include "core/error.hpp"
#include "core/parameters.hpp"
#include "curving/order_elevation.hpp"
#include "gmsh_hybrid_box.hpp"
#include "gmsh_layered.hpp"
#include "io/mesh_readers.hpp"
#include "linear/cad_classification.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/report.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// The largest distance from a node on the CAD to the entity its record names.
double worstNodeDistance(const Mesh& mesh, const CadModel& cad) {
  double worst = 0.0;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    const Eigen::Vector3d p = test::nodePoint(mesh, static_cast<std::int64_t>(i));
    const int index = mesh.nodeCadIndex[i];
    switch (mesh.nodeCadDim[i]) {
      case 0:
        worst = std::max(worst, (p - cad.vertexPoint(index)).norm());
        break;
      case 1:
        worst = std::max(worst, cad.projectOnCurve(index, p).distance);
        break;
      case 2:
        worst = std::max(worst, cad.projectOnSurface(index, p).distance);
        break;
      default:
        break;
    }
  }
  return worst;
}

// The squared distance between two positions rounded to 1e-6 (as firstHeights keys them).
double distance2(const std::array<long, 3>& a, const std::array<long, 3>& b) {
  double d = 0.0;
  for (std::size_t k = 0; k < 3; ++k) d += std::pow(static_cast<double>(a[k] - b[k]), 2);
  return d;
}

// Per wall vertex (by position, rounded to 1e-6): the first layer's height of a mesh's stacks,
// recognised again in its straight-sided cells.
std::map<std::array<long, 3>, double> firstHeights(const Mesh& mesh, int& layers) {
  const Mesh linear = changeOrder(mesh, 1, nullptr);
  std::string why;
  const std::optional<LayerStacks> s = recogniseLayerStacks(linear, why);
  EXPECT_TRUE(s) << why;
  std::map<std::array<long, 3>, double> out;
  if (!s) return out;
  layers = s->record.layers;
  for (std::size_t i = 0; i < s->firstHeights.size(); ++i) {
    if (std::isnan(s->firstHeights[i])) continue;
    const Eigen::Vector3d p = test::nodePoint(s->macro, static_cast<std::int64_t>(i));
    out[{std::lround(p.x() * 1e6), std::lround(p.y() * 1e6), std::lround(p.z() * 1e6)}] =
        s->firstHeights[i];
  }
  return out;
}

// Curves Gmsh's layered mesh `msh` of `step` at each order, optimised, and checks what the issue
// asks: every element proven valid, every boundary node on the CAD to 1e-9 of its diagonal (each
// is placed by projection, to OCCT's 1e-9 of the diagonal), as many layers in every column as
// given and every column's first layer within 5 % of its given height. Returns the results.
std::vector<MeshResult> curveWithLayers(const std::string& msh, const std::string& step,
                                        const test::GmshLayer& layer,
                                        const std::vector<int>& orders, double classifyTolerance) {
  const Mesh given = readMesh(msh);
  int givenLayers = 0;
  const CadModel cad = CadModel::fromFile(step);
  const std::map<std::array<long, 3>, double> givenHeights = firstHeights(
      classifyOnCad(given, cad, classifyTolerance * cad.boundingDiagonal()), givenLayers);
  EXPECT_EQ(givenLayers, layer.layers);
  std::vector<MeshResult> results;
  for (const int order : orders) {
    SCOPED_TRACE("order " + std::to_string(order));
    MeshingOptions options;
    options.order = order;
    options.optimiseIterations = 100;
    options.threads = 2;
    options.classifyTolerance = classifyTolerance;
    results.push_back(curveMeshOnCad(CadSource::file(step), given, options));
    const MeshResult& r = results.back();
    // (On failure the report: the optimiser's record, the notes and where the element is.)
    EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U) << meshReportJson(r, msh);
    EXPECT_LT(worstNodeDistance(r.mesh, *r.cad), 1e-9 * r.cad->boundingDiagonal());
    EXPECT_TRUE(r.givenLayers && r.layerSplit);
    if (!r.givenLayers) continue;
    EXPECT_EQ(r.givenLayers->layers, layer.layers);
    int layers = 0;
    const std::map<std::array<long, 3>, double> heights = firstHeights(r.mesh, layers);
    EXPECT_EQ(layers, layer.layers);
    EXPECT_EQ(heights.size(), givenHeights.size());
    double worst = 0.0;
    for (const auto& [key, h] : heights) {
      // Wall vertices stay where they were, up to the classification's snap, unless the layer
      // had to be released (curve_stage.cpp's releaseLayer: they then slide on the CAD): the
      // nearest given one's column.
      const std::array<long, 3> at = key;  // (a structured binding cannot be captured in C++17)
      auto it = givenHeights.find(at);
      if (it == givenHeights.end())
        it = std::min_element(givenHeights.begin(), givenHeights.end(),
                              [&at](const auto& a, const auto& b) {
                                return distance2(a.first, at) < distance2(b.first, at);
                              });
      if (it != givenHeights.end()) worst = std::max(worst, std::abs(h / it->second - 1.0));
    }
    EXPECT_LT(worst, 0.05);
  }
  return results;
}

// The acceptance case: the closed layer on the sphere, pyramids on the box's faces, at
// orders 2, 4 and 6 (first layers measured within 2e-5 at order 4 and 2e-6 at order 6).
TEST(GivenMesh, GmshsHybridLayeredSphereIsCurvedValidWithItsLayers) {
  const auto dir = test::tempDir();
  const std::string msh = (dir / "sphere.msh").string(), step = (dir / "sphere.step").string();
  const test::GmshLayer layer;
  test::writeGmshLayeredSphere(msh, step, layer);
  const std::vector<MeshResult> results =
      curveWithLayers(msh, step, layer, {2, 4, 6}, parameterDefault("classify_tolerance"));
  const MeshResult& r = results.front();
  ASSERT_TRUE(r.givenLayers);
  EXPECT_EQ(r.givenLayers->sidesMerged, 0U);
  // The report's record of it (report.md#given-boundary-layer).
  const std::string report = meshReportJson(r, msh);
  const std::size_t at = report.find("\"given_layers\": {");
  ASSERT_NE(at, std::string::npos) << report;
  EXPECT_NE(report.find("\"stacks\": " + std::to_string(r.givenLayers->stacks) +
                            ",\n    \"hexahedral_stacks\": 0,\n    \"layers\": 5,",
                        at),
            std::string::npos)
      << report;
}

// The same with the wall's mesh recombined into quadrilaterals: the layer is stacks of
// hexahedra, Gmsh's pyramids on its top (some as flat as 0.11 of their base edge, their apex
// within the curved top's bulge: the optimiser leaves up to 9 invalid at order 4 and straightening
// them repairs them). On the sphere half its patches are recombined: 116 prism and 50 hexahedral
// stacks share the columns where the patches meet. On the cylinder all are: its layer meets the
// end planes (its side quadrilaterals merged and split back).
//
// Both meshes are made before anything is curved. Gmsh runs in a child forked from this process;
// forked after the sphere's multithreaded curving it made another cylinder mesh now and then
// (likely cause, not confirmed: Gmsh orders some containers by address, and the heap the child
// inherits depends on the order the machine's load gave the threads' frees) (1,147 nodes instead of
// 1,153), on which the optimiser leaves a pyramid at an end plane invalid (worst -0.021, not
// repaired by straightening; CI and a fresh clone under load saw it).
TEST(GivenMesh, GmshsHexahedralLayersOnQuadrilateralWallsAreCurvedValidWithTheirLayers) {
  const auto dir = test::tempDir();
  test::GmshLayer layer;
  layer.quadPatches = 4;
  const auto path = [&dir](bool sphere, const char* ext) {
    return (dir / ((sphere ? "sphere." : "cylinder.") + std::string(ext))).string();
  };
  test::writeGmshLayeredSphere(path(true, "msh"), path(true, "step"), layer);
  test::writeGmshLayeredCylinder(path(false, "msh"), path(false, "step"), layer);
  for (const bool sphere : {true, false}) {
    SCOPED_TRACE(sphere ? "sphere" : "cylinder");
    const std::string msh = path(sphere, "msh"), step = path(sphere, "step");
    const double tolerance = sphere ? parameterDefault("classify_tolerance") : 2e-3;
    // (The sphere at order 2 only: at order 4 it has 178,000 nodes, and the cylinder has the
    // same pyramids on a curved top.)
    const std::vector<MeshResult> results = curveWithLayers(
        msh, step, layer, sphere ? std::vector<int>{2} : std::vector<int>{2, 4}, tolerance);
    for (const MeshResult& r : results) {
      ASSERT_TRUE(r.givenLayers && r.layerSplit);
      EXPECT_GT(r.givenLayers->hexStacks, 0U);
      EXPECT_EQ(r.givenLayers->hexStacks < r.givenLayers->stacks, sphere);  // prisms too
      EXPECT_EQ(r.layerSplit->hexahedra, r.givenLayers->hexStacks);
      EXPECT_EQ(r.layerSplit->prisms + r.layerSplit->hexahedra, r.givenLayers->stacks);
      EXPECT_EQ(r.layerSplit->quadrilaterals, r.givenLayers->sidesMerged);
      EXPECT_EQ(r.givenLayers->sidesMerged > 0, !sphere);
    }
  }
}

// A quadrilateral with a corner at the sphere's pole (where the face's u is arbitrary) gets its
// interior nodes from its edges' positions: elevated on the CAD, the hexahedral macro layer of
// Gmsh's sphere is valid (from the (u, v) patch, the three hexahedra at each pole were not).
TEST(GivenMesh, QuadrilateralsAtASpheresPoleAreCurvedValid) {
  const auto dir = test::tempDir();
  const std::string msh = (dir / "sphere.msh").string(), step = (dir / "sphere.step").string();
  test::GmshLayer layer;
  layer.quadPatches = 8;
  test::writeGmshLayeredSphere(msh, step, layer);
  const CadModel cad = CadModel::fromFile(step);
  const Mesh onCad = classifyOnCad(readMesh(msh), cad,
                                   parameterDefault("classify_tolerance") * cad.boundingDiagonal());
  std::string why;
  const std::optional<LayerStacks> stacks = recogniseLayerStacks(onCad, why);
  ASSERT_TRUE(stacks) << why;
  EXPECT_EQ(stacks->record.hexStacks, stacks->record.stacks);
  const QualitySummary quality = evaluateQuality(elevateOrder(stacks->macro, 2, &cad), 2);
  EXPECT_EQ(quality.invalid + quality.undecided, 0U);
}

// A layer whose sides lie on the CAD: the cylinder's layer meets the box's end planes, where
// its side quadrilaterals merge into one per column pair and are split back onto the planes.
TEST(GivenMesh, GmshsLayerMeetingTheEndPlanesKeepsItsSidesOnThem) {
  const auto dir = test::tempDir();
  const std::string msh = (dir / "cyl.msh").string(), step = (dir / "cyl.step").string();
  const test::GmshLayer layer;
  test::writeGmshLayeredCylinder(msh, step, layer);
  const std::vector<MeshResult> results = curveWithLayers(msh, step, layer, {2, 4}, 2e-3);
  for (const MeshResult& r : results) {
    ASSERT_TRUE(r.givenLayers);
    EXPECT_GT(r.givenLayers->sidesMerged, 0U);
    ASSERT_TRUE(r.layerSplit);
    EXPECT_EQ(r.layerSplit->quadrilaterals, r.givenLayers->sidesMerged);
  }
}

// The message of what curveMeshOnCad throws for `given` on the unit box.
template <class E>
std::string refusal(const Mesh& given) {
  MeshingOptions options;
  options.order = 2;
  const std::string box = test::brepText(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape());
  try {
    curveMeshOnCad(CadSource::brepText(box), given, options);
  } catch (const E& e) {
    return e.what();
  }
  return "nothing thrown";
}

// Gmsh's hybrid box (`msh`) with the apex of its 4th pyramid moved to `where` (between 0, its
// base's centre, and 1, where it was).
Mesh boxWithApexMoved(const std::string& msh, double where) {
  Mesh given = readMesh(msh);
  for (const ElementBlock& b : given.blocks) {
    if (b.type != CellType::Pyramid) continue;
    const std::int64_t* p = b.element(3);
    const Eigen::Vector3d base =
        0.25 * (test::nodePoint(given, p[0]) + test::nodePoint(given, p[1]) +
                test::nodePoint(given, p[2]) + test::nodePoint(given, p[3]));
    const Eigen::Vector3d apex = base + where * (test::nodePoint(given, p[4]) - base);
    for (int k = 0; k < 3; ++k) given.xyz[3 * static_cast<std::size_t>(p[4]) + k] = apex[k];
  }
  return given;
}

// A straight-sided cell that cannot be valid curved is refused by name before any curving: a
// pyramid whose apex lies in its base (flat), one whose apex went through its base (turned
// inside out, so it overlaps its neighbours), a hexahedron one of whose corners was pushed
// inside it (its Jacobian changes sign though its faces still enclose a positive volume).
TEST(GivenMesh, CellsThatCannotBeCurvedValidAreRefusedByName) {
  const std::string msh = (test::tempDir() / "box.msh").string();
  test::writeGmshHybridBox({{1, msh}});
  std::string why = refusal<ParameterError>(boxWithApexMoved(msh, 0.0));
  EXPECT_NE(why.find("pyramid 4 of the given mesh"), std::string::npos) << why;
  EXPECT_NE(why.find("is flat"), std::string::npos) << why;
  why = refusal<MeshingError>(boxWithApexMoved(msh, -0.5));
  EXPECT_NE(why.find("pyramid 4"), std::string::npos) << why;
  EXPECT_NE(why.find("overlap"), std::string::npos) << why;

  // 3 x 3 x 3 hexahedra on the unit box; the inner node (1, 1, 1) / 3 moved to (0.6, 0.6, 0.6),
  // near the far corner of the middle hexahedron, the 14th.
  Mesh hexes;
  hexes.dim = 3;
  const auto id = [](std::int64_t i, std::int64_t j, std::int64_t k) { return i + 4 * j + 16 * k; };
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) hexes.xyz.insert(hexes.xyz.end(), {i / 3.0, j / 3.0, k / 3.0});
  for (int c = 0; c < 3; ++c) hexes.xyz[3 * static_cast<std::size_t>(id(1, 1, 1)) + c] = 0.6;
  ElementBlock block{CellType::Hexahedron, 1, {}, {}};
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        block.nodes.insert(
            block.nodes.end(),
            {id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
             id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
        block.entity.push_back(1);
      }
  hexes.blocks.push_back(block);
  why = refusal<MeshingError>(hexes);
  EXPECT_NE(why.find("hex 14 of the given mesh"), std::string::npos) << why;
  EXPECT_NE(why.find("is not valid straight-sided"), std::string::npos) << why;
}

}  // namespace
}  // namespace homesh
