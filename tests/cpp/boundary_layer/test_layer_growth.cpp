// Growing the macro layer (boundary_layer.hpp): a thin gap shrinking it and the record saying
// where, and the faces, thicknesses and tangent neighbours it refuses, named.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <gp.hxx>
#include <gp_Pln.hxx>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "boundary_layer/boundary_layer.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "layer_case_checks.hpp"
#include "linear/linear_mesher.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// A plate 2 x 2 x 0.1 with a layer of 0.06 asked on both large faces (5: z = 0, 6: z = 0.1):
// the two layers would overlap, so both are shrunk, and the report says where and by how much.
TEST(BoundaryLayer, AThinGapShrinksTheLayerAndTheRecordSaysWhere) {
  const CadModel cad = test::toModel(test::box(2.0, 2.0, 0.1));
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.4);
  const Mesh volume = generateLinearMesh(cad, fill);
  BoundaryLayerParameters p;
  p.faces = {5, 6};
  p.thickness = "0.06";
  BoundaryLayerRecord record;
  const Mesh mesh = growBoundaryLayer(volume, cad, p, fill, record);
  ASSERT_EQ(record.shrunk().size(), 2U);
  for (const LayerShrink& s : record.shrunk()) {
    EXPECT_TRUE(s.face == 5 || s.face == 6);
    EXPECT_LT(s.factor, 0.7);  // 2.5 heights must fit in the 0.1 gap: at most 0.04 of 0.06
    EXPECT_GT(s.factor, 0.0);
    EXPECT_GT(s.nodes, 0U);
    EXPECT_NEAR(s.where[2], s.face == 5 ? 0.0 : 0.1, 1e-12);
    // Every column of both faces faces the other across the gap: none at full height.
    EXPECT_EQ(s.nodes, s.columns);
    EXPECT_EQ(s.fullHeight(), 0.0);
  }
  EXPECT_EQ(record.faces.size(), 2U);
  EXPECT_LE(record.thicknessMax, 0.04);
  EXPECT_GT(record.thicknessMin, 0.0);
  // Every prism positive at its corners, the tops of both layers apart, the whole linear mesh
  // certified valid, and the sides on the plate's edges as quadrilaterals.
  std::size_t prisms = 0, quads = 0;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type == CellType::Quadrilateral) quads += b.count();
    if (b.type != CellType::Prism) continue;
    prisms += b.count();
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      for (int k = 0; k < 3; ++k) {
        const double wallZ = point(mesh, v[k]).z();
        const double topZ = point(mesh, v[k + 3]).z();
        EXPECT_GT(std::fabs(topZ - wallZ), 0.0);
        EXPECT_LT(std::fabs(topZ - 0.05), 0.05 - 1e-3);  // the top inside the plate
      }
    }
  }
  EXPECT_EQ(prisms, record.cells);
  EXPECT_GT(quads, 0U);
  EXPECT_EQ(quads, record.sideQuadrilaterals);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid + q.undecided, 0U);
}

// A layer a billion times thicker than the unit cube it is asked in: every column is brought to
// what the space along its normal allows (2.5 heights within the cube's side, the ray rule), the
// layer is grown and valid, and the record says that no column got the height asked.
TEST(BoundaryLayer, ALayerThickerThanTheSolidShrinksToFitAndTheRecordSaysSo) {
  const CadModel cad = test::toModel(test::box(1.0, 1.0, 1.0));
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.25);
  const Mesh volume = generateLinearMesh(cad, fill);
  BoundaryLayerParameters p;
  p.faces = {1};  // x = 0
  p.thickness = "1e9";
  BoundaryLayerRecord record;
  const Mesh mesh = growBoundaryLayer(volume, cad, p, fill, record);
  ASSERT_EQ(record.faces.size(), 1U);
  const LayerShrink& face = record.faces[0];
  EXPECT_EQ(face.face, 1);
  EXPECT_GT(face.columns, 4U);
  EXPECT_EQ(face.nodes, face.columns);
  EXPECT_EQ(face.fullHeight(), 0.0);
  EXPECT_LE(face.factor * 1e9, 1.0 / 2.5);  // the ray rule: 2.5 heights within the side
  EXPECT_NEAR(face.where[0], 0.0, 1e-12);
  // Why: the narrowest gap across the cube along the layer's normal, the wall across named, the
  // thickness asked there and the room the ray rule left (2.5 heights within the gap).
  const LayerShrink::Gap& gap = face.gap;
  EXPECT_NE(gap.across, 0);
  EXPECT_NE(gap.across, 1);
  EXPECT_GE(gap.width, 1.0 - 1e-9);             // no point of the cube nearer across x
  EXPECT_LE(gap.width, std::sqrt(3.0) + 1e-9);  // nor farther than its diagonal
  EXPECT_NEAR(gap.where[0], 0.0, 1e-12);
  EXPECT_EQ(gap.asked, 1e9);
  EXPECT_GT(gap.room, 0.0);
  EXPECT_LE(gap.room, gap.width / 2.5 * (1.0 + 1e-12));
  EXPECT_GT(gap.room, 0.7 * gap.width / 2.5);  // the largest power of 0.7 that fits
  EXPECT_LE(record.thicknessMax, 1.0 / 2.5);
  EXPECT_GT(record.thicknessMin, 0.0);
  EXPECT_EQ(record.shrunk().size(), 1U);
  EXPECT_GT(record.cells, 0U);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid + q.undecided, 0U);
}

// The same in 2D, through the whole pipeline: a unit square with a layer of 1e9 on one side.
TEST(BoundaryLayer, APlanarLayerThickerThanTheFaceShrinksToFitAndIsCertified) {
  const TopoDS_Shape square = BRepBuilderAPI_MakeFace(gp_Pln(gp::XOY()), 0.0, 1.0, 0.0, 1.0).Face();
  MeshingOptions options;
  options.order = 2;
  options.size = 0.2;
  BoundaryLayerParameters p;
  p.faces = {1};
  p.thickness = "1e9";
  options.boundaryLayer = p;
  const MeshResult r = runMeshPipeline(CadSource::brepText(test::brepText(square)), options);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_EQ(r.boundaryLayer->faces.size(), 1U);
  const LayerShrink& curve = r.boundaryLayer->faces[0];
  EXPECT_EQ(curve.face, 1);
  EXPECT_GT(curve.columns, 2U);
  EXPECT_EQ(curve.fullHeight(), 0.0);
  EXPECT_LE(r.boundaryLayer->thicknessMax, 1.0 / 2.5);
  EXPECT_GT(r.boundaryLayer->thicknessMin, 0.0);
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  // Grown to fit, and the job's notes say so.
  const std::string said = "the boundary layer on Edge1 reaches its thickness on 0 % of its";
  EXPECT_TRUE(std::any_of(r.notes.begin(), r.notes.end(), [&](const std::string& n) {
    return n.find(said) != std::string::npos;
  })) << (r.notes.empty() ? "no notes" : r.notes.front());
  // ... and why: the curve across the square, its distance and the room it leaves.
  ASSERT_NE(curve.gap.across, 0);
  const std::string why = "; Edge" + std::to_string(curve.gap.across) + " is " +
                          formatNumber(curve.gap.width) + " away along the layer's normal at (";
  const std::string room = "room for " + formatNumber(curve.gap.room) + " of the 1e+09 asked";
  EXPECT_TRUE(std::any_of(r.notes.begin(), r.notes.end(), [&](const std::string& n) {
    return n.find(why) != std::string::npos && n.find(room) != std::string::npos;
  })) << (r.notes.empty() ? "no notes" : r.notes.front());
}

TEST(BoundaryLayer, MissingFacesAndBadThicknessesAreNamed) {
  const CadModel cad = test::toModel(test::box(1.0, 1.0, 1.0));
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.5);
  const Mesh volume = generateLinearMesh(cad, fill);
  BoundaryLayerParameters p;
  p.faces = {9};
  p.thickness = "0.1";
  BoundaryLayerRecord record;
  try {
    growBoundaryLayer(volume, cad, p, fill, record);
    ADD_FAILURE();
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("face 9"), std::string::npos) << e.what();
  }
  p.faces = {1};
  p.thickness = "0.1 - x";  // negative beyond x = 0.1: face 1 lies at x = 0, so fine there
  EXPECT_NO_THROW(growBoundaryLayer(volume, cad, p, fill, record));
  p.faces = {2};  // x = 1: the thickness is -0.9 there
  try {
    growBoundaryLayer(volume, cad, p, fill, record);
    ADD_FAILURE();
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("Face2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("must be positive"), std::string::npos) << e.what();
  }
}

// The bracket's hole (Face3) runs into Face1 tangentially: no height of prism is valid there,
// and the message says which face should carry the layer too.
TEST(BoundaryLayer, ATangentNeighbourWithoutALayerIsNamed) {
  MeshingOptions options;  // automatic sizing, as `homesh mesh` without sizes
  options.order = 1;
  BoundaryLayerParameters p;
  p.faces = {3, 6};
  p.thickness = "0.5";
  options.boundaryLayer = p;
  try {
    runMeshPipeline(CadSource::file(std::string(HOMESH_SOURCE_DIR) + "/examples/bracket.step"),
                    options);
    ADD_FAILURE();
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("meets Face1, which has no layer, (nearly) tangentially"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace homesh
