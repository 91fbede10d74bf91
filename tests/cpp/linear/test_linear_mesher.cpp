// The Gmsh-driven linear mesher: valid tetrahedra, CAD classification of every node, the
// Gmsh-to-FreeCAD entity numbering on compounds, planar (2D) meshes, and its errors.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_BuilderAlgo.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <GProp_GProps.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <algorithm>
#include <cmath>
#include <gp_Pln.hxx>
#include <map>
#include <set>

#include "core/error.hpp"
#include "linear/linear_mesher.hpp"
#include "sizing/sizing_octree.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

using test::nodePoint;

// Every node on a CAD curve or face sits where its recorded parameters say. Gmsh computes each
// such node as C(t) or S(u, v) through OCCT itself: equal up to a few roundings of |x| <= 5
// (~1e-15), so `tol` = 1e-9 is slack; a wrong entity or parameter is off by 1e-2 or more.
void expectParametersReproduceNodes(const Mesh& mesh, const CadModel& cad, double tol) {
  std::size_t onCurves = 0, onFaces = 0;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    const int dim = static_cast<int>(mesh.nodeCadDim[i]);
    const int index = mesh.nodeCadIndex[i];
    const double* param = &mesh.nodeCadParam[2 * i];
    if (dim == 1) {
      ++onCurves;
      EXPECT_NEAR((cad.evaluateCurve(index, param[0]).point - nodePoint(mesh, i)).norm(), 0.0, tol)
          << "node " << i << " on Edge" << index;
    } else if (dim == 2) {
      ++onFaces;
      EXPECT_NEAR(
          (cad.evaluateSurface(index, param[0], param[1]).point - nodePoint(mesh, i)).norm(), 0.0,
          tol)
          << "node " << i << " on Face" << index;
    } else if (dim == 0) {
      EXPECT_NEAR((cad.vertexPoint(index) - nodePoint(mesh, i)).norm(), 0.0, tol);
    }
  }
  EXPECT_GT(onCurves, 0u);
  EXPECT_GT(onFaces, 0u);
}

// Sum of tetrahedron volumes per solid equals each solid's own volume (so every tetrahedron
// records the right SolidN), and every node's parameters reproduce it.
void expectSolidsFilled(const TopoDS_Shape& shape, double size) {
  const CadModel cad = test::toModel(shape);
  const Mesh mesh = generateLinearMesh(cad, LinearMeshOptions::uniform(size));
  std::map<int, double> volumeBySolid;
  const ElementBlock& tets = mesh.blocks[0];
  for (std::size_t e = 0; e < tets.count(); ++e)
    volumeBySolid[tets.entity[e]] += test::tetVolume(mesh, tets.element(e));
  TopTools_IndexedMapOfShape solids;
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  ASSERT_EQ(static_cast<int>(volumeBySolid.size()), solids.Extent());
  for (int s = 1; s <= solids.Extent(); ++s) {
    GProp_GProps props;
    BRepGProp::VolumeProperties(solids(s), props);
    // Straight tetrahedra fill a box exactly; the sum of n < 1e5 volumes <= 3.4 errs by
    // <= n eps 3.4 = 7e-11 (OCCT integrates planar faces exactly).
    EXPECT_NEAR(volumeBySolid[s], props.Mass(), 1e-9) << "Solid" << s;
  }
  expectParametersReproduceNodes(mesh, cad, 1e-9);
}

TEST(LinearMesher, BoxWithHoleGivesPositiveTetsFillingTheVolume) {
  const CadModel cad = test::toModel(test::boxWithHole());
  const Mesh mesh = generateLinearMesh(cad, LinearMeshOptions::uniform(0.5));
  ASSERT_EQ(mesh.dim, 3);
  const ElementBlock& tets = mesh.blocks[0];
  ASSERT_EQ(tets.type, CellType::Tetrahedron);
  EXPECT_GT(tets.count(), 200u);
  double volume = 0.0;
  for (std::size_t e = 0; e < tets.count(); ++e) {
    const double v = test::tetVolume(mesh, tets.element(e));
    EXPECT_GT(v, 0.0);
    volume += v;
  }
  // The straight-sided mesh of the hole is a polygonal prism, inscribed in the cylinder and
  // (with at least 6 sides) larger than the hexagonal one: geometric bounds 1.1 apart, far
  // beyond rounding.
  EXPECT_GT(volume, 32.0 - 2.0 * M_PI);
  EXPECT_LT(volume, 32.0 - 2.0 * (1.5 * std::sqrt(3.0)));
  expectParametersReproduceNodes(mesh, cad, 1e-9);

  // Boundary triangles cover all seven faces, lines all fifteen edges but the seam-free ones.
  std::set<int> faces, curves;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type == CellType::Triangle) faces.insert(b.entity.begin(), b.entity.end());
    if (b.type == CellType::Line) curves.insert(b.entity.begin(), b.entity.end());
  }
  EXPECT_EQ(faces.size(), 7u);
  EXPECT_EQ(curves.size(), 15u);
}

TEST(LinearMesher, CompoundNumberingFollowsFreeCad) {
  // Three disjoint boxes of different volumes in one compound: Gmsh binds them in its own
  // order; each tetrahedron must still record the solid it fills (by MapShapes index).
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  const double sides[3] = {1.0, 2.0, 1.5};
  for (int k = 0; k < 3; ++k) {
    const TopoDS_Shape b =
        BRepPrimAPI_MakeBox(gp_Pnt(5.0 * k, 0, 0), sides[k], sides[k], sides[k]).Shape();
    builder.Add(compound, b);
  }
  ASSERT_EQ(test::toModel(compound).numSolids(), 3);
  expectSolidsFilled(compound, 0.4);
}

TEST(LinearMesher, SolidsSharingAFace) {
  // Two boxes fragmented so that they share their common face (FreeCAD's BooleanFragments).
  TopTools_ListOfShape arguments;
  arguments.Append(BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 1.0, 1.0, 1.0).Shape());
  arguments.Append(BRepPrimAPI_MakeBox(gp_Pnt(1, 0, 0), 2.0, 1.0, 1.0).Shape());
  BRepAlgoAPI_BuilderAlgo fragments;
  fragments.SetArguments(arguments);
  fragments.Build();
  ASSERT_TRUE(fragments.IsDone());
  const TopoDS_Shape shared = fragments.Shape();
  EXPECT_EQ(test::toModel(shared).numFaces(), 11);
  expectSolidsFilled(shared, 0.3);
}

TEST(LinearMesher, TouchingSolidsWithoutSharedTopology) {
  // The same two boxes in a plain compound: their common face exists twice, at the same place,
  // as do its edges and vertices. The numbering must still tell them apart.
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  builder.Add(compound, BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 1.0, 1.0, 1.0).Shape());
  builder.Add(compound, BRepPrimAPI_MakeBox(gp_Pnt(1, 0, 0), 2.0, 1.0, 1.0).Shape());
  EXPECT_EQ(test::toModel(compound).numFaces(), 12);
  expectSolidsFilled(compound, 0.3);
}

TEST(LinearMesher, PlanarFaceGivesOrientedTriangles) {
  // A 4 x 2 rectangle in a tilted plane.
  const gp_Pln plane(gp_Pnt(1, 2, 3), gp_Dir(1, 1, 1));
  const TopoDS_Shape face = BRepBuilderAPI_MakeFace(plane, -2.0, 2.0, -1.0, 1.0).Shape();
  const CadModel cad = test::toModel(face);
  const Mesh mesh = generateLinearMesh(cad, LinearMeshOptions::uniform(0.25));
  ASSERT_EQ(mesh.dim, 2);
  const Eigen::Vector3d n(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
  EXPECT_NEAR(std::abs(n.dot(Eigen::Vector3d(1, 1, 1).normalized())), 1.0, 1e-12);  // rounding
  const ElementBlock& tris = mesh.blocks[0];
  ASSERT_EQ(tris.type, CellType::Triangle);
  double area = 0.0;
  for (std::size_t e = 0; e < tris.count(); ++e) {
    const std::int64_t* t = tris.element(e);
    const Eigen::Vector3d a = nodePoint(mesh, t[0]);
    const double signedArea =
        0.5 * (nodePoint(mesh, t[1]) - a).cross(nodePoint(mesh, t[2]) - a).dot(n);
    EXPECT_GT(signedArea, 0.0);
    area += signedArea;
  }
  EXPECT_NEAR(area, 8.0, 1e-9);  // exact tiling; the sum's rounding is ~n eps 8 = 1e-12
  EXPECT_EQ(mesh.blocks[1].type, CellType::Line);
  expectParametersReproduceNodes(mesh, cad, 1e-9);
}

// A lone cylindrical face (not planar, in no solid) gets a surface mesh: triangles on the face
// in 3D with no plane (Mesh::isSurface), their nodes on the cylinder with the parameters that
// reproduce them.
TEST(LinearMesher, ALoneCurvedFaceGetsASurfaceMesh) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(test::cylinder(1, 2), TopAbs_FACE, faces);
  int lateral = 0;
  for (int f = 1; f <= faces.Extent() && lateral == 0; ++f) {
    const CadModel one = test::toModel(faces(f));
    if (!one.isPlanar(1)) lateral = f;
  }
  ASSERT_GT(lateral, 0);
  const CadModel curved = test::toModel(faces(lateral));
  const Mesh mesh = generateLinearMesh(curved, LinearMeshOptions::uniform(0.5));
  EXPECT_EQ(mesh.dim, 2);
  EXPECT_TRUE(mesh.isSurface());
  ASSERT_EQ(mesh.blocks.size(), 2U);
  EXPECT_EQ(mesh.blocks[0].type, CellType::Triangle);
  EXPECT_EQ(mesh.blocks[1].type, CellType::Line);
  // The tube's area 4 pi over triangles of side 0.5 (0.108 each): about 116.
  EXPECT_GT(mesh.numElements(), 60U);
  EXPECT_LT(mesh.numElements(), 240U);
  for (std::size_t i = 0; i < mesh.numNodes(); ++i)  // |(x, y)| = 1 to OCCT's rounding
    ASSERT_NEAR(std::hypot(mesh.xyz[3 * i], mesh.xyz[3 * i + 1]), 1.0, 1e-12) << i;
  expectParametersReproduceNodes(mesh, curved, 1e-9);
  // A uniform size is checked against the faces' area (4 pi), twice the square of half the
  // box's diagonal (sqrt(12)) that bounds a planar model: at 6.5e-4, 2.3 x 4 pi / 6.5e-4^2 =
  // 6.8e7 triangles exceed the 5e7 allowed, where the planar bound would give 3.3e7.
  try {
    generateLinearMesh(curved, LinearMeshOptions::uniform(6.5e-4));
    FAIL() << "6.8e7 triangles were not refused";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("faces' area 12.56"), std::string::npos) << e.what();
  }
}

TEST(LinearMesher, RejectsWhatItCannotMesh) {
  const CadModel cube = test::toModel(test::box(1, 1, 1));
  EXPECT_THROW(generateLinearMesh(cube, LinearMeshOptions::uniform(0.0)), ParameterError);
  EXPECT_THROW(generateLinearMesh(cube, LinearMeshOptions::uniform(-1.0)), ParameterError);
  EXPECT_THROW(generateLinearMesh(cube, LinearMeshOptions::uniform(1e-5)),
               ParameterError);  // ~1e16 elements
}

// The sizing octree's sizes on a slender cylinder (radius 1, length 150) from 2.5 to 50: Gmsh
// 4.8 refines the curved face's edges round after round while its invalid elements grow, each
// round longer than the last (on a cylinder 1000 long it ran out its whole 600 s budget). The
// watch on its output ends the run, MeshAdapt is tried and stalls too, and the error names the
// CAD face.
TEST(LinearMesher, AGmshRunThatMakesNoProgressIsRefusedNamingTheFace) {
  const CadModel cad = test::toModel(BRepPrimAPI_MakeCylinder(1.0, 150.0).Shape());
  SizingParameters sizing;
  sizing.minDelta = 2.5;
  sizing.maxDelta = 50.0;
  const SizingOctree octree = SizingOctree::build(cad, sizing);
  LinearMeshOptions options;
  options.sizeField = [&octree](const Eigen::Vector3d& p) { return octree.delta(p); };
  options.minSize = 2.5;
  options.maxSize = 50.0;
  options.timeLimit = 600.0;
  std::string message;
  try {
    generateLinearMesh(cad, options);
  } catch (const MeshingError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("made no progress"), std::string::npos) << message;
  EXPECT_NE(message.find("(CAD face 1)"), std::string::npos) << message;
  EXPECT_NE(message.find("MeshAdapt algorithm failed too"), std::string::npos) << message;
}

}  // namespace
}  // namespace homesh
