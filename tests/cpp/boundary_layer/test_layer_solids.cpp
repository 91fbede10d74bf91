// The 3D layer in a model of several solids (layer_solids.hpp): a box with a spherical cavity
// beside a second box, sharing a face; the layer on the cavity grows in its solid, the other
// solid keeps its tetrahedra, the mesh conforms across the shared face and is certified valid
// through the pipeline; the shared face grows into the solid named; a layer that the other solid
// would see is refused, named.
#include <gtest/gtest.h>

#include <BOPAlgo_Builder.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRep_Builder.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Pnt.hxx>
#include <gp_Trsf.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "boundary_layer/boundary_layer.hpp"
#include "core/error.hpp"
#include "layer_case_checks.hpp"
#include "linear/linear_mesher.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

constexpr double kThickness = 0.04;
constexpr int kLayers = 3;

// The unit box with a spherical cavity of radius 0.25 at its centre (7 faces).
TopoDS_Shape boxWithCavity() {
  return BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(),
                         BRepPrimAPI_MakeSphere(gp_Pnt(0.5, 0.5, 0.5), 0.25).Shape())
      .Shape();
}

// boxWithCavity and the box [1, 2] x [0, 1]^2 beside it, fused so that they share the face x = 1
// (12 faces: 6 + 1 + 6, the shared one once).
std::string cavityBesideBox() {
  const TopoDS_Shape cavity = boxWithCavity();
  gp_Trsf shift;
  shift.SetTranslation(gp_Vec(1.0, 0.0, 0.0));
  BOPAlgo_Builder builder;
  builder.AddArgument(cavity);
  builder.AddArgument(
      BRepBuilderAPI_Transform(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(), shift, true).Shape());
  builder.Perform();
  if (builder.HasErrors()) throw Error("cavity beside a box: the general fuse failed");
  return test::brepText(builder.Shape());
}

// The face of the boundary triangle whose centroid is nearest `x`.
int faceNear(const Mesh& mesh, const Eigen::Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  int face = 0;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Triangle) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* t = b.element(e);
      const Eigen::Vector3d c = (point(mesh, t[0]) + point(mesh, t[1]) + point(mesh, t[2])) / 3.0;
      if ((c - x).norm() < best) {
        best = (c - x).norm();
        face = b.entity[e];
      }
    }
  }
  return face;
}

// The solid of the tetrahedra whose centroids lie at x < 1 (the cavity's) and at x > 1.
std::array<int, 2> solidsOf(const Mesh& mesh) {
  std::array<int, 2> solids{0, 0};
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Tetrahedron) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* t = b.element(e);
      double x = 0.0;
      for (int k = 0; k < 4; ++k) x += point(mesh, t[k]).x() / 4.0;
      solids[x < 1.0 ? 0 : 1] = b.entity[e];
    }
  }
  return solids;
}

// The tetrahedra of `solid`, each as its sorted corner points.
std::set<std::vector<double>> tetrahedraOf(const Mesh& mesh, int solid) {
  std::set<std::vector<double>> tets;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Tetrahedron) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      if (b.entity[e] != solid) continue;
      std::vector<std::array<double, 3>> corners;
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d p = point(mesh, b.element(e)[k]);
        corners.push_back({p.x(), p.y(), p.z()});
      }
      std::sort(corners.begin(), corners.end());
      std::vector<double> flat;
      for (const auto& c : corners) flat.insert(flat.end(), c.begin(), c.end());
      tets.insert(flat);
    }
  }
  return tets;
}

// Every face of every tetrahedron and prism is shared by two cells, or is a boundary triangle
// or quadrilateral of the mesh (once on the model's outside, twice on the shared face): the
// mesh conforms, the layer's cells included (a cell over another leaves a face in three), and
// `interfaces` of the boundary faces are shared (the face between two solids).
void expectConforming(const Mesh& mesh, bool interfaces) {
  std::map<std::vector<std::int64_t>, int> cells, boundary;
  const auto key = [](std::vector<std::int64_t> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  for (const ElementBlock& b : mesh.blocks)
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      if (b.type == CellType::Tetrahedron)
        for (int k = 0; k < 4; ++k) ++cells[key({v[(k + 1) % 4], v[(k + 2) % 4], v[(k + 3) % 4]})];
      if (b.type == CellType::Prism) {
        for (const std::vector<std::int64_t>& f : {std::vector<std::int64_t>{v[0], v[1], v[2]},
                                                   {v[3], v[4], v[5]},
                                                   {v[0], v[1], v[4], v[3]},
                                                   {v[1], v[2], v[5], v[4]},
                                                   {v[2], v[0], v[3], v[5]}})
          ++cells[key(f)];
      }
      if (b.type == CellType::Triangle) ++boundary[key({v[0], v[1], v[2]})];
      if (b.type == CellType::Quadrilateral) ++boundary[key({v[0], v[1], v[2], v[3]})];
    }
  std::size_t shared = 0, outside = 0;
  for (const auto& [face, count] : cells) {
    const auto it = boundary.find(face);
    if (it == boundary.end()) {
      EXPECT_EQ(count, 2) << "a face of " << face.size() << " nodes inside the mesh " << face[0]
                          << " " << face[1] << " " << face[2] << " at "
                          << point(mesh, face[0]).transpose() << " / "
                          << point(mesh, face[1]).transpose() << " / "
                          << point(mesh, face[2]).transpose();
      continue;
    }
    EXPECT_EQ(it->second, 1);
    EXPECT_TRUE(count == 1 || count == 2);
    ++(count == 2 ? shared : outside);
  }
  EXPECT_EQ(boundary.size(), shared + outside);  // every boundary element on a cell
  EXPECT_EQ(shared > 0, interfaces);
}

TEST(BoundaryLayerInSolids, TheCavitysSolidGrowsItAndTheOtherKeepsItsTetrahedra) {
  const CadModel cad = CadModel::fromBrepText(cavityBesideBox());
  ASSERT_EQ(cad.numSolids(), 2);
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.15);
  const Mesh volume = generateLinearMesh(cad, fill);
  const std::array<int, 2> solids = solidsOf(volume);
  ASSERT_NE(solids[0], solids[1]);
  const int sphere = faceNear(volume, {0.5, 0.5, 0.75});
  ASSERT_FALSE(cad.isPlanar(sphere));
  BoundaryLayerParameters p;
  p.faces = {sphere};
  p.thickness = std::to_string(kThickness);
  BoundaryLayerRecord record;
  const Mesh mesh = growBoundaryLayer(volume, cad, p, fill, record);
  ASSERT_EQ(record.faces.size(), 1U);
  EXPECT_EQ(record.faces[0].face, sphere);
  EXPECT_EQ(record.faces[0].fullHeight(), 1.0);
  EXPECT_NEAR(record.thicknessMin, kThickness, 1e-9 * kThickness);
  // Every prism in the cavity's solid, its wall on the sphere and its top inside the solid.
  std::size_t prisms = 0;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Prism) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      ++prisms;
      EXPECT_EQ(b.entity[e], solids[0]);
      for (int k = 0; k < 3; ++k) {
        const double wall = (point(mesh, b.element(e)[k]) - Eigen::Vector3d(0.5, 0.5, 0.5)).norm();
        const double top =
            (point(mesh, b.element(e)[k + 3]) - Eigen::Vector3d(0.5, 0.5, 0.5)).norm();
        EXPECT_NEAR(wall, 0.25, 1e-6);
        EXPECT_NEAR(top - wall, kThickness, 0.1 * kThickness);  // along the smoothed normal
      }
    }
  }
  EXPECT_EQ(prisms, record.cells);
  EXPECT_GT(prisms, 50U);
  // The other solid's tetrahedra as the volume mesh had them, the cavity's remade.
  EXPECT_EQ(tetrahedraOf(mesh, solids[1]), tetrahedraOf(volume, solids[1]));
  EXPECT_NE(tetrahedraOf(mesh, solids[0]), tetrahedraOf(volume, solids[0]));
  expectConforming(mesh, true);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid + q.undecided, 0U);
}

// One solid, the same cavity: the layer's top and the box are two shells, and the fill keeps
// out of the inner one (a single surface loop over both had Gmsh fill the cavity and the layer
// over again with tetrahedra, each valid on its own).
TEST(BoundaryLayerInSolids, ALayerOnACavityLeavesTheCavityAndTheLayerToThemselves) {
  const CadModel cad = test::toModel(boxWithCavity());
  ASSERT_EQ(cad.numSolids(), 1);
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.15);
  const Mesh volume = generateLinearMesh(cad, fill);
  BoundaryLayerParameters p;
  p.faces = {faceNear(volume, {0.5, 0.5, 0.75})};
  ASSERT_FALSE(cad.isPlanar(p.faces[0]));
  p.thickness = std::to_string(kThickness);
  BoundaryLayerRecord record;
  const Mesh mesh = growBoundaryLayer(volume, cad, p, fill, record);
  EXPECT_GT(record.cells, 50U);
  expectConforming(mesh, false);
  // No tetrahedron's centroid within the layer's top (0.25 + kThickness from the centre).
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Tetrahedron) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k) c += point(mesh, b.element(e)[k]) / 4.0;
      EXPECT_GT((c - Eigen::Vector3d(0.5, 0.5, 0.5)).norm(), 0.25 + 0.5 * kThickness);
    }
  }
}

TEST(BoundaryLayerInSolids, IsCertifiedValidThroughThePipelineWithTheLayersInEveryColumn) {
  const std::string brep = cavityBesideBox();
  const CadModel cad = CadModel::fromBrepText(brep);
  std::set<int> walls;
  for (int f = 1; f <= cad.numFaces(); ++f)
    if (!cad.isPlanar(f)) walls.insert(f);
  ASSERT_EQ(walls.size(), 1U);
  MeshingOptions options;
  options.order = 2;
  options.optimiseIterations = 20;
  options.threads = 2;
  options.size = 0.15;
  BoundaryLayerParameters layer;
  layer.faces.assign(walls.begin(), walls.end());
  layer.thickness = std::to_string(kThickness);
  layer.layers = kLayers;
  layer.progression = 1.5;
  options.boundaryLayer = layer;
  const MeshResult r = runMeshPipeline(CadSource::brepText(brep, "cavity beside a box"), options);
  expectValidWithLayersInEveryWallColumn(r, walls, kLayers);
  std::set<int> solids;
  for (const ElementBlock& b : r.mesh.blocks)
    if (b.type == CellType::Tetrahedron) solids.insert(b.entity.begin(), b.entity.end());
  EXPECT_EQ(solids.size(), 2U);
  expectNektarAndGmshFilesReadBack(r, "cavity_beside_box");
}

// The face between the solids grows into the solid named (the second box): its prisms there,
// their tops at the thickness across the face, the first solid's tetrahedra untouched.
TEST(BoundaryLayerInSolids, TheFaceBetweenTwoSolidsGrowsIntoTheOneNamed) {
  const CadModel cad = CadModel::fromBrepText(cavityBesideBox());
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.2);
  const Mesh volume = generateLinearMesh(cad, fill);
  const std::array<int, 2> solids = solidsOf(volume);
  BoundaryLayerParameters p;
  p.faces = {faceNear(volume, {1.0, 0.5, 0.5})};
  p.solids = {solids[1]};
  p.thickness = std::to_string(kThickness);
  BoundaryLayerRecord record;
  const Mesh mesh = growBoundaryLayer(volume, cad, p, fill, record);
  ASSERT_EQ(record.faces.size(), 1U);
  EXPECT_EQ(record.faces[0].fullHeight(), 1.0);
  std::size_t prisms = 0;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Prism) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      ++prisms;
      EXPECT_EQ(b.entity[e], solids[1]);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(point(mesh, b.element(e)[k]).x(), 1.0, 1e-12);
        EXPECT_NEAR(point(mesh, b.element(e)[k + 3]).x(), 1.0 + kThickness, 1e-9);
      }
    }
  }
  EXPECT_EQ(prisms, record.cells);
  EXPECT_GT(prisms, 20U);
  EXPECT_GT(record.sideQuadrilaterals, 0U);  // climbing the second box's four sides
  EXPECT_EQ(tetrahedraOf(mesh, solids[0]), tetrahedraOf(volume, solids[0]));
  expectConforming(mesh, true);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid + q.undecided, 0U);
}

// Two boxes apart, a layer on each top: both solids grow, and each keeps the nodes its layer
// relaxed on its side faces (a second solid's growth once put the first's back where the volume
// mesh had them, under the first's fill).
TEST(BoundaryLayerInSolids, TwoSolidsGrowingBothKeepTheirSideFacesRelaxed) {
  TopoDS_Compound two;
  BRep_Builder builder;
  builder.MakeCompound(two);
  builder.Add(two, BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape());
  builder.Add(two, BRepPrimAPI_MakeBox(gp_Pnt(2.0, 0.0, 0.0), 1.0, 1.0, 1.0).Shape());
  const CadModel cad = test::toModel(two);
  ASSERT_EQ(cad.numSolids(), 2);
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.2);
  const Mesh volume = generateLinearMesh(cad, fill);
  BoundaryLayerParameters p;
  p.faces = {faceNear(volume, {0.5, 0.5, 1.0}), faceNear(volume, {2.5, 0.5, 1.0})};
  std::sort(p.faces.begin(), p.faces.end());
  p.thickness = "0.1";
  BoundaryLayerRecord record;
  const Mesh mesh = growBoundaryLayer(volume, cad, p, fill, record);
  EXPECT_EQ(record.faces.size(), 2U);
  // The grown mesh keeps the volume's surface nodes first, in order: count, per box, the nodes
  // inside its side faces that moved.
  std::array<std::size_t, 2> relaxed{0, 0};
  std::size_t j = 0;
  for (std::size_t i = 0; i < volume.numNodes(); ++i) {
    if (volume.nodeCadDim[i] == 3) continue;
    const auto k = static_cast<std::int64_t>(j++);
    const bool side =
        volume.nodeCadDim[i] == 2 &&
        std::find(p.faces.begin(), p.faces.end(), volume.nodeCadIndex[i]) == p.faces.end();
    const Eigen::Vector3d before = point(volume, static_cast<std::int64_t>(i));
    if (side && (point(mesh, k) - before).norm() > 1e-9) ++relaxed[before.x() < 1.5 ? 0 : 1];
  }
  EXPECT_GT(relaxed[0], 0U);
  EXPECT_GT(relaxed[1], 0U);
  expectConforming(mesh, false);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid + q.undecided, 0U);
}

TEST(BoundaryLayerInSolids, ALayerTheOtherSolidWouldSeeIsRefusedNamingTheSolids) {
  const CadModel cad = CadModel::fromBrepText(cavityBesideBox());
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.25);
  const Mesh volume = generateLinearMesh(cad, fill);
  const std::array<int, 2> solids = solidsOf(volume);
  const std::string a = "Solid" + std::to_string(solids[0]);
  const std::string b = "Solid" + std::to_string(solids[1]);
  const auto refusal = [&](int face, const std::vector<int>& named) {
    BoundaryLayerParameters p;
    p.faces = {face};
    p.solids = named;
    p.thickness = "0.05";
    BoundaryLayerRecord record;
    try {
      growBoundaryLayer(volume, cad, p, fill, record);
    } catch (const ParameterError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // The face between them, neither solid or both named.
  const int shared = faceNear(volume, {1.0, 0.5, 0.5});
  for (const std::vector<int>& named : {std::vector<int>{}, {solids[0], solids[1]}}) {
    const std::string between = refusal(shared, named);
    EXPECT_NE(between.find("boundary-layer face " + std::to_string(shared)), std::string::npos)
        << between;
    EXPECT_NE(between.find("between Solid"), std::string::npos) << between;
    EXPECT_NE(between.find(a), std::string::npos) << between;
    EXPECT_NE(between.find(b), std::string::npos) << between;
    EXPECT_NE(between.find(named.empty() ? "--bl-solids" : "both are named"), std::string::npos)
        << between;
  }
  // The second box's floor, whose layer would climb the face between them.
  const int floor = faceNear(volume, {1.5, 0.5, 0.0});
  const std::string beside = refusal(floor, {});
  EXPECT_NE(beside.find("the boundary layer in " + b + " would climb Face" +
                        std::to_string(shared) + ", which it shares with " + a),
            std::string::npos)
      << beside;
  EXPECT_NE(beside.find("not made yet"), std::string::npos) << beside;
  // A solid the model does not have.
  EXPECT_NE(refusal(shared, {3}).find("boundary-layer solid 3 does not exist"), std::string::npos);
}

}  // namespace
}  // namespace homesh
